"""Safe path length (eq. 3), incursion rate (eq. 4) and the SPL vs R_i curves of Windsor et al. (IV-E, Figs. 5-8).

A *prediction table* has one row per (predictor, method, trajectory, dataset, tolerance, operating point)
with at least the columns ``predictor, method, trajectory, dataset, tolerance, operating_point, theta_p,
theta_a``; ``operating_point`` is n_t for the predictors and the envelope size for the static baseline.
Rows whose theta_p is NaN are flagged rows (too few stops, bad threshold): they are left out of the curves
and counted in ``n_flagged``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.errors import check_array, check_same_length

CURVE_KEYS = ["predictor", "method", "trajectory", "tolerance", "operating_point"]


def _positions(name: str, values: object) -> np.ndarray:
    """Trajectory positions (deg or mm) as floats: numbers within 1e12 or NaN (unknown), anything else refused."""
    return check_array(name, values, allow_nan=True)


def safe_path_length(theta_p: np.ndarray, theta_a: np.ndarray) -> np.ndarray:
    """Eq. (3): SPL = min(theta_p, theta_a). (m,), (m,) -> (m,), deg or mm; NaN where theta_p or theta_a is NaN.
    ArgumentError naming both when their lengths differ, or naming one that holds something other than numbers
    (NaN is the documented unknown; inf, 1e300 and booleans are refused)."""
    theta_p, theta_a = _positions("theta_p", theta_p), _positions("theta_a", theta_a)
    if theta_p.shape != theta_a.shape:
        check_same_length(theta_p=np.atleast_1d(theta_p), theta_a=np.atleast_1d(theta_a))
    return np.minimum(theta_p, theta_a)


def incursion(theta_p: np.ndarray, theta_a: np.ndarray) -> np.ndarray:
    """An incursion of eq. (4): theta_p > theta_a, the predictor lets the robot past the actual envelope.

    (m,), (m,) -> (m,) float: 1.0 incursion, 0.0 none, NaN where theta_p is NaN (a flagged row) or theta_a is NaN
    (an unknown envelope: no incursion can be told, never 0). ArgumentError naming both when their lengths differ.
    A censored theta_a (no failure observed up to the last stop) still counts: theta_p never exceeds the range
    end, which is the last stop in our datasets, so this cannot invent an incursion there. Arguments are refused as
    by :func:`safe_path_length`.
    """
    theta_p, theta_a = _positions("theta_p", theta_p), _positions("theta_a", theta_a)
    if theta_p.shape != theta_a.shape:
        check_same_length(theta_p=np.atleast_1d(theta_p), theta_a=np.atleast_1d(theta_a))
    return np.where(np.isnan(theta_p) | np.isnan(theta_a), np.nan, (theta_p > theta_a).astype(float))


def with_metrics(table: pd.DataFrame) -> pd.DataFrame:
    """The table with columns ``spl`` (eq. 3) and ``incursion`` (eq. 4's indicator) added."""
    return table.assign(
        spl=safe_path_length(table["theta_p"], table["theta_a"]),
        incursion=incursion(table["theta_p"], table["theta_a"]),
    )


def operating_curves(table: pd.DataFrame) -> pd.DataFrame:
    """The SPL vs R_i curves: one row per (predictor, method, trajectory, tolerance, operating point).

    Columns: the keys, mean_spl (over the unflagged datasets), incursion_rate R_i = I / n (eq. 4),
    n (unflagged datasets), n_flagged.
    """
    table = with_metrics(table) if "spl" not in table else table
    grouped = table.assign(flagged=table["theta_p"].isna()).groupby(CURVE_KEYS, sort=True)
    return grouped.agg(
        mean_spl=("spl", "mean"),
        incursion_rate=("incursion", "mean"),
        n=("incursion", "count"),
        n_flagged=("flagged", "sum"),
    ).reset_index()


def best_operating_point(
    curve: pd.DataFrame, max_incursion_rate: float, conservative_high: bool
) -> tuple[float, float]:
    """(max mean SPL with R_i <= max_incursion_rate, the operating point achieving it) of one curve.

    (NaN, NaN) when no operating point is that safe. With max_incursion_rate = 0 this is Tables I-III's
    "maximum mean SPL at zero incursion" and its threshold.
    curve : rows of :func:`operating_curves` for one predictor / method / trajectory / tolerance
    conservative_high : among ties, take the largest operating point (True: n_t, larger is more conservative)
        or the smallest (False: static envelope size)
    """
    safe = curve[(curve["incursion_rate"] <= max_incursion_rate) & (curve["n"] > 0)]
    if safe.empty:
        return float("nan"), float("nan")
    best = safe[safe["mean_spl"] == safe["mean_spl"].max()]["operating_point"]
    return float(safe["mean_spl"].max()), float(best.max() if conservative_high else best.min())


def relative_improvement(ours: float, baseline: float) -> float:
    """(ours - baseline) / baseline, as in Tables I-II (0.841 = 84.1 %); NaN if the baseline is 0 or NaN."""
    return float((ours - baseline) / baseline) if baseline and np.isfinite(baseline) else float("nan")
