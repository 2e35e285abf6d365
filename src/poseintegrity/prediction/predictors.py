"""The localization-envelope predictors of Windsor et al. (III-E, IV-A) and the static baseline.

    boundaries        theta_p for every inlier threshold n_t at once from one fitted artifact model (III-E)
    long_range        fit the sampled stops (4 on arcs, 5 on lines), theta_p per n_t (III-E, V-A)
    next_step         refit at every stop from the 4th on; stop where the robot is when theta_p < theta_i + theta_b
                      (III-E, IV-A, V-B)
    static_baseline   one envelope size for every dataset (IV-A)
    relative_thresholds  beyond the paper: n_t as a fraction of the first stop's mean n_i

The artifact fit does not depend on n_t, so every predictor fits once per dataset (and stop) and finds the
crossings of all thresholds on one evaluation of the fitted curve. theta is deg for arcs, mm for lines.

Statuses of a theta_p (the first four as in the scalar reference ``envelope_boundary`` of tests/scalar_boundary.py):
    "root"            the fitted curve falls to n_t inside [theta_1, theta_end]
    "censored"        it stays above n_t up to the range end: theta_p = theta_end
    "below_at_start"  it is at or below n_t already at the first stop: theta_p = 0 (no safe motion predicted)
    "non_finite"      the curve is nan/inf before any crossing: theta_p = the last finite point before it
    "bad_threshold"   n_t is not finite: theta_p = NaN (a flagged row)
    "too_few_stops"   fewer stops with a valid inlier count than the predictor needs: theta_p = NaN (flagged)
    "stopped" / "end_of_path"   next-step only: the robot was stopped (theta_p = the stop where it stands) / it
                      reached the last stop (theta_p = the last stop)

Beside the status of theta_p, every answer carries the status of the fit(s) behind it (ok / at_bound / non_physical
/ fallback, artifact_models/fitted.py; NO_FIT where nothing was fitted). A flagged fit's theta_p still counts: it is
what the robot would have done (a "fallback" fit predicts with its line, the others with their fitted curve).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from poseintegrity.artifact_models import FIT_STATUSES, FittedModel, fit_model
from poseintegrity.artifact_models.fitted import MAX_THETA, OK
from poseintegrity.artifact_models.series import Series
from poseintegrity.errors import ArgumentError, check_array, check_increasing, check_scalar
from poseintegrity.params.fit import FitParams
from poseintegrity.seeding import keyed_rng

BISECTION_XTOL = 1e-9  # theta units; the root refinement of :func:`boundaries`
NO_FIT = "no_fit"  # fit status of an answer without a fit (too few stops, a bad threshold, the static baseline)


@dataclass(frozen=True)
class Boundaries:
    """theta_p : (T,) float, deg or mm;  status : (T,) str, one per threshold (module docstring)."""

    theta_p: np.ndarray
    status: np.ndarray


def operating_points(name: str, values: object, what: str) -> np.ndarray:
    """``values`` as operating points (T,) float: inlier thresholds n_t, safety factors k or the levels a curve falls
    to (``what``, in the message); ArgumentError naming ``name`` unless a number or a 1-D array of numbers (a NaN one
    is flagged "bad_threshold" by the predictors, not refused)."""
    points = np.atleast_1d(check_array(name, values, finite=False))
    if points.ndim != 1:
        raise ArgumentError(f"{name}: expected a number or a (T,) array of {what}, got shape {points.shape}")
    return points


def boundaries(
    predict: Callable[[np.ndarray], np.ndarray],
    levels: np.ndarray,
    theta_start: float,
    theta_end: float,
    n_grid: int,
) -> Boundaries:
    """theta_p in [theta_start, theta_end] where predict first falls to each level (III-E, vectorized): an inlier
    threshold n_t of a count curve, or a safety factor k of a margin curve (:mod:`.error_predictors`).

    The same answers as the scalar reference ``envelope_boundary`` of tests/scalar_boundary.py with ``n_scan = n_grid`` (checked in
    the tests): f is evaluated once on the grid; the first grid point at or below a level is found for every
    level through the running minimum of f; each bracketing interval is then refined by a bisection run on
    all brackets at once (one call of ``predict`` per halving) down to BISECTION_XTOL.

    predict : f, (m,) float -> (m,) float;  levels : (T,) float
    n_grid : scan points (``predict.n_grid``)
    Refused (:class:`~poseintegrity.errors.ArgumentError` naming the argument): n_grid not an integer >= 2,
    theta_start or theta_end not finite within 1e6, an empty range, levels not a number or (T,) array of numbers;
    a non-finite level is flagged ("bad_threshold"), not refused; no levels give an empty answer.
    """
    if isinstance(n_grid, (bool, np.bool_)) or not isinstance(n_grid, (int, np.integer)) or n_grid < 2:
        raise ArgumentError(f"n_grid: expected an integer >= 2 (scan points), got {n_grid!r}")
    check_scalar("theta_start", theta_start, low=-MAX_THETA, high=MAX_THETA)
    check_scalar("theta_end", theta_end, low=-MAX_THETA, high=MAX_THETA)
    if not theta_end > theta_start:
        raise ArgumentError(f"theta_start, theta_end: empty search range [{theta_start}, {theta_end}]")
    level = operating_points("levels", levels, "levels")
    theta = np.linspace(theta_start, theta_end, n_grid)
    f = np.asarray(predict(theta), dtype=float)
    bad = ~np.isfinite(f)
    first_bad = int(np.argmax(bad)) if bad.any() else n_grid
    running_min = np.minimum.accumulate(f[:first_bad]) if first_bad else np.empty(0)
    # first grid index with f <= level, or first_bad if f stays above it on the finite prefix
    first_below = np.searchsorted(-running_min, -np.nan_to_num(level, nan=-np.inf), side="left")

    theta_p = np.full(level.shape, np.nan)
    status = np.full(level.shape, "root", dtype=object)
    censored = first_below == n_grid
    non_finite = (first_below == first_bad) & ~censored
    at_start = (first_below == 0) & ~non_finite
    theta_p[censored], status[censored] = theta_end, "censored"
    theta_p[non_finite], status[non_finite] = theta[max(first_bad - 1, 0)], "non_finite"
    theta_p[at_start], status[at_start] = theta_start, "below_at_start"
    bad_level = ~np.isfinite(level)
    theta_p[bad_level], status[bad_level] = np.nan, "bad_threshold"

    root = (status == "root").nonzero()[0]
    i = first_below[root]
    lo, hi = theta[i - 1], theta[i]
    exact = f[i] == level[root]
    theta_p[root[exact]] = hi[exact]
    root, lo, hi, target = root[~exact], lo[~exact], hi[~exact], level[root[~exact]]
    failed = np.zeros(root.shape, dtype=bool)
    for _ in range(int(np.ceil(np.log2(max((theta[1] - theta[0]) / BISECTION_XTOL, 2.0))))):
        mid = 0.5 * (lo + hi)
        excess = np.asarray(predict(mid), dtype=float) - target if mid.size else mid
        failed |= ~np.isfinite(excess)
        above = excess > 0.0
        lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
    theta_p[root] = np.where(failed, theta[first_below[root] - 1], 0.5 * (lo + hi))
    status[root[failed]] = "non_finite"
    return Boundaries(theta_p, status.astype(str))


def stop_positions(series: Series) -> tuple[np.ndarray, np.ndarray]:
    """(stops, theta) of the stops with at least one valid inlier count, in stop order : (s,) int, (s,) float."""
    valid = np.isfinite(series.n_inliers) & (series.n_inliers >= 0) & np.isfinite(series.theta)
    stops = np.unique(series.stop[valid])
    theta = np.array([series.theta[series.stop == s].mean() for s in stops])
    return stops, theta


def fit_rng(seed: int, method: str, series: Series, n_fitted_stops: int) -> np.random.Generator:
    """The Generator of one fit (of ``series``' first ``n_fitted_stops`` stops): the same for any number of workers,
    order of work and other datasets in the table."""
    return keyed_rng(seed, f"{method}/{series.trajectory}/{series.dataset}", n_fitted_stops)


def fit_stops(
    series: Series, stops: np.ndarray, model: str, fit: FitParams, rng: np.random.Generator
) -> tuple[FittedModel, np.ndarray, np.ndarray]:
    """The artifact model fitted to the images of ``stops`` : (fitted, theta (m,), n_inliers (m,))."""
    keep = np.isin(series.stop, stops)
    theta, n_inliers = series.theta[keep], series.n_inliers[keep]
    fitted = fit_model(model, theta, n_inliers, theta_end=series.theta_end, params=fit, rng=rng)
    return fitted, theta, n_inliers


def envelope_prediction(
    predict: Callable[[np.ndarray], np.ndarray], operating_points: np.ndarray, theta_1: float, theta_end: float,
    n_grid: int,
) -> Boundaries:
    """theta_p per operating point from a fitted curve, searched from the first stop (III-E): where the curve falls
    to it, the search of :func:`boundaries`. operating_points : (T,) float, n_t of an inlier count curve
    (``FittedModel.predict``) or safety factors k of a safety margin curve (:mod:`.error_predictors`).

    The robot starts inside the envelope (III-E) and the model vouches for nothing before its first sample,
    so the search starts at theta_1; a curve already at or below the operating point there predicts failure at
    once: 0.
    """
    found = boundaries(predict, operating_points, theta_1, theta_end, n_grid)
    return Boundaries(np.where(found.status == "below_at_start", 0.0, found.theta_p), found.status)


def flagged(operating_points: np.ndarray, status: str) -> Boundaries:
    """Every operating point (n_t, k or h) flagged with ``status`` and theta_p NaN."""
    return Boundaries(np.full(np.shape(operating_points), np.nan), np.full(np.shape(operating_points), status))


@dataclass(frozen=True)
class LongRange:
    """The long range predictor's answer for one dataset: theta_p per threshold and the fit behind it."""

    prediction: Boundaries
    fitted: FittedModel | None  # None when there were too few stops
    theta: np.ndarray  # (m,) the fitted samples
    n_inliers: np.ndarray  # (m,)


def long_range(
    series: Series, n_sampled_stops: int, model: str, thresholds: np.ndarray, fit: FitParams, rng: np.random.Generator,
    n_grid: int,
) -> LongRange:
    """Long range predictor (III-E, V-A): fit the first ``n_sampled_stops`` stops once, theta_p for every n_t.

    "too_few_stops" (theta_p NaN) when fewer than ``n_sampled_stops`` stops have a valid inlier count, e.g. all-NaN
    counts. The fit's status (``fitted.status``) holds for every threshold.
    """
    thresholds = operating_points("thresholds", thresholds, "n_t")
    stops, theta_stops = stop_positions(series)
    if stops.size < n_sampled_stops:
        return LongRange(flagged(thresholds, "too_few_stops"), None, np.empty(0), np.empty(0))
    fitted, theta, n_inliers = fit_stops(series, stops[:n_sampled_stops], model, fit, rng)
    prediction = envelope_prediction(fitted.predict, thresholds, theta_stops[0], series.theta_end, n_grid)
    return LongRange(prediction, fitted, theta, n_inliers)


def next_step_stops(theta_p: np.ndarray, theta_i: float, theta_b: float) -> np.ndarray:
    """III-E's rule: stop the robot when theta_p < theta_i + theta_b. (T,) float -> (T,) bool (True: stop).
    theta_i and theta_b must be finite (ArgumentError naming them): a NaN would never stop the robot."""
    check_scalar("theta_i", theta_i)
    check_scalar("theta_b", theta_b, low=0.0)
    return np.asarray(theta_p, dtype=float) < theta_i + theta_b


def sampling_interval(theta_stops: np.ndarray) -> float:
    """theta_b of the next-step predictor: the dataset's sampling interval (median gap between stops).
    theta_stops : (s,) at least 2 finite increasing stop positions (ArgumentError naming it otherwise)."""
    theta_stops = check_increasing("theta_stops", theta_stops)
    if len(theta_stops) < 2:
        raise ArgumentError(f"theta_stops: a sampling interval needs at least 2 stops, got {len(theta_stops)}")
    return float(np.median(np.diff(theta_stops)))


@dataclass(frozen=True)
class NextStep:
    """Next-step answer for one dataset: where the robot stops per threshold (its SPL position, V-B), status, fits."""

    prediction: Boundaries  # theta_p = where the robot stops; status "stopped" | "end_of_path" | "too_few_stops"
    boundary: np.ndarray  # (T,) the model's theta_p at the stop that stopped the robot (NaN: never stopped)
    fit_status: np.ndarray  # (T,) str, the most severe status of the fits the robot went by (NO_FIT: none)
    fit_reason: np.ndarray  # (T,) str, "ok" or the reason of the first fit of that status
    n_fits: int


def next_step(
    series: Series, n_sampled_stops: int, model: str, thresholds: np.ndarray, fit: FitParams, seed: int, method: str,
    n_grid: int,
) -> NextStep:
    """Next-step predictor (III-E, IV-A, V-B) run over a recorded dataset for every threshold at once.

    The robot samples the first ``n_sampled_stops`` stops (IV-A: "the first 4 sampling positions ... to generate
    initial artifact models"); from the last of them on, at every stop i the model is refitted on all stops so far
    and theta_p(n_t) found; a threshold whose theta_p < theta_i + theta_b (theta_b: the sampling interval, IV-A)
    stops the robot where it is, so its SPL position is theta_i (V-B: "the viewing angle where the predictor would
    stop the robot"). Thresholds never stopped reach the last stop ("end_of_path"); a non-finite n_t is flagged
    "bad_threshold". Fits stop once every threshold has stopped. A threshold's fit status is the most severe
    status among the fits it went by (up to and including the one that stopped it): its path relied on each.
    """
    thresholds = operating_points("thresholds", thresholds, "n_t")
    _, theta_stops = stop_positions(series)

    def boundary(stops: np.ndarray, moving: np.ndarray) -> tuple[np.ndarray, str, str]:
        fitted, _, _ = fit_stops(series, stops, model, fit, fit_rng(seed, method, series, stops.size))
        return (envelope_prediction(fitted.predict, moving, theta_stops[0], series.theta_end, n_grid).theta_p,
                fitted.status, fitted.reason)

    return supervise(series, n_sampled_stops, thresholds, boundary)


def supervise(series: Series, n_sampled_stops: int, operating_points: np.ndarray,
              boundary: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, str, str]]) -> NextStep:
    """III-E's next-step supervision for every operating point at once, whatever predicts the boundary.

    operating_points : (T,) float, checked by the caller: :func:`next_step`'s n_t, or the safety factors k of
    :func:`~.error_predictors.error_next_step`; a non-finite one is flagged "bad_threshold"
    boundary(stops, operating_points) -> (theta_p (T',), fit status, fit reason): the boundary predicted from the
    samples of ``stops`` (all stops so far) for each operating point still moving. From the last of the
    ``n_sampled_stops`` sampled stops on, an operating point whose theta_p < theta_i + theta_b stops the robot at
    theta_i (:func:`next_step`)."""
    stops, theta_stops = stop_positions(series)
    no_fit = np.full(np.shape(operating_points), NO_FIT)
    if stops.size < max(n_sampled_stops, 2):
        nan = np.full(np.shape(operating_points), np.nan)
        return NextStep(flagged(operating_points, "too_few_stops"), nan, no_fit, np.full(nan.shape, "too few stops"),
                        0)
    theta_b = sampling_interval(theta_stops)
    stop_at = np.full(np.shape(operating_points), theta_stops[-1])
    boundary_at = np.full(np.shape(operating_points), np.nan)
    moving = np.isfinite(operating_points)
    severity = np.zeros(np.shape(operating_points), dtype=int)  # index into FIT_STATUSES
    fit_reason = np.full(np.shape(operating_points), OK, dtype=object)
    n_fits = 0
    for i in range(n_sampled_stops - 1, stops.size):
        if not moving.any():
            break
        theta_p, status, reason = boundary(stops[: i + 1], operating_points[moving])
        n_fits += 1
        worse = moving & (FIT_STATUSES.index(status) > severity)
        severity[worse], fit_reason[worse] = FIT_STATUSES.index(status), f"fit on {i + 1} stops: {reason}"
        stop = next_step_stops(theta_p, theta_stops[i], theta_b)
        index = moving.nonzero()[0][stop]
        stop_at[index], boundary_at[index] = theta_stops[i], theta_p[stop]
        moving[index] = False
    status = np.where(moving, "end_of_path", "stopped").astype(object)
    bad = ~np.isfinite(operating_points)
    stop_at[bad], status[bad] = np.nan, "bad_threshold"
    fit_status = np.where(bad, NO_FIT, np.array(FIT_STATUSES)[severity])
    fit_reason[bad] = "bad threshold"
    return NextStep(Boundaries(stop_at, status.astype(str)), boundary_at, fit_status, fit_reason.astype(str), n_fits)


def first_stop_mean(series: Series) -> float:
    """Mean n_i over the images of the first stop with a valid count (NaN without one): the reference of the
    relative thresholds."""
    stops, _ = stop_positions(series)
    if stops.size == 0:
        return float("nan")
    counts = series.n_inliers[(series.stop == stops[0]) & np.isfinite(series.n_inliers)]
    return float(counts.mean())


def relative_thresholds(series: Series, fractions: np.ndarray) -> np.ndarray:
    """Beyond the paper: n_t = fraction x mean n_i at the first stop, so that one operating point means the same
    share of a target's features whatever its texture. fractions : (R,) -> (R,) inlier thresholds."""
    return np.asarray(fractions, dtype=float) * first_stop_mean(series)


def static_baseline(sizes: np.ndarray) -> Boundaries:
    """The naive baseline (IV-A): theta_p = the envelope size, whatever the dataset. sizes : (S,) deg or mm."""
    sizes = np.asarray(sizes, dtype=float)
    return Boundaries(sizes.copy(), np.full(sizes.shape, "static"))
