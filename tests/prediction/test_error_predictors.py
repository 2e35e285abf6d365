"""The error predictors (prediction/error_predictors.py, issue 38) on series whose predicted error follows its growth
law exactly, against known answers."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

from poseintegrity.artifact_models.base_functions import emg
from poseintegrity.artifact_models.fitted import FALLBACK, OK
from poseintegrity.artifact_models.series import Series
from poseintegrity.errors import ArgumentError
from poseintegrity.pose_correspondences import MIN_CORRESPONDENCES
from poseintegrity.prediction.error_predictors import (
    CountTrend, error_long_range, error_next_step, fit_growth, growth_regressor, observed_scale,
)
from poseintegrity.prediction.predictors import fit_stops, next_step

ALPHA, K, MU = 3000.0, 8.0, -1.0  # exact eq. 1, as tests/prediction/test_predictors.py
THETA_STOPS = 2.25 * np.arange(20)
A_T, B_T, A_R, B_R = 4.0, 700.0, 0.4, 40.0  # sigma^2 n = a + b sin^2 theta (mm^2; deg^2), stage 02's magnitudes
TOLERANCE = (2.0, 3.0)
SAFETY_FACTORS = np.geomspace(0.2, 10.0, 41)


def exact_sigma(theta, a, b):
    """The law's sigma; no pose (inf) where the count is below the 4 correspondences a pose needs (past 38 deg)."""
    n = emg(theta, ALPHA, K, MU)
    return np.where(n >= MIN_CORRESPONDENCES, np.sqrt((a + b * np.sin(np.radians(theta)) ** 2) / n), np.inf)


def error_series(images: int = 3, n_stops: int = 20, sigma_t=None) -> Series:
    theta = np.repeat(THETA_STOPS[:n_stops], images)
    return Series("scene_1_arc000", "arc", np.repeat(np.arange(n_stops), images), theta, emg(theta, ALPHA, K, MU),
                  45.0, exact_sigma(theta, A_T, B_T) if sigma_t is None else sigma_t, exact_sigma(theta, A_R, B_R))


def true_crossing(k: float) -> float:
    """Where k x the exact sigma first reaches the tolerance of either criterion."""
    margin = lambda t: min(TOLERANCE[0] / exact_sigma(np.array([t]), A_T, B_T)[0],  # noqa: E731
                           TOLERANCE[1] / exact_sigma(np.array([t]), A_R, B_R)[0]) - k
    return brentq(margin, 0.0, 45.0) if margin(45.0) < 0 < margin(0.0) else np.nan


def eq1_growth(series: Series, stops: np.ndarray, fit) -> tuple:
    """fit_growth with the eq. 1 count fitted to ``stops``, as error_long_range fits it."""
    fitted, _, _ = fit_stops(series, stops, "emg", fit, np.random.default_rng(0))
    return fit_growth(series, stops, fitted, fitted.status, fitted.reason)


def test_growth_recovers_the_law_from_the_first_stops(tiny_fit):
    growth, status, _ = eq1_growth(error_series(), np.arange(4), tiny_fit)
    assert status == OK
    np.testing.assert_allclose(growth.coefficients_t, (A_T, B_T), rtol=1e-6)
    np.testing.assert_allclose(growth.coefficients_r, (A_R, B_R), rtol=1e-6)
    theta = np.linspace(0.0, 45.0, 10)
    np.testing.assert_allclose(growth.sigma(theta)[0], exact_sigma(theta, A_T, B_T), rtol=1e-3)


def test_no_pose_is_predicted_where_the_count_falls_below_four(tiny_fit):
    growth, _, _ = eq1_growth(error_series(), np.arange(20), tiny_fit)
    theta = np.linspace(0.0, 45.0, 181)
    n = growth.inliers.predict(theta)
    assert (n < 4).any() and (n >= 4).any()
    sigma_t, sigma_r = growth.sigma(theta)
    assert np.isinf(sigma_t[n < 4]).all() and np.isinf(sigma_r[n < 4]).all()
    assert np.isfinite(sigma_t[n >= 4]).all() and np.isfinite(sigma_r[n >= 4]).all()
    assert (growth.margin(theta, TOLERANCE)[n < 4] == 0).all()  # no safety factor lets the robot go there


