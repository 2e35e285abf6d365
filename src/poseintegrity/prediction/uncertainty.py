"""A prediction interval on theta_p (beyond Windsor et al.) and the variant that stops on its lower bound.

Two ways, chosen by ``predict.uncertainty.method``:

    covariance  the least squares parameter covariance of a base-function fit (eq. 1 for the EMG; pseudo-inverse),
                    P = s^2 (J^T J)^+,   s^2 = RSS / (m - p),   J = d f(theta_j; params) / d params  (m, p)
                gives the pointwise band f(theta) -/+ z sd_f(theta), sd_f^2 = J(theta) P J(theta)^T (delta
                method); the interval on theta_p is where the lower / upper band curves cross n_t, found with
                the same :func:`boundaries` as theta_p itself (so censored and below-at-start answers carry over)
    bootstrap   refit on the images resampled with replacement, ``n_bootstrap`` times; the interval is the
                (1 - level)/2 and (1 + level)/2 percentiles of the refits' theta_p (any artifact model)

A fit that fell back to its line (status "fallback", artifact_models/fitted.py) gives no interval: (NaN, NaN)
with a reason, and the lower-bound variant then flags the row. A fit at a bound or non-physical gets one from its
fitted curve, as its theta_p does; its rows carry that fit status.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.stats import norm

from poseintegrity.artifact_models import FittedModel, fit_model
from poseintegrity.params.fit import FitParams
from poseintegrity.artifact_models.base_functions import BaseCurve
from poseintegrity.params.predict import UncertaintyParams
from poseintegrity.prediction.predictors import envelope_prediction


@dataclass(frozen=True)
class Interval:
    """lower, upper : (T,) float, deg or mm, per threshold (NaN: no interval);  reason : "ok" or why not."""

    lower: np.ndarray
    upper: np.ndarray
    reason: str


def parameter_jacobian(curve: BaseCurve, theta: np.ndarray) -> np.ndarray:
    """d f(theta; p) / d p : (m, p) by central differences (step 1e-6 relative) for any base function."""
    p = np.asarray(curve.p, dtype=float)
    columns = []
    for j in range(p.size):
        h = 1e-6 * max(abs(p[j]), 1.0)
        up, down = p.copy(), p.copy()
        up[j] += h
        down[j] -= h
        columns.append((curve.f(theta, *up) - curve.f(theta, *down)) / (2.0 * h))
    return np.stack(columns, axis=1)


def parameter_covariance(fitted: FittedModel, theta: np.ndarray, n_inliers: np.ndarray) -> np.ndarray | None:
    """P = s^2 (J^T J)^+ of a fitted base-function curve : (p, p); None for a fallback, an MLP or m <= p samples.

    theta, n_inliers : (m,) the fitted samples (invalid ones are dropped as the fit dropped them)
    """
    if not (fitted.has_curve and isinstance(fitted.curve, BaseCurve)):
        return None
    keep = np.isfinite(theta) & np.isfinite(n_inliers) & (n_inliers >= 0)
    theta, n_inliers = theta[keep], n_inliers[keep]
    J = parameter_jacobian(fitted.curve, theta)
    dof = theta.size - J.shape[1]
    if dof <= 0:
        return None
    s2 = float(np.sum((n_inliers - fitted.curve(theta)) ** 2)) / dof
    # (J^T J)^+ from the SVD of J, not of J^T J: on the exponential tail of eq. 1 alpha and mu nearly trade off
    # (cond(J) ~ 1e8), which squaring would push below double precision; cut-off as numpy.linalg.lstsq's
    _, S, Vt = np.linalg.svd(J, full_matrices=False)
    keep = S > S[0] * max(J.shape) * np.finfo(float).eps
    return s2 * (Vt[keep].T / S[keep] ** 2) @ Vt[keep]


def covariance_interval(
    fitted: FittedModel, theta: np.ndarray, n_inliers: np.ndarray, thresholds: np.ndarray,
    theta_1: float, theta_end: float, level: float, n_grid: int,
) -> Interval:  # fmt: skip
    """Delta-method interval: where f -/+ z sd_f crosses each n_t (module docstring). theta, n_inliers : (m,)."""
    P = parameter_covariance(fitted, np.asarray(theta, float), np.asarray(n_inliers, float))
    if P is None:
        nan = np.full(np.shape(thresholds), np.nan)
        return Interval(nan, nan, "no covariance: the fit is not a fitted base function with m > p samples")
    z = float(norm.ppf(0.5 + level / 2.0))

    def band(sign: float) -> Callable[[np.ndarray], np.ndarray]:
        def f(t: np.ndarray) -> np.ndarray:
            J = parameter_jacobian(fitted.curve, np.asarray(t, dtype=float))
            sd = np.sqrt(np.maximum(np.einsum("mi,ij,mj->m", J, P, J), 0.0))
            return fitted.curve(t) + sign * z * sd

        return f

    lower = envelope_prediction(band(-1.0), thresholds, theta_1, theta_end, n_grid).theta_p
    upper = envelope_prediction(band(+1.0), thresholds, theta_1, theta_end, n_grid).theta_p
    return Interval(lower, upper, "ok")


def bootstrap_interval(
    model: str, theta: np.ndarray, n_inliers: np.ndarray, thresholds: np.ndarray, *, theta_end: float,
    fit: FitParams, level: float, n_bootstrap: int, rng: np.random.Generator, n_grid: int,
) -> Interval:  # fmt: skip
    """Percentile interval of theta_p over refits on images resampled with replacement. theta, n_inliers : (m,).

    Refits that fall back to their line are left out; fewer than two fitted refits give (NaN, NaN).
    """
    theta, n_inliers = np.asarray(theta, dtype=float), np.asarray(n_inliers, dtype=float)
    theta_1 = float(np.nanmin(theta)) if theta.size else np.nan
    draws = []
    for _ in range(n_bootstrap):
        index = rng.integers(0, theta.size, theta.size)
        refit = fit_model(model, theta[index], n_inliers[index], theta_end=theta_end, params=fit, rng=rng)
        if refit.has_curve:
            draws.append(envelope_prediction(refit.predict, thresholds, theta_1, theta_end, n_grid).theta_p)
    if len(draws) < 2:
        nan = np.full(np.shape(thresholds), np.nan)
        return Interval(nan, nan, f"only {len(draws)} of {n_bootstrap} bootstrap refits fitted a curve")
    q = 100.0 * np.array([0.5 - level / 2.0, 0.5 + level / 2.0])
    lower, upper = np.percentile(np.stack(draws), q, axis=0)
    return Interval(lower, upper, "ok")


def prediction_interval(
    model: str, fitted: FittedModel, theta: np.ndarray, n_inliers: np.ndarray, thresholds: np.ndarray, *,
    theta_end: float, fit: FitParams, uncertainty: UncertaintyParams, rng: np.random.Generator, n_grid: int,
) -> Interval:  # fmt: skip
    """The interval on theta_p chosen by ``uncertainty.method`` for samples (theta, n_inliers) fitted as ``fitted``."""
    if np.size(theta) == 0:
        nan = np.full(np.shape(thresholds), np.nan)
        return Interval(nan, nan, "no samples")
    if uncertainty.method == "covariance":
        theta_1 = float(np.nanmin(theta))
        return covariance_interval(fitted, theta, n_inliers, thresholds, theta_1, theta_end, uncertainty.level, n_grid)
    return bootstrap_interval(
        model, theta, n_inliers, thresholds, theta_end=theta_end, fit=fit, level=uncertainty.level,
        n_bootstrap=uncertainty.n_bootstrap, rng=rng, n_grid=n_grid,
    )  # fmt: skip
