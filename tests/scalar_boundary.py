"""A scalar reference for theta_p, the boundary where an artifact model falls to n_t (Windsor et al. III-E).

The package computes theta_p for all thresholds at once (:func:`poseintegrity.prediction.predictors.boundaries`,
a vectorized scan and bisection); this is the independent reference it is checked against (tests) and timed
against (benchmarks/bench_prediction.py): one threshold at a time, scipy.optimize.brentq in the bracket.

Windsor et al. predict failure for theta > theta_p, theta_p the root of f(theta) = n_t found by root finding.
The model need not be monotone, so the boundary is the *first* downward crossing met when moving from the
start of the search range: f is scanned on a grid, and scipy.optimize.brentq refines the root inside the
first grid interval where f - n_t changes sign. The answers when there is no such interval:

    status "root"           f crosses n_t inside the range; theta_p is that root
    status "censored"       f stays above n_t over the whole range; theta_p = theta_end (the range end:
                            no failure predicted within the range, the true boundary is beyond it)
    status "below_at_start" f(theta_start) <= n_t; theta_p = theta_start (failure predicted at once)
    status "non_finite"     f is nan/inf before any crossing; theta_p = the last finite grid point
                            before it (the model vouches for nothing beyond), also when brentq meets
                            a non-finite value inside the bracket
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq


@dataclass(frozen=True)
class EnvelopeBoundary:
    """theta_p : float, same unit as theta (deg or mm);  status : how it was found (module docstring)."""

    theta_p: float
    status: str


def envelope_boundary(
    predict: Callable[[np.ndarray], np.ndarray],
    n_t: float,
    theta_start: float,
    theta_end: float,
    n_scan: int = 256,
    xtol: float = 1e-9,
) -> EnvelopeBoundary:
    """theta_p in [theta_start, theta_end] where predict(theta) first falls to the inlier threshold n_t.

    predict : f, (m,) float -> (m,) float inlier counts (e.g. ``FittedModel.predict``)
    n_scan : grid points for the bracket scan; a crossing and re-crossing inside one grid step is missed
    """
    if not theta_end > theta_start:
        raise ValueError(f"empty search range [{theta_start}, {theta_end}]")
    theta = np.linspace(theta_start, theta_end, n_scan)
    excess = np.asarray(predict(theta), dtype=float) - n_t  # f - n_t; the envelope is where it is > 0
    bad = ~np.isfinite(excess)
    below = ~bad & (excess <= 0.0)
    if below[0]:
        return EnvelopeBoundary(float(theta_start), "below_at_start")
    first_bad = int(np.argmax(bad)) if bad.any() else n_scan
    first_below = int(np.argmax(below)) if below.any() else n_scan
    if first_bad < first_below:
        return EnvelopeBoundary(float(theta[max(first_bad - 1, 0)]), "non_finite")
    if first_below == n_scan:
        return EnvelopeBoundary(float(theta_end), "censored")
    lo, hi = theta[first_below - 1], theta[first_below]
    if excess[first_below] == 0.0:
        return EnvelopeBoundary(float(hi), "root")

    def g(t: float) -> float:
        return float(np.asarray(predict(np.array([t])), dtype=float)[0]) - n_t

    try:
        return EnvelopeBoundary(float(brentq(g, lo, hi, xtol=xtol)), "root")
    except (ValueError, RuntimeError):  # f non-finite between two finite grid points
        return EnvelopeBoundary(float(lo), "non_finite")