def test_error_long_range_stops_where_k_sigma_reaches_the_tolerance(tiny_fit):
    found, status, _ = error_long_range(error_series(), 4, "emg", SAFETY_FACTORS, TOLERANCE, tiny_fit,
                                        np.random.default_rng(0), 256)
    assert status == OK
    root = found.status == "root"
    assert root.sum() > 20
    np.testing.assert_allclose(found.theta_p[root], [true_crossing(k) for k in SAFETY_FACTORS[root]], atol=0.02)
    assert np.all(np.diff(found.theta_p) <= 1e-9)  # a larger safety factor never lets the robot go further


DECAY = -0.12  # per deg: the count of decaying_series, exactly log-linear in (n + 1)


def decaying_series(images: int = 3) -> Series:
    """error_series' law with the count (n + 1) = 300 exp(DECAY theta): the count trend of any three stops is exact."""
    theta = np.repeat(THETA_STOPS, images)
    n = 300.0 * np.exp(DECAY * theta) - 1.0
    sigma = [np.where(n >= MIN_CORRESPONDENCES, np.sqrt((a + b * np.sin(np.radians(theta)) ** 2) / n), np.inf)
             for a, b in ((A_T, B_T), (A_R, B_R))]
    return Series("scene_1_arc000", "arc", np.repeat(np.arange(20), images), theta, n, 45.0, *sigma)


def test_count_trend_continues_the_last_stops_and_never_rises():
    series = decaying_series()
    trend = CountTrend.of(series, np.arange(6))
    assert trend.slope == pytest.approx(DECAY) and trend.theta_last == pytest.approx(THETA_STOPS[5])
    theta = np.linspace(0.0, 45.0, 50)
    np.testing.assert_allclose(trend.predict(theta), np.maximum(300.0 * np.exp(DECAY * theta) - 1.0, 0.0), rtol=1e-9)
    # only the last three stops count: a different start changes nothing
    early = replace(series, n_inliers=np.where(series.stop < 3, 1000.0, series.n_inliers))
    assert CountTrend.of(early, np.arange(6)) == trend
    rising = replace(series, n_inliers=series.n_inliers[::-1].copy())
    flat = CountTrend.of(rising, np.arange(6))
    assert flat.slope == 0.0 and flat.predict(np.array([45.0]))[0] == pytest.approx(flat.n_last)
    # a failed frame (0 inliers) is a count: the mean of a stop falls with it; NaN is no count
    holes = replace(series, n_inliers=np.where((series.stop == 5) & (np.arange(60) % 3 == 0), np.nan, series.n_inliers))
    assert CountTrend.of(holes, np.arange(6)).n_last == pytest.approx(trend.n_last)
    assert CountTrend.of(series, np.arange(1)).slope == 0.0  # one stop: no trend yet


def test_error_next_step_follows_iii_e_rule():
    """At every stop from the 4th on, the robot stops once the predicted crossing is less than a step ahead: with
    an exact law (and a count whose trend is exact), at the last stop before the true crossing (at the 4th, where
    it decides first, if that is later)."""
    series = decaying_series()

    def crossing(k: float) -> float:
        theta = np.linspace(0.0, 45.0, 4501)
        n = 300.0 * np.exp(DECAY * theta) - 1.0
        h = np.sin(np.radians(theta)) ** 2
        with np.errstate(divide="ignore", invalid="ignore"):
            margin = np.where(n >= MIN_CORRESPONDENCES, np.minimum(TOLERANCE[0] / np.sqrt((A_T + B_T * h) / n),
                                                                   TOLERANCE[1] / np.sqrt((A_R + B_R * h) / n)), 0.0)
        below = np.flatnonzero(margin < k)
        return theta[below[0]] if below.size else np.nan

    step = error_next_step(series, 4, SAFETY_FACTORS, TOLERANCE, 256)
    assert (step.prediction.status == "stopped").sum() > 20
    for k, theta_p, status in zip(SAFETY_FACTORS, step.prediction.theta_p, step.prediction.status):
        true = crossing(k)
        if status == "stopped" and true > THETA_STOPS[3]:
            assert theta_p < true + 0.01 and true - theta_p <= 2.25 + 0.01
        elif status == "stopped":
            assert theta_p == THETA_STOPS[3]


def observed(series: Series, times_t, times_r=None) -> Series:
    """``series`` with observed errors ``times_t`` (and ``times_r``, default the same) x its predicted ones."""
    times_r = times_t if times_r is None else times_r
    return replace(series, observed_t=series.sigma_t * times_t, observed_r=series.sigma_r * times_r)


