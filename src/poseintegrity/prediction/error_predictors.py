"""Predictors that stop where the predicted localization error reaches the tolerance (ours, issue 38).

Windsor et al. stop the robot where the fitted inlier count falls to a threshold n_t chosen by experiment, and name
"thresholds based on task specific localization accuracy requirements" as future work (VI). Stage 02 gives every
posed frame a predicted RMS error (sigma_t mm, sigma_r deg; :mod:`poseintegrity.localization.pose_covariance`): the
tolerance itself can then be the threshold, and the operating point is a safety factor k (a stop is unsafe once
k x sigma reaches the tolerance of either criterion).

How the predicted error grows (:class:`ErrorGrowth`). The pose covariance is N^-1 (...) N^-1 with N = J^T J summed
over the inliers, so per inlier it scales as 1 / n_i; its model-point term grows as the view turns away from the
model view, where M_t's depth errors lie along the rays (~ sin^2 theta of the turn; on a straight line the view
does not turn and the term grows with the distance instead, first order in x). So per image

    sigma^2 n_i = a + b h(theta),   h = sin^2 theta (arcs, theta in deg) or x (lines, mm),   a, b >= 0

is fitted by non-negative least squares to the sampled images with a pose, for E_t and E_r each, and divided by a
count forecast n(theta): sigma(theta) = sqrt((a + b h(theta)) / n(theta)). The count carries what n_i says (a falling
count raises the error as 1 / sqrt(n_i)); the propagation adds what it cannot see (the model points' errors
entering the image as the view turns). Where the forecast count falls below the 4 correspondences a pose needs
(MIN_CORRESPONDENCES, :mod:`poseintegrity.pose_correspondences`) there is no pose to have an error: the predicted
error is infinite (a frame without a pose fails every tolerance, IV-C).

Which count forecast. Long range extrapolates over the whole arc from four stops: it takes the paper's artifact
model (eq. 1, fitted to the same stops), the only curve that says how a count decays that far. Next step needs the
count one stop ahead, and there the eq. 1 fit lags where the count drops fast: least squares on raw counts is led
by the stops with hundreds of inliers, not by the last few with tens. :class:`CountTrend` instead continues the
log-linear trend of the last TREND_STOPS stops' mean counts. Measured on the main world's arcs and lines, one stop
ahead, wherever the last stop's mean count lay in 6-40 (182 forecasts; studies/next_stop_forecasts.py): mean |log error|
of (n + 1) 0.12 against the eq. 1 fit's 0.43, and one of its forecasts below 4 inliers where the stop kept its poses
against the eq. 1 fit's 24; of the one stop there that lost most of its poses, it forecast the loss and the eq. 1
fit did not. On the validation world (149 forecasts): 0.18 against 0.35, 1 false loss against 7, and neither
forecast any of the three stops that lost their poses. The main world chose it; the predictors' scores played no
part.

    error_long_range   fit the sampled stops (4 on arcs, 5 on lines, as the long range predictor); theta_p where
                       k x sigma(theta) first reaches the tolerance (III-E's search, :func:`envelope_prediction`)
    error_next_step    refit at every stop from the last sampled one on, the count from its trend
                       (:class:`CountTrend`), and stop where the robot stands once theta_p is less than one step
                       ahead: III-E's rule (:func:`~poseintegrity.prediction.predictors.supervise`)
    error_next_step_observed
                       the same, with the predicted error scaled by how much the estimates of the last
                       SCALE_STOPS stops have disagreed with the robot's kinematics beyond it
                       (:func:`observed_scale`): the propagation is calibrated on each arc itself, where the robot
                       observes its error

Why the observed variant: the propagation's measured / predicted E_t is 1.0 in the median over the arcs of a world,
but it spreads by a factor of exp(0.4) between arcs (std of the log of each arc's median ratio), and on one deciding
arc (val_2_arc270) it is 3-4.5 from 6.75 deg on: RANSAC's consensus bias (docs/references.md). A static target and a
robot that reports where it is observe each estimate's error (localization/kinematic_consistency.py, Spearman
0.89-0.93 with E_t before theta_a), but only once it happened: a failure within one stop is no more visible in it
than in the propagation, so it calibrates the prediction rather than replacing it. The scale only raises the
prediction: the observation carries the robot's own error (0.1-0.3 mm across an arc), and a lower observed error at
the first stops is one draw of M_t's errors, which the propagation already describes. The scale comes from the
last SCALE_STOPS stops, not from all so far: where an arc's estimates turn wrong (val_2_arc270 from 9 deg on), the
median over all stops lags behind by as many stops as went well. Measured one stop ahead on the main world before
theta_a (studies/next_stop_forecasts.py, no predictor score involved), the mean |log error| of the scaled sigma_t
against the next stop's observed error was 0.258 (2 mm) / 0.272 (4 mm) with the last 3 stops, 0.259 / 0.273 with
the last 2, 0.276 / 0.286 with the last one, 0.278 / 0.296 with all stops so far, 0.339 / 0.352 unscaled: the last
2 and 3 tie, and 3 is the window of the count's trend too. (Validation: 0.352 / 0.371 with 3, 0.337 / 0.357 with all,
0.489 / 0.507 unscaled.)

The search runs on the safety margin m(theta) = min(tol_t / sigma_t, tol_r / sigma_r), which falls as the error
grows: theta_p(k) is where m falls to k, for every k at once.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np
from scipy.optimize import nnls

from poseintegrity.artifact_models.fitted import FALLBACK, OK
from poseintegrity.artifact_models.series import Series
from poseintegrity.errors import ArgumentError
from poseintegrity.params.fit import FitParams
from poseintegrity.pose_correspondences import MIN_CORRESPONDENCES
from poseintegrity.prediction.predictors import (
    Boundaries, NextStep, envelope_prediction, fit_stops, flagged, operating_points, stop_positions, supervise,
)

NO_ERROR = "no predicted error at the sampled stops"  # fit reason of a dataset without one (a fallback fit)


def growth_regressor(trajectory: str, theta: np.ndarray) -> np.ndarray:
    """h(theta) (module docstring): sin^2 theta on arcs (theta deg), theta itself on lines (mm). (m,) -> (m,)."""
    theta = np.asarray(theta, dtype=float)
    return np.sin(np.radians(theta)) ** 2 if trajectory == "arc" else theta


class CountModel(Protocol):
    """A count forecast n(theta): the eq. 1 fit (:class:`~poseintegrity.artifact_models.FittedModel`) or
    :class:`CountTrend`."""

    def predict(self, theta: np.ndarray) -> np.ndarray: ...


TREND_STOPS = 3  # CountTrend's stops: the last three (module docstring, "Which count forecast")
SCALE_STOPS = 3  # observed_scale's stops: the last three (module docstring, "Why the observed variant")
COUNT_TREND = "count_trend"  # the ``model`` of the next-step error predictors' rows (sweeps.py)


@dataclass(frozen=True)
class CountTrend:
    """n(theta) = (n_last + 1) exp(s (theta - theta_last)) - 1, clipped at 0: the log-linear trend of the mean counts
    of the last TREND_STOPS stops (slope s <= 0, per deg or mm), continued from the last stop's mean count n_last at
    theta_last (module docstring). The slope is not let rise above 0: three stops of rising counts are no licence to
    forecast more inliers than the robot has just seen."""

    theta_last: float
    n_last: float
    slope: float

    @classmethod
    def of(cls, series: Series, stops: np.ndarray) -> CountTrend:
        """The trend of ``series``' images at the last TREND_STOPS of ``stops`` (>= 1 stop with a finite count):
        the least squares slope of log(mean n + 1) against the stops' mean theta (0 from one stop)."""
        last = stops[-TREND_STOPS:]
        theta, log_n = np.empty(last.size), np.empty(last.size)
        for j, stop in enumerate(last):
            here = (series.stop == stop) & np.isfinite(series.n_inliers)
            theta[j], log_n[j] = series.theta[here].mean(), np.log(series.n_inliers[here].mean() + 1.0)
        slope = float(np.polyfit(theta, log_n, 1)[0]) if last.size >= 2 else 0.0
        return cls(float(theta[-1]), float(np.exp(log_n[-1]) - 1.0), min(slope, 0.0))

    def predict(self, theta: np.ndarray) -> np.ndarray:
        """n (m,) at theta (m,)."""
        theta = np.asarray(theta, dtype=float)
        return np.maximum((self.n_last + 1.0) * np.exp(self.slope * (theta - self.theta_last)) - 1.0, 0.0)


