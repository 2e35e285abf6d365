"""The ``predict`` section (params/predict.py): the paper-scale sweeps, and every bad value refused naming its key."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from params_cases import refusal
from poseintegrity.config import load_params

ROOT = Path(__file__).resolve().parents[2]


def test_paper_scale_thresholds_and_sizes():
    params = load_params(ROOT / "params.yaml")
    predict, protocol = params.predict, params.protocol
    np.testing.assert_array_equal(predict.thresholds, np.arange(4.0, 101.0))  # IV-A: n_t from 4 to 100
    assert predict.static_sizes(protocol.range_end("line"))[-1] == 150.0
    relative = predict.relative_thresholds
    assert (relative[0], relative[-1]) == (predict.relative_min, predict.relative_max)  # both ends on the grid


# (dotted key, bad value, what the error names): each refused before any work (tests/params_cases.py)
BAD_VALUES = [
    ("predict.n_t_max", 3, "predict.n_t_max"),  # < n_t_min
    ("predict.n_t_min", 0, "predict.n_t_min"),
    ("predict.n_t_max", 10**6, "predict.n_t_max"),
    ("predict.live_n_t", 200, "predict.live_n_t"),  # not a swept threshold: the live trials would be empty
    ("predict.live_n_t", 2, "predict.live_n_t"),
    ("predict.relative_min", 0.6, "predict.relative_max"),  # relative_min > relative_max
    ("predict.relative_step", 0.07, "predict.relative_step"),  # 0.02 .. 0.5 is not whole steps of 0.07
    ("predict.relative_max", 1.5, "predict.relative_max"),
    ("predict.n_static", 1, "predict.n_static"),
    ("predict.n_grid", 8, "predict.n_grid"),
    ("predict.models.long_range", "spline", "predict.models.long_range"),
    ("predict.models.long_range_free_width", "emg_wide", "predict.models.long_range_free_width"),
    ("predict.models.next_step_free_width", None, "predict.models.next_step_free_width"),
    ("predict.tail_n_t_max", 200, "predict.tail_n_t_max"),  # beyond the swept n_t_max (30 in the tiny params)
    ("predict.tail_n_t_max", 2, "predict.tail_n_t_max"),  # below n_t_min
    ("predict.tail_n_t_shown", [4, 60], "predict.tail_n_t_shown.1"),  # not a swept threshold
    ("predict.tail_n_t_shown", [4, 4], "predict.tail_n_t_shown"),  # distinct
    ("predict.tail_n_t_shown", [], "predict.tail_n_t_shown"),
    ("predict.loso_target_rates", [1.5], "predict.loso_target_rates.0"),
    ("predict.loso_target_rates", [0.0, -0.1], "predict.loso_target_rates.1"),
    ("predict.loso_target_rates", [0.0, 0.0], "predict.loso_target_rates"),  # distinct
    ("predict.loso_target_rates", [], "predict.loso_target_rates"),
    ("predict.uncertainty.level", 1.0, "predict.uncertainty.level"),
    ("predict.uncertainty.n_bootstrap", 1, "predict.uncertainty.n_bootstrap"),
    ("predict.seed", -1, "predict.seed"),
    ("predict.n_jobs", 2, "predict.n_jobs"),  # gone: parallel.n_jobs is the only worker count
    ("predict.unknown_key", 1, "predict.unknown_key"),
]


@pytest.mark.parametrize(("key", "value", "expected"), BAD_VALUES)
def test_bad_value_is_refused_naming_its_key(tiny_raw, key, value, expected):
    assert expected in refusal(tiny_raw, key, value)


def test_covariance_intervals_need_a_least_squares_long_range_model(tiny_raw):
    tiny_raw["predict"]["uncertainty"]["method"] = "bootstrap"  # any model: valid with the MLP below
    tiny_raw["predict"]["models"]["long_range"] = "mlp_pretrained"
    assert "predict.uncertainty.method" in refusal(tiny_raw, "predict.uncertainty.method", "covariance")


def test_a_model_needing_more_stops_than_sampled_is_refused(tiny_raw):
    """With 2 sampled stops on arcs, eq. 1 (3 parameters) could never be fitted by the long range predictor."""
    tiny_raw["protocol"]["sampled_stops"]["arc"] = 2
    tiny_raw["fit"].update(models=["exponential", "mlp_pretrained"], k_min=2)  # 2-parameter models only
    tiny_raw["predict"]["models"].update(long_range="exponential", next_step="exponential",
                                         long_range_free_width="exponential", next_step_free_width="exponential")
    tiny_raw["predict"]["model_choice"] = ["exponential"]
    assert "predict.model_choice.1" in refusal(tiny_raw, "predict.model_choice", ["exponential", "emg"])
    assert "predict.models.long_range" in refusal(tiny_raw, "predict.models.long_range", "emg")
    assert "predict.models.next_step" in refusal(tiny_raw, "predict.models.next_step", "gaussian")


def test_the_free_width_emg_fits_the_stops_sampled_and_no_fewer(tiny_raw):
    """It needs 4 stops: the 4 (arcs) and 5 (lines) of the paper's protocol suffice, 3 on arcs do not."""
    from poseintegrity.config import parse_params

    assert parse_params(tiny_raw).predict.models.long_range_free_width == "emg_free_width"  # 4 and 5 stops: valid
    tiny_raw["protocol"]["sampled_stops"]["arc"] = 3
    tiny_raw["fit"].update(models=["emg", "exponential"])
    tiny_raw["predict"]["models"].update(long_range_free_width="emg", next_step_free_width="emg")
    tiny_raw["predict"]["model_choice"] = ["emg", "exponential"]
    for key in ("predict.models.long_range_free_width", "predict.models.next_step_free_width"):
        message = refusal(tiny_raw, key, "emg_free_width")
        assert key in message and "needs 4 stops" in message


@pytest.mark.parametrize(("value", "expected"), [
    (["emg", "mlp_pretrained"], "predict.model_choice.1"),  # the MLP is a predictor of its own, not a base function
    (["emg", "emg"], "predict.model_choice"),  # distinct
    ([], "predict.model_choice"),
    (["emg", "cubic"], "predict.model_choice.1"),
])
def test_model_choice_names_least_squares_base_functions(tiny_raw, value, expected):
    assert expected in refusal(tiny_raw, "predict.model_choice", value)
