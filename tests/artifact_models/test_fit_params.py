"""The ``fit`` section schema: valid sections load, bad values raise naming the key."""

from __future__ import annotations

import typing
from pathlib import Path

import pytest
import yaml
from pydantic import ValidationError

from poseintegrity.artifact_models import MODEL_NAMES, FitParams
from poseintegrity.artifact_models.params import ModelName

ROOT = Path(__file__).resolve().parents[2]


def with_change(raw: dict, path: str, value: object) -> dict:
    *parents, leaf = path.split(".")
    node = raw
    for key in parents:
        node = node[key]
    node[leaf] = value
    return raw


def test_paper_scale_section_validates():
    params = FitParams.model_validate(yaml.safe_load((ROOT / "params.yaml").read_text())["fit"])
    assert params.k_max is None
    assert (params.mlp.hidden_layers, params.mlp.hidden_units) == (3, 10)  # Windsor et al. IV-E
    assert params.range_end("arc") == 45.0 and params.range_end("line") == 150.0


def test_schema_model_names_match_the_fitters():
    assert set(typing.get_args(ModelName)) == set(MODEL_NAMES)


@pytest.mark.parametrize(
    ("path", "value", "match"),
    [
        ("models", ["emg", "spline"], r"models\.1"),
        ("models", ["emg", "emg"], "duplicates"),
        ("models", [], "models"),
        ("k_min", 1, "k_min"),
        ("k_max", 2, "k_max"),
        ("n_jobs", 0, "n_jobs"),
        ("theta_max_deg", -45.0, "theta_max_deg"),
        ("mlp.hidden_units", 0, r"mlp\.hidden_units"),
        ("mlp.max_iter_finetune", 0, r"mlp\.max_iter_finetune"),
        ("mlp.optimizer", "adam", r"mlp\.optimizer"),
        ("seed", -1, "seed"),
    ],
)
def test_bad_value_raises_naming_the_key(tiny_fit_raw, path, value, match):
    FitParams.model_validate(tiny_fit_raw)  # valid before the change
    with pytest.raises(ValidationError, match=match):
        FitParams.model_validate(with_change(tiny_fit_raw, path, value))


def test_params_are_frozen(tiny_fit):
    with pytest.raises(ValidationError, match="frozen"):
        tiny_fit.seed = 3
