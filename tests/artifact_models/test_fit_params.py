"""The ``fit`` section schema: params.yaml validates, every bad value is refused naming its key."""

from __future__ import annotations

import typing
from pathlib import Path

import pytest
from pydantic import ValidationError

from params_cases import refusal
from poseintegrity.artifact_models import BASE_FUNCTIONS
from poseintegrity.params.model_names import MODEL_NAMES, distinct_theta_needed
from poseintegrity.params.fit import ModelName
from poseintegrity.config import load_params

ROOT = Path(__file__).resolve().parents[2]


def test_paper_scale_section_validates():
    fit = load_params(ROOT / "params.yaml").fit
    assert fit.k_max is None
    assert (fit.mlp.hidden_layers, fit.mlp.hidden_units) == (3, 10)  # Windsor et al. IV-E


def test_schema_model_names_match_the_fitters():
    assert set(typing.get_args(ModelName)) == set(MODEL_NAMES)


def test_stops_needed_are_the_parameter_counts():
    assert distinct_theta_needed("emg") == 3  # alpha, K, mu of eq. 1
    assert distinct_theta_needed("emg_free_width") == 4  # ... and sigma
    assert distinct_theta_needed("exponential") == 2
    assert {distinct_theta_needed(name) for name in ("mlp_scratch", "mlp_pretrained")} == {2}
    assert all(distinct_theta_needed(name) == len(base.param_names) for name, base in BASE_FUNCTIONS.items())


# (dotted key, bad value, what the error names): each refused before any work (tests/params_cases.py)
BAD_VALUES = [
    ("fit.models", ["emg", "spline"], "fit.models.1"),
    ("fit.models", ["emg", "emg"], "fit.models"),  # distinct
    ("fit.models", [], "fit.models"),
    ("fit.k_min", 1, "fit.k_min"),
    ("fit.k_max", 2, "fit.k_max"),  # < k_min
    ("fit.k_max", 1000, "fit.k_max"),
    ("fit.max_nfev", 5, "fit.max_nfev"),
    ("fit.max_nfev", 10**7, "fit.max_nfev"),
    ("fit.seed", -1, "fit.seed"),
    ("fit.seed", 2**64, "fit.seed"),
    ("fit.n_jobs", 2, "fit.n_jobs"),  # gone: parallel.n_jobs is the only worker count
    ("fit.mlp.hidden_units", 0, "fit.mlp.hidden_units"),
    ("fit.mlp.hidden_units", 5000, "fit.mlp.hidden_units"),
    ("fit.mlp.hidden_layers", 11, "fit.mlp.hidden_layers"),
    ("fit.mlp.max_iter_finetune", 0, "fit.mlp.max_iter_finetune"),
    ("fit.mlp.max_iter_scratch", 10**6, "fit.mlp.max_iter_scratch"),
    ("fit.mlp.tolerance_change", 0.0, "fit.mlp.tolerance_change"),
    ("fit.mlp.tolerance_change", float("nan"), "fit.mlp.tolerance_change"),
    ("fit.mlp.n_pretrain_points", 1, "fit.mlp.n_pretrain_points"),
    ("fit.mlp.n_artificial", 10**4, "fit.mlp.n_artificial"),
    ("fit.mlp.optimizer", "adam", "fit.mlp.optimizer"),
]


@pytest.mark.parametrize(("key", "value", "expected"), BAD_VALUES)
def test_bad_value_is_refused_naming_its_key(tiny_raw, key, value, expected):
    assert expected in refusal(tiny_raw, key, value)


def test_k_min_below_every_models_need_is_refused(tiny_raw):
    """With eq. 1 (3 parameters) and the free-width EMG (4) alone, no fit can be made on 2 stops."""
    tiny_raw["fit"]["models"] = ["emg", "emg_free_width"]
    assert "fit.k_min" in refusal(tiny_raw, "fit.k_min", 2)


def test_a_model_needing_fewer_stops_allows_a_smaller_k_min(tiny_raw):
    """k_min = 2 fits the exponential and the MLPs, which need 2 stops; eq. 1 joins Fig. 2 at 3, the free-width EMG
    at 4 (fig2.py)."""
    from poseintegrity.config import parse_params

    tiny_raw["fit"].update(models=["exponential", "mlp_pretrained"], k_min=2)
    assert parse_params(tiny_raw).fit.k_min == 2
    tiny_raw["fit"]["models"] = ["emg", "emg_free_width", "exponential"]
    assert parse_params(tiny_raw).fit.models == ["emg", "emg_free_width", "exponential"]


def test_a_model_needing_more_stops_than_sampled_is_refused_by_name(tiny_raw):
    """With 3 sampled stops on arcs the free-width EMG (4 parameters) would have no headline RMSE (nor predictor)."""
    tiny_raw["protocol"]["sampled_stops"]["arc"] = 3
    tiny_raw["predict"]["models"].update(long_range_free_width="emg", next_step_free_width="emg")
    tiny_raw["predict"]["model_choice"] = ["emg", "exponential"]
    tiny_raw["fit"]["models"] = ["emg", "exponential"]
    message = refusal(tiny_raw, "fit.models", ["emg", "exponential", "emg_free_width"])
    assert "fit.models.2" in message and "emg_free_width" in message


def test_params_are_frozen(tiny_fit):
    with pytest.raises(ValidationError, match="frozen"):
        tiny_fit.seed = 3
