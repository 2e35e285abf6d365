"""theta_p for all thresholds at once (boundaries) against the scalar reference envelope_boundary and analytic
crossings; long range, next-step and static predictors on data whose envelope is known, and every bad-input case."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from scalar_boundary import envelope_boundary
from poseintegrity.artifact_models.base_functions import emg
from poseintegrity.artifact_models.fitted import OK, worst
from poseintegrity.artifact_models.series import Series
from poseintegrity.prediction import NO_FIT, NextStepSupervisor, boundaries, long_range, next_step, static_baseline

ALPHA, K, MU = 3000.0, 8.0, -1.0  # exact eq. 1: ~290 inliers at the first stop, 18 at 45 deg
THETA_STOPS = 2.25 * np.arange(20)  # IV-D: from the model view, up to the arc's range end of 45 deg
N_T = np.arange(4.0, 101.0)
N_GRID = 256  # scan points of the boundaries tests (any n_grid finds these crossings; the property test varies it)


@settings(deadline=None, max_examples=30)
@given(
    alpha=st.floats(500.0, 5000.0), K=st.floats(2.0, 20.0), mu=st.floats(-4.0, 4.0),
    n_grid=st.sampled_from([64, 256]),
)  # fmt: skip
def test_same_answers_as_envelope_boundary_on_emg_curves(alpha, K, mu, n_grid):
    def f(theta):
        return emg(theta, alpha, K, mu)

    found = boundaries(f, N_T, 2.25, 45.0, n_grid)
    for n_t, theta_p, status in zip(N_T, found.theta_p, found.status, strict=True):
        reference = envelope_boundary(f, n_t, 2.25, 45.0, n_scan=n_grid)
        assert status == reference.status
        assert theta_p == pytest.approx(reference.theta_p, abs=1e-7)


def test_exponential_decay_crosses_where_the_logarithm_says():
    a, tau = 200.0, 15.0  # n = a exp(-theta / tau) = n_t at theta = tau ln(a / n_t)
    found = boundaries(lambda t: a * np.exp(-t / tau), N_T, 0.0, 45.0, N_GRID)
    inside = tau * np.log(a / N_T) <= 45.0
    np.testing.assert_allclose(found.theta_p[inside], tau * np.log(a / N_T[inside]), atol=1e-8)
    assert set(found.status[inside]) == {"root"} and set(found.status[~inside]) == {"censored"}
    assert np.all(found.theta_p[~inside] == 45.0)


def test_first_crossing_of_a_non_monotone_curve_matches_brentq_on_its_first_bracket():
    def f(t):
        return 60.0 + 40.0 * np.cos(t / 3.0)  # falls to 20 at 3 pi, back up to 100 at 6 pi

    found = boundaries(f, np.array([50.0]), 0.0, 30.0, N_GRID)
    assert found.theta_p[0] == pytest.approx(brentq(lambda t: f(t) - 50.0, 0.0, 3.0 * np.pi), abs=1e-8)


def test_statuses_below_at_start_censored_non_finite_and_bad_threshold():
    def f(t):
        return np.where(t < 30.0, 100.0 - t, np.nan)  # falls to 70 at 30, then NaN

    found = boundaries(f, np.array([120.0, 80.0, 50.0, np.nan]), 0.0, 45.0, N_GRID)
    assert list(found.status) == ["below_at_start", "root", "non_finite", "bad_threshold"]
    assert found.theta_p[0] == 0.0 and found.theta_p[1] == pytest.approx(20.0, abs=1e-8)
    assert found.theta_p[2] == envelope_boundary(f, 50.0, 0.0, 45.0).theta_p and np.isnan(found.theta_p[3])
    assert boundaries(lambda t: 100.0 - t, np.array([10.0]), 0.0, 45.0, N_GRID).status[0] == "censored"


def test_empty_range_raises():
    with pytest.raises(ValueError, match="empty search range"):
        boundaries(lambda t: t, N_T, 5.0, 5.0, N_GRID)


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
    statuses = [long_range(series, n_stops, "emg", n_t, tiny_fit, np.random.default_rng(0), 256).fitted.status
                for n_stops in range(4, THETA_STOPS.size + 1)]  # the fit on the first n_stops stops  # fmt: skip
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
