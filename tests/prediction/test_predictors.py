"""Long range, next-step and static predictors on data whose envelope is known, and every bad-input case."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from poseintegrity.artifact_models.base_functions import emg
from poseintegrity.artifact_models.fitted import OK, worst
from poseintegrity.artifact_models.series import Series
from poseintegrity.prediction import NO_FIT, NextStepSupervisor, long_range, next_step, static_baseline

ALPHA, K, MU = 3000.0, 8.0, -1.0  # exact eq. 1: ~290 inliers at the first stop, 18 at 45 deg
THETA_STOPS = 2.25 * np.arange(20)  # IV-D: from the model view, up to the arc's range end of 45 deg
N_T = np.arange(4.0, 101.0)


def exact_series(n_inliers=None, n_stops: int = 20, images: int = 3) -> Series:
    theta = np.repeat(THETA_STOPS[:n_stops], images)
    counts = emg(theta, ALPHA, K, MU) if n_inliers is None else n_inliers
    return Series("scene_1_arc000", "arc", np.repeat(np.arange(n_stops), images), theta, np.asarray(counts, float),
                  theta_end=45.0)  # fmt: skip


def test_the_test_arcs_end_where_the_protocol_ends_them(protocol):
    assert exact_series().theta_end == protocol.range_end("arc")


def true_crossing(n_t: float) -> float:
    return brentq(lambda t: emg(np.array([t]), ALPHA, K, MU)[0] - n_t, 0.0, 45.0)


def test_long_range_on_an_exact_emg_finds_the_true_crossing(tiny_fit):
    answer = long_range(exact_series(), 4, "emg", N_T, tiny_fit, np.random.default_rng(0), 256)
    assert answer.fitted.status == OK
    root = answer.prediction.status == "root"
    assert root.sum() > 50
    expected = [true_crossing(n) for n in N_T[root]]
    np.testing.assert_allclose(answer.prediction.theta_p[root], expected, atol=1e-3)
    assert np.all(np.diff(answer.prediction.theta_p) <= 1e-12)  # conservative as n_t grows (III-F)


def test_thresholds_outside_the_data_range_have_documented_answers(tiny_fit):
    n_t = np.array([1e4, 0.5, np.nan])  # above every count, below every count, not a number
    answer = long_range(exact_series(), 4, "emg", n_t, tiny_fit, np.random.default_rng(0), 256)
    assert list(answer.prediction.status) == ["below_at_start", "censored", "bad_threshold"]
    assert answer.prediction.theta_p[0] == 0.0 and answer.prediction.theta_p[1] == 45.0
    assert np.isnan(answer.prediction.theta_p[2])


def test_next_step_flags_a_non_finite_threshold(tiny_fit):
    step = next_step(exact_series(), 4, "emg", np.array([30.0, np.nan]), tiny_fit, 0, "usac_magsac", 256)
    assert list(step.prediction.status) == ["stopped", "bad_threshold"] and np.isnan(step.prediction.theta_p[1])


@pytest.mark.parametrize("series", [exact_series(n_stops=3), exact_series(np.full(60, np.nan))])
def test_too_few_stops_or_all_nan_counts_are_flagged_not_raised(series, tiny_fit):
    answer = long_range(series, 4, "emg", N_T, tiny_fit, np.random.default_rng(0), 256)
    assert set(answer.prediction.status) == {"too_few_stops"} and np.all(np.isnan(answer.prediction.theta_p))
    step = next_step(series, 4, "emg", N_T, tiny_fit, 0, "usac_magsac", 256)
    assert set(step.prediction.status) == {"too_few_stops"} and step.n_fits == 0
    assert set(step.fit_status) == {NO_FIT}


def test_next_step_stops_where_the_supervisor_does(tiny_fit):
    series = exact_series()
    step = next_step(series, 4, "emg", N_T, tiny_fit, 0, "usac_magsac", 256)
    assert set(step.prediction.status) <= {"stopped", "end_of_path"}
    assert np.all(np.diff(step.prediction.theta_p) <= 0.0)  # a larger n_t never lets the robot further
    for index in (0, 20, 60):
        supervisor = NextStepSupervisor(n_t=N_T[index], theta_b=2.25, theta_end=series.theta_end, fit=tiny_fit,
                                        rng=np.random.default_rng(0), model="emg", first_stops=4, n_grid=256)  # fmt: skip
        stopped_at = THETA_STOPS[-1]
        for theta in THETA_STOPS:
            decision = supervisor.update(theta, emg(np.full(3, theta), ALPHA, K, MU))
            if not decision.proceed:
                stopped_at = theta  # the robot stops where it is (V-B)
                break
        assert step.prediction.theta_p[index] == stopped_at
        if step.prediction.status[index] == "stopped":  # stopped because the boundary is within one step
            assert step.boundary[index] < stopped_at + 2.25


def test_next_step_on_exact_data_stops_at_the_last_stop_before_the_true_crossing(tiny_fit):
    step = next_step(exact_series(), 4, "emg", N_T, tiny_fit, 0, "usac_magsac", 256)
    assert set(step.fit_status) == {OK} and set(step.prediction.theta_p[step.prediction.status == "stopped"]) <= set(
        THETA_STOPS)
    for n_t, stop, status in zip(N_T, step.prediction.theta_p, step.prediction.status, strict=True):
        crossing = true_crossing(n_t) if emg(np.array([45.0]), ALPHA, K, MU)[0] < n_t else np.inf
        if status == "stopped" and crossing > THETA_STOPS[3]:
            # the robot stands at the last stop from which the next step would cross the boundary
            assert stop <= crossing + 1e-3 and crossing <= stop + 2.25 + 1e-3


def test_next_step_rows_carry_the_worst_fit_the_robot_went_by(tiny_fit):
    """Counts that decay over the 4 sampled stops, then rise again: the later fits (on more of the rise) are flagged,
    and each row carries the most severe status among the fits made up to the one that stopped the robot."""
    counts = np.where(THETA_STOPS < 7.0, 300.0 - 30.0 * THETA_STOPS, 97.5 + 10.0 * (THETA_STOPS - 6.75))
    series = exact_series(np.repeat(counts, 3))
    n_t = np.array([250.0, 60.0, 10.0])
    step = next_step(series, 4, "emg", n_t, tiny_fit, 0, "usac_magsac", 256)
    statuses = [long_range(series, k, "emg", n_t, tiny_fit, np.random.default_rng(0), 256).fitted.status
                for k in range(4, THETA_STOPS.size + 1)]  # the fit on the first k stops  # fmt: skip
    assert statuses[0] == OK and statuses[-1] != OK  # a decay, then no decay any more
    for theta_p, status, fit_status in zip(step.prediction.theta_p, step.prediction.status, step.fit_status,
                                           strict=True):  # fmt: skip
        last_fit = int(np.flatnonzero(THETA_STOPS == theta_p)[0]) + 1 if status == "stopped" else THETA_STOPS.size
        assert fit_status == worst(statuses[: last_fit - 3])
    assert step.prediction.status[0] == "stopped" and step.fit_status[0] == OK  # n_t = 250: stopped by the first fit


def test_static_baseline_is_the_size_for_every_dataset():
    sizes = np.linspace(0.0, 45.0, 11)
    found = static_baseline(sizes)
    np.testing.assert_array_equal(found.theta_p, sizes)
    assert set(found.status) == {"static"}
