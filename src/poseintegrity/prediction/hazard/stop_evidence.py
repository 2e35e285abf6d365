"""What the robot knows at each stop of an arc without any ground truth: the failure hazard's evidence (issue 50).

One row per (world, dataset, stop) of ``protocol.pnp_method``, from stage 02's artifacts table (the stop's images
averaged; definitions in docs/references.md, "The failure hazard"). Every quantity is one a robot has at that stop:
no E_t, E_r, board pose or exact pose is read. Errors enter as log10 of their ratio to the tolerance, so that one
model serves the worlds whatever their tolerance, floored at RATIO_FLOOR (a spread of exactly 0 is no evidence of
infinite safety).

Levels at stop i (:data:`LEVELS`):

    log_inliers        log(1 + mean n_i), a frame without a pose counting 0 inliers
    log_min_inliers    log(1 + the fewest n_i among the stop's images)
    posed_share        share of the stop's images with a pose
    inlier_ratio       mean n_i / matches
    reproj_error_px    mean RMS reprojection error of the inliers (px)
    log_hull_area      log(1 + mean area of the inliers' convex hull, px^2)
    model_coverage     mean share of M_t's points among the inliers
    predicted_error    log10 max(sigma_t / tol_t, sigma_r / tol_r): the propagated error (pose_covariance.py)
    kinematic_error    log10 max(E_kinematic / tol): the disagreement with the robot's kinematics
    stop_spread        log10 max(stop spread / tol): how far the poses of the still robot's images scatter
    bootstrap_spread   log10 max(consensus dispersion / tol): the poses re-solved on resampled inliers
    rerun_elsewhere    share of RANSAC re-runs landing elsewhere (the consensus margin's other half)

Trends over the last TREND_STOPS stops (i - 2, i - 1, i), of the levels in :data:`TRENDED`: ``<level>_slope`` (least
squares slope per stop) and ``<level>_acceleration`` (x_i - 2 x_{i-1} + x_{i-2}); 0 where fewer stops are known
(the first stops of an arc). A column stage 02 did not write (an older table; a recording without robot poses)
is NaN: the model fills it with its training median (:mod:`.model`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

RATIO_FLOOR = 1e-3  # error / tolerance below this counts as this (log10: -3)
TREND_STOPS = 3  # the trends' window: the last three stops, as the error predictors' count trend (error_predictors.py)
LEVELS = ("log_inliers", "log_min_inliers", "posed_share", "inlier_ratio", "reproj_error_px", "log_hull_area",
          "model_coverage", "predicted_error", "kinematic_error", "stop_spread", "bootstrap_spread",
          "rerun_elsewhere")
TRENDED = ("log_inliers", "predicted_error", "kinematic_error", "stop_spread", "bootstrap_spread", "inlier_ratio")
TRENDS = tuple(f"{level}_{kind}" for level in TRENDED for kind in ("slope", "acceleration"))
EVIDENCE = (*LEVELS, *TRENDS)  # the columns the hazard models read
ERROR_PAIRS = {  # level -> (translation column mm, rotation column deg) of stage 02's table
    "predicted_error": ("sigma_t_pred_mm", "sigma_r_pred_deg"),
    "kinematic_error": ("E_t_kinematic_mm", "E_r_kinematic_deg"),
    "stop_spread": ("stop_spread_t_mm", "stop_spread_r_deg"),
    "bootstrap_spread": ("consensus_t_mm", "consensus_r_deg"),
}
KEYS = ["world", "dataset", "stop"]


def _column(frames: pd.DataFrame, name: str) -> pd.Series:
    """A column of stage 02's table as floats, NaN where the table has no such column."""
    return frames[name].astype(float) if name in frames.columns else pd.Series(np.nan, frames.index)


def error_ratio(frames: pd.DataFrame, columns: tuple[str, str], tolerance: tuple[float, float]) -> pd.Series:
    """log10 max(t / tol_t, r / tol_r) per frame (NaN where both are NaN), floored at RATIO_FLOOR."""
    ratio = pd.concat([_column(frames, columns[0]) / tolerance[0], _column(frames, columns[1]) / tolerance[1]],
                      axis=1).max(axis=1, skipna=True)
    return np.log10(ratio.clip(lower=RATIO_FLOOR))