def test_observed_scale_is_the_median_excess_after_the_first_stop():
    series = error_series()
    assert observed_scale(observed(series, 3.0, 1.5), np.arange(6)) == pytest.approx((3.0, 1.5))
    assert observed_scale(observed(series, 0.5), np.arange(6)) == (1.0, 1.0)  # never lowers the prediction
    first = np.where(series.stop == 0, 100.0, 2.0)  # the model view's disagreement is not the estimate's
    assert observed_scale(observed(series, first), np.arange(6)) == pytest.approx((2.0, 2.0))
    assert observed_scale(observed(series, first), np.arange(1)) == (1.0, 1.0)  # nothing after the first stop yet
    gaps = np.where(series.stop % 2 == 1, np.nan, 4.0)  # images without a pose or a robot pose are no sample
    assert observed_scale(observed(series, gaps), np.arange(6)) == pytest.approx((4.0, 4.0))
    recent = np.where(series.stop < 4, 10.0, 2.0)  # the last SCALE_STOPS (3) stops only: an arc's latest state
    assert observed_scale(observed(series, recent), np.arange(6)) == pytest.approx((2.0, 2.0))
    assert observed_scale(observed(series, recent), np.arange(6), window=None) == pytest.approx((10.0, 10.0))
    rising = 1.0 + series.stop  # the scale uses the stops seen so far only
    assert observed_scale(observed(series, rising), np.arange(3))[0] == pytest.approx(np.sqrt(2.0 * 3.0))  # log median


def test_error_next_step_observed_is_the_plain_one_on_the_scaled_error():
    """With observed errors 3 x (t) and 2 x (r) the predicted ones at every stop, the observed variant stops where the
    plain one stops on errors scaled so; with observed errors below the predicted, where the plain one stops."""
    series = error_series()
    args = (4, SAFETY_FACTORS, TOLERANCE, 256)
    scaled = error_next_step(replace(series, sigma_t=3.0 * series.sigma_t, sigma_r=2.0 * series.sigma_r), *args)
    ours = error_next_step(observed(series, 3.0, 2.0), *args, observed=True)
    np.testing.assert_array_equal(ours.prediction.theta_p, scaled.prediction.theta_p)
    assert (ours.prediction.status == "stopped").sum() > 20
    plain = error_next_step(series, *args)
    np.testing.assert_array_equal(error_next_step(observed(series, 0.5), *args, observed=True).prediction.theta_p,
                                  plain.prediction.theta_p)
    assert np.nanmean(ours.prediction.theta_p) < np.nanmean(plain.prediction.theta_p)
    with pytest.raises(ArgumentError, match="no observed error"):
        error_next_step(series, *args, observed=True)


def test_no_predicted_error_is_a_flagged_fit_not_an_error(tiny_fit):
    series = error_series(sigma_t=np.full(60, np.nan))
    growth, status, reason = eq1_growth(series, np.arange(4), tiny_fit)
    assert status == FALLBACK and "no predicted error" in reason
    found, _, _ = error_long_range(series, 4, "emg", SAFETY_FACTORS, TOLERANCE, tiny_fit, np.random.default_rng(0), 256)
    assert np.all(found.theta_p == 0.0)  # an unknown error is no licence to move
    without = Series("scene_1_arc000", "arc", series.stop, series.theta, series.n_inliers, 45.0)
    with pytest.raises(ArgumentError, match="series: dataset scene_1_arc000"):
        error_long_range(without, 4, "emg", SAFETY_FACTORS, TOLERANCE, tiny_fit, np.random.default_rng(0), 256)


def test_the_supervision_loop_is_the_papers(tiny_fit):
    """next_step, now one use of the shared loop, still stops every threshold where III-E says (the scalar reference
    of test_scalar_boundary checks its numbers; here: every stop is a sampled stop at or after the 4th)."""
    series = error_series()
    step = next_step(series, 4, "emg", np.arange(4.0, 60.0), tiny_fit, 0, "usac_magsac", 256)
    stopped = step.prediction.status == "stopped"
    assert stopped.any() and set(step.prediction.theta_p[stopped]) <= set(THETA_STOPS[3:])


def test_growth_regressor_per_trajectory():
    np.testing.assert_allclose(growth_regressor("arc", [0.0, 30.0, 90.0]), [0.0, 0.25, 1.0], atol=1e-12)
    np.testing.assert_allclose(growth_regressor("line", [0.0, 70.0]), [0.0, 70.0])
