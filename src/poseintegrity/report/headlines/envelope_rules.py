"""Tables I-II under each rule for the frames without a pose (``predictors.json`` ``envelope_rules``, stage 04,
theta_a of Windsor et al. IV-E): max mean SPL at zero incursion (deg) and long range's improvement over static."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.sections import Headline


def rule_rows() -> list[Headline]:
    """predictors.json envelope_rules: Tables I-II under each rule for frames without a pose (theta_a, IV-E)."""
    rows = []
    for rule in ("fail_fraction", "capped", "infinite"):
        for tolerance in paper.TOLERANCES:
            label = paper.TOLERANCE_LABELS[tolerance]
            for predictor in ("static", "long_range", "next_step"):
                rows.append(Headline("predictors", f"envelope_rules.{rule}.{predictor}.{tolerance}"
                                     f".max_mean_spl_zero_incursion",
                                     f"theta_a rule '{rule}': {predictor}, {label} (deg)",
                                     f"{paper.WINDSOR_SPL_ZERO_INCURSION[predictor][tolerance]:g}"))
        rows.append(Headline("predictors", f"envelope_rules.{rule}.long_range.relative_improvement",
                             f"theta_a rule '{rule}': long range over static",
                             f"+{paper.WINDSOR_IMPROVEMENTS['long_range_vs_static']:.1%}", fmt="{:+.1%}"))
    return rows
