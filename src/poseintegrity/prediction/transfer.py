"""Operating points chosen on one world, applied unchanged to another (the generalisation check of stage 04).

Windsor et al. choose each predictor's threshold n_t (and the static baseline its size) where the mean SPL is
largest at zero incursion on their datasets (Tables I-III), and then use n_t = 15 on live trials of another scene
(V-C: "some generalization capability in terms of transferring parameters"). Here the operating points are chosen
on the main world, as the paper does, and applied to a validation world nothing was tuned on: its incursion rate
R_i (eq. 4) and mean SPL (eq. 3) at that operating point say whether the headline survives a change of scenery.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.prediction.ceiling import ceiling_share

KEYS = ["predictor", "method", "trajectory", "tolerance"]
DECIMALS = 9  # operating points of both worlds come from the same grids; rounding makes them comparable exactly


def transfer(best: pd.DataFrame, curves: pd.DataFrame) -> pd.DataFrame:
    """The other world's curve read at each operating point chosen on the first.

    best : :func:`~poseintegrity.prediction.paper_tables.best_table` of the world the points were chosen on
    curves : :func:`~poseintegrity.prediction.metrics.operating_curves` of the world they are applied to
    Returns one row per row of ``best`` (keys, ``operating_point``, ``chosen_mean_spl``: the mean SPL where it was
    chosen) with that world's ``incursion_rate``, ``mean_spl`` and ``n`` at the same operating point; NaN where the
    first world had no zero-incursion point or the second has no such curve.
    """
    chosen = best.rename(columns={"best_operating_point": "operating_point", "max_mean_spl": "chosen_mean_spl"})
    chosen = chosen.assign(point=chosen["operating_point"].round(DECIMALS))
    applied = curves.assign(point=curves["operating_point"].round(DECIMALS))[
        [*KEYS, "point", "incursion_rate", "mean_spl", "n"]]
    merged = chosen.merge(applied, on=[*KEYS, "point"], how="left").drop(columns="point")
    return merged[[*KEYS, "operating_point", "chosen_mean_spl", "incursion_rate", "mean_spl", "n"]]


def transfer_metrics(transferred: pd.DataFrame, predictors: tuple[str, ...], method: str,
                     trajectory: str = "arc", limits: dict | None = None) -> dict:
    """``<predictor>.<tolerance>.{operating_point, incursion_rate, mean_spl}`` of :func:`transfer` rows (NaN: none),
    and ``ceiling_share`` of that mean SPL where ``limits`` (the world's :func:`~.ceiling.ceiling`) is given. A
    transferred operating point that incurs on the other world keeps its mean SPL and share: its incursion rate
    says what they cost."""
    rows = transferred[(transferred["method"] == method) & (transferred["trajectory"] == trajectory)]
    metrics: dict = {}
    for predictor in predictors:
        entry = {}
        for row in rows[rows["predictor"] == predictor].itertuples():
            mean_spl = float(row.mean_spl) if np.isfinite(row.mean_spl) else np.nan
            entry[row.tolerance] = {"operating_point": float(row.operating_point),
                                    "incursion_rate": float(row.incursion_rate), "mean_spl": mean_spl}
            if limits is not None:
                entry[row.tolerance]["ceiling_share"] = ceiling_share(mean_spl, limits[row.tolerance])
        metrics[predictor] = entry
    return metrics