def levels(frames: pd.DataFrame, tolerance: tuple[float, float]) -> pd.DataFrame:
    """The :data:`LEVELS` per stop (rows keyed by :data:`KEYS`, with ``theta_deg`` the stop's mean angle).

    frames : stage 02's rows of one PnP method (arcs), with world, dataset, stop, theta_deg, status, n_inliers,
        n_matches, inlier_ratio, reproj_error_px, inlier_hull_area_px2, model_coverage and the error columns of
        ERROR_PAIRS where stage 02 wrote them; tolerance : (mm, deg)
    """
    posed = frames["status"] == "ok"
    inliers = _column(frames, "n_inliers").where(posed, 0.0).fillna(0.0)
    per_frame = pd.DataFrame({
        **{key: frames[key] for key in KEYS}, "theta_deg": frames["theta_deg"].astype(float),
        "inliers": inliers, "posed": posed.astype(float),
        "inlier_ratio": _column(frames, "inlier_ratio").where(posed),
        "reproj_error_px": _column(frames, "reproj_error_px").where(posed),
        "log_hull_area": np.log1p(_column(frames, "inlier_hull_area_px2").where(posed)),
        "model_coverage": _column(frames, "model_coverage").where(posed),
        **{level: error_ratio(frames, columns, tolerance).where(posed) for level, columns in ERROR_PAIRS.items()},
        "rerun_elsewhere": _column(frames, "consensus_elsewhere").where(posed),
    })
    grouped = per_frame.groupby(KEYS, sort=True)
    table = grouped.mean(numeric_only=True)
    table["log_min_inliers"] = np.log1p(grouped["inliers"].min())
    table["log_inliers"] = np.log1p(table.pop("inliers"))
    table["posed_share"] = table.pop("posed")
    return table.reset_index()[[*KEYS, "theta_deg", *LEVELS]]


def with_trends(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` (:func:`levels`, stop order within each dataset) with the :data:`TRENDS` added (module docstring):
    each computed from the arc's own stops up to that stop, never from a later one."""
    table = table.sort_values(KEYS, kind="stable").reset_index(drop=True)
    by_arc = table.groupby(["world", "dataset"], sort=False)
    steps = np.arange(TREND_STOPS, dtype=float) - (TREND_STOPS - 1) / 2  # centred stop indices of the window
    trends = {}
    for level in TRENDED:
        values = table[level]
        lagged = [by_arc[level].shift(lag) for lag in range(TREND_STOPS - 1, -1, -1)]  # x_{i-2}, x_{i-1}, x_i
        window = np.column_stack(lagged)
        slope = (window * steps).sum(axis=1) / (steps**2).sum()  # least squares slope on 3 equally spaced stops
        two = values - by_arc[level].shift(1)  # two stops known: the difference
        trends[f"{level}_slope"] = np.where(np.isfinite(slope), slope, two.fillna(0.0))
        acceleration = window[:, 2] - 2 * window[:, 1] + window[:, 0]
        trends[f"{level}_acceleration"] = np.where(np.isfinite(acceleration), acceleration, 0.0)
    return table.assign(**trends)


def stop_evidence(artifacts: pd.DataFrame, method: str, tolerance: tuple[float, float]) -> pd.DataFrame:
    """Every arc's stops of ``method`` with :data:`EVIDENCE` (module docstring): one row per (world, dataset, stop),
    with ``theta_deg``. artifacts : stage 02's table (its ``usable`` rows); tolerance : (mm, deg)."""
    frames = artifacts[(artifacts["trajectory"] == "arc") & (artifacts["method"] == method)]
    if frames.empty:
        return pd.DataFrame(columns=[*KEYS, "theta_deg", *EVIDENCE])
    return with_trends(levels(frames, tolerance))
