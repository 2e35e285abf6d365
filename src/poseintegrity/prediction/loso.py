"""Choosing n_t from a failure tolerance by leave-one-scene-out cross-validation (Windsor et al. VI, future work).

For a target incursion rate r*, the threshold is chosen on every scene but one as the operating point with the
largest mean SPL among those with R_i <= r* (the most conservative one if none is that safe, flagged
``feasible`` False), then scored on the held-out scene's datasets. Pooled over folds: the held-out R_i = I / n
(eq. 4) and mean SPL (eq. 3) say whether a threshold chosen on some scenes stays safe on unseen ones.

The scene of a dataset id is the part before ``_arc`` / ``_line`` (``scene_3_arc090`` -> ``scene_3``).
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from poseintegrity.prediction.metrics import best_operating_point, operating_curves

FOLD_COLUMNS = [
    "predictor", "tolerance", "target_rate", "scene", "operating_point", "feasible", "heldout_incursions",
    "heldout_n", "heldout_spl_sum",
]  # fmt: skip


def scene_of(dataset: str) -> str:
    """``scene_3_arc090`` -> ``scene_3``; an id without ``_arc`` / ``_line`` is its own scene."""
    return re.split(r"_(?:arc|line)", dataset, maxsplit=1)[0]


def loso_folds(table: pd.DataFrame, target_rates: tuple[float, ...], conservative_high: bool) -> pd.DataFrame:
    """One row per target rate and held-out scene (rates in the given order, scenes sorted) for one predictor /
    tolerance / method / trajectory of a prediction table; each scene's training curve serves every rate.

    table : rows of one curve family with columns dataset, operating_point, theta_p, spl, incursion (and the
        curve keys). Needs at least two scenes; with one scene the result is empty.
    """
    scenes = table["dataset"].map(scene_of)
    rows: dict[float, list[dict]] = {rate: [] for rate in target_rates}
    for scene in sorted(scenes.unique()):
        train, test = table[scenes != scene], table[scenes == scene]
        if train.empty:
            continue
        curve = operating_curves(train)
        for rate in target_rates:
            _, point = best_operating_point(curve, rate, conservative_high)
            feasible = bool(np.isfinite(point))
            if not feasible:  # nothing that safe on the training scenes: the most conservative operating point
                points = curve["operating_point"]
                point = float(points.max() if conservative_high else points.min())
            held = test[(test["operating_point"] == point) & test["theta_p"].notna()]
            rows[rate].append(
                dict(predictor=str(table["predictor"].iloc[0]), tolerance=str(table["tolerance"].iloc[0]),
                     target_rate=rate, scene=scene, operating_point=point, feasible=feasible,
                     heldout_incursions=float(held["incursion"].sum()), heldout_n=int(len(held)),
                     heldout_spl_sum=float(held["spl"].sum()))
            )  # fmt: skip
    return pd.DataFrame([row for rate in target_rates for row in rows[rate]], columns=FOLD_COLUMNS)


def loso(
    table: pd.DataFrame, target_rates: tuple[float, ...], predictors: tuple[str, ...], method: str,
    trajectory: str = "arc",
) -> pd.DataFrame:  # fmt: skip
    """LOSO folds for every predictor, tolerance and target rate on one PnP method and trajectory type."""
    rows = table[(table["method"] == method) & (table["trajectory"] == trajectory)]
    folds = [
        loso_folds(group, tuple(target_rates), conservative_high=predictor != "static")
        for (predictor, _), group in rows[rows["predictor"].isin(predictors)].groupby(["predictor", "tolerance"])
    ]
    return pd.concat(folds, ignore_index=True) if folds else pd.DataFrame(columns=FOLD_COLUMNS)


def pooled(folds: pd.DataFrame) -> pd.DataFrame:
    """The folds pooled per (predictor, tolerance, target_rate): one row each, sorted, with

    heldout_incursion_rate : held-out incursions / held-out datasets (eq. 4 over all folds; NaN without any)
    heldout_mean_spl : mean SPL over all held-out datasets (eq. 3);  heldout_n : held-out datasets
    n_infeasible_folds : folds where no operating point met the target on the training scenes
    """
    grouped = folds.assign(infeasible=~folds["feasible"].astype(bool)).groupby(
        ["predictor", "tolerance", "target_rate"], sort=True)
    sums = grouped.agg(incursions=("heldout_incursions", "sum"), heldout_n=("heldout_n", "sum"),
                       spl=("heldout_spl_sum", "sum"), n_infeasible_folds=("infeasible", "sum"))
    n = sums["heldout_n"].where(sums["heldout_n"] > 0)  # NaN rates for no held-out dataset, not a division by zero
    return pd.DataFrame({
        "heldout_incursion_rate": sums["incursions"] / n, "heldout_mean_spl": sums["spl"] / n,
        "heldout_n": sums["heldout_n"].astype(int), "n_infeasible_folds": sums["n_infeasible_folds"].astype(int),
    }).reset_index()  # fmt: skip


def loso_summary(folds: pd.DataFrame, target_rate: float) -> dict:
    """predictor -> tolerance -> the :func:`pooled` held-out figures at ``target_rate``, with target_incursion_rate
    and the operating point chosen per held-out scene (``thresholds``)."""
    at_rate = folds[folds["target_rate"] == target_rate]
    summary: dict = {}
    for row in pooled(at_rate).itertuples(index=False):
        group = at_rate[(at_rate["predictor"] == row.predictor) & (at_rate["tolerance"] == row.tolerance)]
        summary.setdefault(str(row.predictor), {})[str(row.tolerance)] = {
            "target_incursion_rate": float(target_rate),
            "heldout_incursion_rate": float(row.heldout_incursion_rate),
            "heldout_mean_spl": float(row.heldout_mean_spl),
            "n_infeasible_folds": int(row.n_infeasible_folds),
            "thresholds": {str(s): float(p) for s, p in zip(group["scene"], group["operating_point"], strict=True)},
        }
    return summary
