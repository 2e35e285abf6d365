"""The rows of ``validation.json`` (stage 04, the held-out world): per tolerance each predictor at the main world's
operating point (R_i, mean SPL in deg) and at its own best, and its own sweep's relative improvements."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.sections import Headline


def validation_rows() -> list[Headline]:
    """validation.json: per tolerance, each predictor at the main world's operating point (R_i, mean SPL) and at its
    own best; the relative improvements of its own sweep."""
    names = {"static": "static baseline", "mlp": "MLP", "long_range": "long range (eq. 1)", "next_step": "next step",
             "long_range_free_width": "ours: long range, free-width EMG",
             "next_step_free_width": "ours: next step, free-width EMG"}
    rows = []
    for tolerance in paper.TOLERANCES:
        label = paper.TOLERANCE_LABELS[tolerance]
        for predictor, name in names.items():
            rows += [
                Headline("validation", f"transfer.{predictor}.{tolerance}.incursion_rate",
                         f"{name}, {label}, the main world's operating point: R_i", "0 (live trials, V-C)"),
                Headline("validation", f"transfer.{predictor}.{tolerance}.mean_spl", "... mean SPL (deg)"),
                Headline("validation", f"{predictor}.{tolerance}.max_mean_spl_zero_incursion",
                         f"{name}, {label}, its own sweep: max mean SPL at zero incursion (deg)",
                         f"{paper.WINDSOR_SPL_ZERO_INCURSION[predictor][tolerance]:g}"
                         if predictor in paper.WINDSOR_SPL_ZERO_INCURSION else "-"),
            ]
    improvement = paper.WINDSOR_IMPROVEMENTS
    rows += [
        Headline("validation", "long_range.relative_improvement", "its own sweep: long range over static",
                 f"+{improvement['long_range_vs_static']:.1%}", fmt="{:+.1%}"),
        Headline("validation", "next_step.relative_improvement", "its own sweep: next step over static",
                 f"+{improvement['next_step_vs_static']:.1%}", fmt="{:+.1%}"),
        Headline("validation", "straight_line.relative_improvement", "its own sweep: straight lines, long range over "
                 "static", f"+{improvement['straight_line_vs_static']:.1%}", fmt="{:+.1%}"),
        Headline("validation", "tails.long_range.2mm_3deg.n_overshooting",
                 "arcs whose eq. 1 theta_p overshoots theta_a at every n_t <= 30, 2 mm/3 deg"),
    ]
    return rows
