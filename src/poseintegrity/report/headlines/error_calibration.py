"""How well the predicted error is calibrated (``artifacts.json`` ``error_prediction.<world>.<tolerance>``, stage 02):
the share of frames whose measured E_t lies within 1 and 2 predicted sigma, the median ratio, the rank correlations;
shown beside the predictors that use it."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.sections import Headline


def calibration_rows(world: str) -> list[Headline]:
    """How well the predicted error is calibrated (artifacts.json error_prediction.<world>.<tolerance>, stage 02)."""
    rows = []
    for tolerance in paper.TOLERANCES:
        label, key = paper.TOLERANCE_LABELS[tolerance], f"error_prediction.{world}.{tolerance}"
        rows += [
            Headline("artifacts", f"{key}.within_2sigma_t", f"predicted error, {world} world, frames before theta_a "
                     f"({label}): measured E_t within 2 predicted sigma", target=">= 90 %",
                     why="the median measured / predicted E_t is near 1 (rows below), so the scale is right, but the "
                     "tails are heavier than a Gaussian's; the error predictors' safety factor k (1.4-3.5, chosen at "
                     "zero incursion) absorbs them",
                     fmt="{:.0%}", section="predictors"),
            Headline("artifacts", f"{key}.within_1sigma_t", "... within 1 sigma (a Gaussian: 61-68 %)", fmt="{:.0%}",
                     section="predictors"),
            Headline("artifacts", f"{key}.median_ratio_t", "... median measured / predicted E_t", fmt="{:.2f}",
                     section="predictors"),
            Headline("artifacts", f"{key}.unconditioned.median_ratio_t", "... the same without the inlier test's "
                     "conditioning (plain first order)", fmt="{:.2f}", section="predictors"),
            Headline("artifacts", f"{key}.spearman_t", "... rank correlation with E_t per frame", fmt="{:.2f}",
                     section="predictors"),
            Headline("artifacts", f"{key}.spearman_n_i_t", "... that of -n_i, beside it", fmt="{:.2f}",
                     section="predictors"),
        ]
    return rows
