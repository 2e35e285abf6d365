"""Ours, not the paper's (``predictors.json``, stage 04): long range and next step on the free-width EMG beside theirs
on eq. 1 (max mean SPL at zero incursion, deg; n_t), and the arcs whose long range theta_p overshoots theta_a (the
tail diagnosis)."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.fits import FIT_STATUS_LABELS
from poseintegrity.report.headlines.sections import Headline

FREE_WIDTH_LABELS = {"long_range_free_width": ("long range", "long_range"),
                     "next_step_free_width": ("next step", "next_step")}  # ours -> (name, the paper's predictor)


def free_width_rows() -> list[Headline]:
    """Ours, not the paper's: the predictors on the free-width EMG beside theirs on eq. 1, and the tail diagnosis (the
    arcs whose long range theta_p overshoots theta_a at every n_t <= predict.tail_n_t_max)."""
    rows = []
    for tolerance in paper.TOLERANCES:
        label = paper.TOLERANCE_LABELS[tolerance]
        for predictor, (name, _) in FREE_WIDTH_LABELS.items():
            rows += [
                Headline("predictors", f"{predictor}.{tolerance}.max_mean_spl_zero_incursion",
                         f"ours: {name} on the free-width EMG, {label}: max mean SPL at zero incursion (deg)"),
                Headline("predictors", f"{predictor}.{tolerance}.best_n_t", "... its threshold n_t"),
            ]
    for predictor, (name, theirs) in FREE_WIDTH_LABELS.items():
        rows.append(Headline("predictors", f"{predictor}.relative_improvement_vs_{theirs}",
                             f"ours: {name} on the free-width EMG over {name} on eq. 1 (mean of both tolerances)",
                             fmt="{:+.1%}"))
        rows += [Headline("predictors", f"fit_status.{predictor}.{status}",
                          f"ours: {name} on the free-width EMG: share of rows on a fit {label}" if status == "ok"
                          else f"... {label}", fmt="{:.1%}")
                 for status, label in FIT_STATUS_LABELS.items()]
    for tolerance in paper.TOLERANCES:
        label = paper.TOLERANCE_LABELS[tolerance]
        for predictor, model in (("long_range", "eq. 1"), ("long_range_free_width", "the free-width EMG")):
            rows += [
                Headline("predictors", f"tails.{predictor}.{tolerance}.n_overshooting",
                         f"ours: arcs whose long range theta_p on {model} overshoots theta_a at every n_t up to "
                         f"predict.tail_n_t_max, {label}"),
                Headline("predictors", f"tails.{predictor}.{tolerance}.datasets", "... which arcs"),
            ]
    return rows
