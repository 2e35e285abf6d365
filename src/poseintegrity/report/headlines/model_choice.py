"""Ours (``predictors.json`` ``model_choice``, stage 04): every least squares base function as the long range
predictor's model, per world and tolerance, in sample and held out by scene (mean SPL in deg, R_i)."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.fits import MODEL_LABELS
from poseintegrity.report.headlines.sections import Headline


def model_choice_rows() -> list[Headline]:
    """Ours: every least squares base function as the long range predictor's model (prediction/model_choice.py), on
    each world: in-sample max mean SPL at zero incursion and the held-out figures of the leave-one-scene-out choice."""
    rows = []
    for world in ("main", "validation"):
        for tolerance in paper.TOLERANCES:
            label = paper.TOLERANCE_LABELS[tolerance]
            for model, name in MODEL_LABELS.items():
                if model.startswith("mlp"):
                    continue
                key = f"model_choice.{world}.{model}.{tolerance}"
                rows += [
                    Headline("predictors", f"{key}.max_mean_spl_zero_incursion",
                             f"ours, model choice, {world} world: long range on {name}, {label}: max mean SPL at zero "
                             f"incursion (deg)"),
                    Headline("predictors", f"{key}.heldout_mean_spl", "... held out (leave one scene out): mean SPL (deg)"),
                    Headline("predictors", f"{key}.heldout_incursion_rate", "... held out: R_i"),
                ]
    return rows
