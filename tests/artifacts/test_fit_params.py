"""The ``fit`` section schema: valid sections load, bad values raise naming the key."""

from __future__ import annotations

import typing

import pytest
import yaml
from pydantic import ValidationError

from poseintegrity.artifacts import MODEL_NAMES, FitParams
from poseintegrity.artifacts.params import ModelName

# The paper-scale section proposed for params.yaml (kept here so that the proposal is known to validate).
PAPER_FIT_YAML = """
fit:
  pnp_method: usac_magsac
  models: [emg, exponential, gaussian, logistic, power_law, mlp_scratch, mlp_pretrained]
  k_min: 3
  k_max: null
  k_report_arc: 4
  k_report_line: 5
  theta_max_deg: 45.0
  x_max_mm: 150.0
  max_nfev: 400
  seed: 20240
  n_jobs: 2
  mlp:
    hidden_layers: 3
    hidden_units: 10
    max_iter_scratch: 300
    max_iter_pretrain: 100
    max_iter_finetune: 20
    tolerance_change: 1.0e-12
    n_pretrain_points: 100
    n_artificial: 10
"""


def with_change(raw: dict, path: str, value: object) -> dict:
    *parents, leaf = path.split(".")
    node = raw
    for key in parents:
        node = node[key]
    node[leaf] = value
    return raw


def test_paper_scale_section_validates():
    params = FitParams.model_validate(yaml.safe_load(PAPER_FIT_YAML)["fit"])
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
