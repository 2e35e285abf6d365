"""The exact-pose diagnostic (``predictors.json`` and ``validation.json`` ``exact_pose_diagnostic``, stage 04): Tables
I-II with theta_a against the renderer's exact pose (deg), not the paper's metric."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.sections import Headline


def exact_pose_rows(stage: str) -> list[Headline]:
    """``exact_pose_diagnostic`` (predictors.json, validation.json): Tables I-II with theta_a against the renderer's
    exact pose. A diagnostic, not the paper's metric (IV-C measures against the board)."""
    names = {"static": "static baseline", "mlp": "MLP", "long_range": "long range", "next_step": "next step"}
    rows = []
    for tolerance in paper.TOLERANCES:
        label = paper.TOLERANCE_LABELS[tolerance]
        for predictor, name in names.items():
            rows.append(Headline(stage, f"exact_pose_diagnostic.{predictor}.{tolerance}.max_mean_spl_zero_incursion",
                                 f"diagnostic, not the paper's metric: errors vs the exact pose, {name}, {label} (deg)"))
            if predictor in ("long_range", "next_step"):
                rows.append(Headline(stage, f"exact_pose_diagnostic.{predictor}.{tolerance}.best_operating_point",
                                     "... its threshold n_t"))
    return rows + [Headline(stage, f"exact_pose_diagnostic.{p}.relative_improvement",
                            f"diagnostic: {p.replace('_', ' ')} over static, errors vs the exact pose", fmt="{:+.1%}")
                   for p in ("long_range", "next_step")]