@dataclass(frozen=True)
class ErrorGrowth:
    """sigma^2 n = a + b h(theta) for E_t (mm^2) and E_r (deg^2), and the count forecast n(theta) (module
    docstring)."""

    trajectory: str
    coefficients_t: tuple[float, float]
    coefficients_r: tuple[float, float]
    inliers: CountModel

    def sigma(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(sigma_t (m,) mm, sigma_r (m,) deg) predicted at theta (m,); inf where the forecast count is below the
        MIN_CORRESPONDENCES a pose needs (module docstring)."""
        h = growth_regressor(self.trajectory, theta)
        n = np.asarray(self.inliers.predict(theta), dtype=float)
        posed = n >= MIN_CORRESPONDENCES
        with np.errstate(divide="ignore", invalid="ignore"):
            return tuple(np.where(posed, np.sqrt((a + b * h) / np.where(posed, n, 1.0)), np.inf)
                         for a, b in (self.coefficients_t, self.coefficients_r))

    def margin(self, theta: np.ndarray, tolerance: tuple[float, float]) -> np.ndarray:
        """m(theta) = min(tol_t / sigma_t, tol_r / sigma_r) (m,): the safety factor left at theta (0 where the
        predicted error is infinite, inf where it is zero)."""
        sigma_t, sigma_r = self.sigma(theta)
        with np.errstate(divide="ignore"):
            return np.minimum(tolerance[0] / sigma_t, tolerance[1] / sigma_r)


def fit_growth(series: Series, stops: np.ndarray, inliers: CountModel, status: str = OK, reason: str = OK
               ) -> tuple[ErrorGrowth, str, str]:
    """The error growth fitted to the images of ``stops`` with the count forecast ``inliers``: (growth, fit status,
    reason). The status is ``status`` (the count model's: the eq. 1 fit's, artifact_models/fitted.py), "fallback"
    when fewer than two distinct theta have a predicted error (the growth then holds the error of the images there,
    constant: b = 0; none at all: an infinite error, theta_p 0)."""
    with np.errstate(over="ignore", invalid="ignore"):  # an image without a pose or a usable error is no sample
        y_t, y_r = series.sigma_t**2 * series.n_inliers, series.sigma_r**2 * series.n_inliers
    keep = (np.isin(series.stop, stops) & np.isfinite(series.theta) & (series.n_inliers > 0) & np.isfinite(y_t)
            & np.isfinite(y_r))
    theta = series.theta[keep]
    h = growth_regressor(series.trajectory, theta)
    columns = np.column_stack([np.ones_like(h), h]) if np.unique(theta).size >= 2 else np.ones((h.size, 1))
    coefficients = []
    for y in (y_t[keep], y_r[keep]):
        if h.size == 0:
            coefficients.append((np.inf, 0.0))
            continue
        solution, _ = nnls(columns, y)
        coefficients.append((float(solution[0]), float(solution[1]) if solution.size > 1 else 0.0))
    if np.unique(theta).size < 2:
        status, reason = FALLBACK, NO_ERROR if h.size == 0 else f"{NO_ERROR} but one: the error held constant"
    return ErrorGrowth(series.trajectory, coefficients[0], coefficients[1], inliers), status, reason


def _checked(series: Series, safety_factors: object) -> np.ndarray:
    """The safety factors k (F,) float, once a series with a predicted error is given (ArgumentError naming the
    argument otherwise; a NaN factor is flagged "bad_threshold", not refused)."""
    if series.sigma_t is None or series.sigma_r is None:
        raise ArgumentError(f"series: dataset {series.dataset}: the series carries no predicted error (stage 02's "
                            f"sigma_t_pred_mm, sigma_r_pred_deg)")
    return operating_points("safety_factors", safety_factors, "safety factors")


def error_long_range(series: Series, n_sampled_stops: int, model: str, safety_factors: np.ndarray,
                     tolerance: tuple[float, float], fit: FitParams, rng: np.random.Generator, n_grid: int
                     ) -> tuple[Boundaries, str, str]:
    """theta_p for every safety factor k of ``safety_factors`` (F,) from the growth fitted to the first
    ``n_sampled_stops`` stops, for one tolerance (E_t mm, E_r deg): (Boundaries, fit status, fit reason).
    "too_few_stops" (NaN) with fewer than ``n_sampled_stops`` stops with a valid inlier count."""
    safety_factors = _checked(series, safety_factors)
    stops, theta_stops = stop_positions(series)
    if stops.size < n_sampled_stops:
        return flagged(safety_factors, "too_few_stops"), "no_fit", "too few stops"
    fitted, _, _ = fit_stops(series, stops[:n_sampled_stops], model, fit, rng)
    growth, status, reason = fit_growth(series, stops[:n_sampled_stops], fitted, fitted.status, fitted.reason)
    found = envelope_prediction(lambda theta: growth.margin(theta, tolerance), safety_factors, theta_stops[0],
                                series.theta_end, n_grid)
    return found, status, reason


def observed_scale(series: Series, stops: np.ndarray, window: int | None = SCALE_STOPS) -> tuple[float, float]:
    """(c_t, c_r) >= 1: how many times the observed error (Series.observed_t / _r) has exceeded the predicted one
    (sigma_t / sigma_r) over the images of the last ``window`` of ``stops`` (None: all), the first stop left out (at
    the first the view is the model view's: the disagreement there is the robot's and the placement's own); the exp
    of the median log ratio over the images with both, floored at 1 (module docstring); 1 without such images."""
    keep = np.isin(series.stop, stops[1:] if window is None else stops[1:][-window:])
    scales = []
    for observed, predicted in ((series.observed_t, series.sigma_t), (series.observed_r, series.sigma_r)):
        with np.errstate(divide="ignore", invalid="ignore"):
            log_ratio = np.log(observed[keep] / predicted[keep])
        log_ratio = log_ratio[np.isfinite(log_ratio)]
        scales.append(max(1.0, float(np.exp(np.median(log_ratio)))) if log_ratio.size else 1.0)
    return scales[0], scales[1]


def error_next_step(series: Series, n_sampled_stops: int, safety_factors: np.ndarray, tolerance: tuple[float, float],
                    n_grid: int, observed: bool = False) -> NextStep:
    """The next-step predictor of III-E on the predicted error: from the last of the ``n_sampled_stops`` sampled
    stops on, the growth is refitted on all stops so far, the count continued from its trend (:class:`CountTrend`),
    and the robot stops where it stands for every safety factor k of ``safety_factors`` (F,) whose theta_p <
    theta_i + theta_b (:func:`~poseintegrity.prediction.predictors.supervise`). ``observed``: each refit on the
    predicted errors scaled by :func:`observed_scale` of the last stops (``error_next_step_observed``; a series
    without observed errors is refused, ArgumentError naming it)."""
    safety_factors = _checked(series, safety_factors)
    if observed and (series.observed_t is None or series.observed_r is None):
        raise ArgumentError(f"series: dataset {series.dataset}: the series carries no observed error (stage 02's "
                            f"E_t_kinematic_mm, E_r_kinematic_deg: the robot's poses, T_base_cam_robot)")
    _, theta_stops = stop_positions(series)

    def boundary(stops: np.ndarray, moving: np.ndarray) -> tuple[np.ndarray, str, str]:
        seen = series
        if observed:
            c_t, c_r = observed_scale(series, stops)
            seen = replace(series, sigma_t=series.sigma_t * c_t, sigma_r=series.sigma_r * c_r)
        growth, status, reason = fit_growth(seen, stops, CountTrend.of(series, stops))
        found = envelope_prediction(lambda theta: growth.margin(theta, tolerance), moving, theta_stops[0],
                                    series.theta_end, n_grid)
        return found.theta_p, status, reason

    return supervise(series, n_sampled_stops, safety_factors, boundary)


def combined(theta_p_error: np.ndarray, theta_p_inliers: float) -> np.ndarray:
    """The earlier stop of the error predictor (per safety factor, (F,)) and the inlier predictor at its chosen n_t:
    each guards what the other cannot see. NaN where either is NaN (a flagged row)."""
    return np.minimum(np.asarray(theta_p_error, dtype=float), theta_p_inliers)
