"""The ceiling of any predictor's gain over the static baseline, and the share of it a predictor takes (ours).

Windsor et al. judge a predictor by its mean safe path length (eq. 3) at zero incursion against the static baseline
(Tables I-II). How much there is to gain depends on the lab: a predictor that knew every envelope would stop each
robot exactly at theta_a and reach mean SPL = mean theta_a with no incursion, while one envelope size for all can be
no larger than the smallest theta_a. So

    gain  = mean theta_a / min theta_a - 1                     the ceiling of any predictor's gain over static
    share = (SPL - SPL_static) / (mean theta_a - SPL_static)   the part of that gap a predictor takes

and the share compares predictors across worlds and recordings whose envelopes spread differently (1: it knew every
envelope; 0: no better than one size for all; below 0: worse). Arcs of the paper's PnP path, as Tables I-II.
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def ceiling(table: pd.DataFrame, best: pd.DataFrame, method: str, tolerances: list[str],
            trajectory: str = "arc") -> dict:
    """``<tolerance>.{n_arcs, mean_theta_a, min_theta_a, static_spl, gain}`` of one world (module docstring).

    table : prediction rows of one world (dataset, trajectory, method, tolerance, theta_a; the scored ones)
    best : :func:`~poseintegrity.prediction.paper_tables.best_table` of the same world (the static baseline's max mean SPL
        at zero incursion). NaN figures (and n_arcs 0) where the world has no such datasets.
    """
    rows = table[(table["trajectory"] == trajectory) & (table["method"] == method)]
    static = best[(best["predictor"] == "static") & (best["trajectory"] == trajectory) & (best["method"] == method)]
    metrics: dict = {}
    for tolerance in tolerances:
        theta_a = rows[rows["tolerance"] == tolerance].drop_duplicates("dataset")["theta_a"].to_numpy(dtype=float)
        spl = static.loc[static["tolerance"] == tolerance, "max_mean_spl"]
        mean, low = (float(theta_a.mean()), float(theta_a.min())) if theta_a.size else (np.nan, np.nan)
        metrics[tolerance] = {"n_arcs": int(theta_a.size), "mean_theta_a": mean, "min_theta_a": low,
                              "static_spl": float(spl.iloc[0]) if len(spl) else np.nan,
                              "gain": mean / low - 1.0 if low > 0 else np.nan}
    return metrics


def ceiling_share(spl: float, entry: dict) -> float:
    """(SPL - SPL_static) / (mean theta_a - SPL_static) for one ``ceiling`` entry; NaN where SPL or the entry is NaN
    or the static baseline already reaches mean theta_a (no gap to take a share of)."""
    gap = entry["mean_theta_a"] - entry["static_spl"]
    if not (np.isfinite(spl) and np.isfinite(gap)) or gap <= 0:
        return float("nan")
    return float((spl - entry["static_spl"]) / gap)
