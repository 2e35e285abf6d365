"""studies/next_stop_forecasts.py against known answers: a count exactly log-linear in (n + 1) is forecast exactly by
its trend and not by "last", the losses are counted where the forecast and the stop say no pose; an observed error a
constant times the predicted one is forecast exactly by every scaled window, and stops past theta_a are left out."""

import importlib.util

import numpy as np
import pandas as pd
import pytest

from repository import ROOT

spec = importlib.util.spec_from_file_location("next_stop_forecasts", ROOT / "studies" / "next_stop_forecasts.py")
study = importlib.util.module_from_spec(spec)
spec.loader.exec_module(study)


def artifacts(protocol) -> pd.DataFrame:
    """One arc of 20 stops x 3 images whose count (n + 1) = 300 exp(-0.12 theta) falls below 4 at the end."""
    stops, images = np.repeat(np.arange(20), 3), np.tile(np.arange(3), 20)
    theta = 2.25 * stops
    return pd.DataFrame({"world": "main", "dataset": "scene_1_arc000", "trajectory": "arc", "stop": stops,
                         "image": images, "theta_deg": theta, "x_mm": 0.0, "method": protocol.pnp_method,
                         "n_inliers": 300.0 * np.exp(-0.12 * theta) - 1.0})


def test_an_exact_decay_is_forecast_exactly_by_its_trend(protocol, tiny_fit):
    table = study.count_forecasts(artifacts(protocol), protocol, tiny_fit, "emg", 0)
    assert len(table) == 20 - protocol.stops_sampled("arc")  # stops 3 .. 18 forecast 4 .. 19
    np.testing.assert_allclose(table.trend, table.observed, rtol=1e-9)
    assert (table["last"] > table.observed).all()  # no change: always too many on a decay
    summary = study.count_summary(table, (0.0, 1e9), protocol.envelope.max_failed_fraction)
    assert summary.loc[("main", "trend"), "mean_abs_log_error"] == pytest.approx(0.0, abs=1e-9)
    assert summary.loc[("main", "last"), "median_log_error"] == pytest.approx(0.12 * 2.25)
    # the count falls below 4 from stop 16 on (theta 36: 300 exp(-4.32) - 1 = 3.0): every image there lost its pose
    lost = int((table.observed < 4).sum())
    assert lost >= 4 and summary.loc[("main", "trend"), "losses"] == lost
    assert summary.loc[("main", "trend"), "losses_forecast"] == lost
    assert summary.loc[("main", "trend"), "false_losses"] == 0
    assert summary.loc[("main", "last"), "losses_forecast"] < lost


def test_a_constant_excess_is_forecast_by_every_window_before_theta_a(protocol):
    table = artifacts(protocol).assign(sigma_t_pred_mm=lambda t: 0.1 + 0.01 * t.theta_deg, sigma_r_pred_deg=0.1,
                                       E_t_kinematic_mm=lambda t: 3.0 * t.sigma_t_pred_mm, E_r_kinematic_deg=0.3)
    envelopes = pd.DataFrame({"world": "main", "dataset": "scene_1_arc000", "method": protocol.pnp_method,
                              "rule": protocol.envelope.failed_frames, "tolerance": ["2mm_3deg", "4mm_10deg"],
                              "theta_a": [20.0, np.nan]})
    scales = study.scale_forecasts(table, envelopes, protocol)
    assert set(scales.tolerance) == {"2mm_3deg"}  # no envelope: no stop is known to lie before it
    assert scales.stop.tolist() == list(range(protocol.stops_sampled("arc"), 9))  # theta 9 .. 18 <= 20
    summary = study.scale_summary(scales)
    for window in ("last 1", "last 3", "all"):
        assert summary.loc[("main", "2mm_3deg", window), "mean_abs_log_error"] == pytest.approx(0.0, abs=1e-12)
    assert summary.loc[("main", "2mm_3deg", "unscaled"), "median_log_error"] == pytest.approx(-np.log(3.0))
    assert summary.loc[("main", "2mm_3deg", "unscaled"), "within_2x"] == 0.0
