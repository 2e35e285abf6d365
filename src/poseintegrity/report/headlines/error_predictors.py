"""The predictors on the predicted error (``predictors.json`` and ``validation.json``, stage 04,
:mod:`~poseintegrity.prediction.error_predictors`): per tolerance the max mean SPL at zero incursion (deg), the safety
factor k and the share of the ceiling, on the main world, held out by scene and on the validation world."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.sections import Headline

ERROR_NAMES = {"error_long_range": "ours: long range on the predicted error",
               "error_next_step": "ours: next step on the predicted error",
               "error_next_step_observed": "ours: next step on the predicted error, calibrated on each arc by the "
                                           "robot's kinematics",
               "error_combined": "ours: next step, the earlier of n_i's (Table III n_t) and the predicted error's"}


def error_predictor_rows() -> list[Headline]:
    """Issue 38's predictors (prediction/error_predictors.py), beside the paper's: per tolerance their max mean SPL at
    zero incursion, safety factor k and share of the ceiling on the main world, held out by scene (LOSO) and on the
    validation world at the main world's k."""
    rows = []
    for tolerance in paper.TOLERANCES:
        label = paper.TOLERANCE_LABELS[tolerance]
        for predictor, name in ERROR_NAMES.items():
            key = f"{predictor}.{tolerance}"
            rows += [
                Headline("predictors", f"{key}.max_mean_spl_zero_incursion",
                         f"{name}, {label}: max mean SPL at zero incursion (deg)"),
                Headline("predictors", f"{key}.best_k", "... its safety factor k"),
                Headline("predictors", f"{key}.ceiling_share", "... its share of the ceiling", fmt="{:.0%}"),
                Headline("predictors", f"loso.{key}.heldout_incursion_rate", "... held out by scene (LOSO): R_i"),
                Headline("predictors", f"loso.{key}.ceiling_share", "... held out by scene: share of the ceiling",
                         fmt="{:.0%}"),
                Headline("validation", f"transfer.{key}.incursion_rate",
                         f"{name}, {label}, the main world's k: R_i", "0 (live trials, V-C)"),
                Headline("validation", f"transfer.{key}.ceiling_share", "... share of the ceiling", fmt="{:.0%}"),
                Headline("validation", f"{key}.ceiling_share", f"{name}, {label}, its own sweep: share of the ceiling",
                         fmt="{:.0%}"),
            ]
    return rows
