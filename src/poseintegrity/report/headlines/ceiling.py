"""The ceiling (``predictors.json`` and ``validation.json`` ``ceiling.<tolerance>``, stage 04): the most any predictor
can gain over static on a world's arcs (theta_a in deg), and each paper predictor's share of it."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.sections import Headline


def ceiling_rows(stage: str) -> list[Headline]:
    """Issue 38's ceiling (predictors.json, validation.json ``ceiling.<tolerance>``): the most any predictor can gain
    over static, from the arcs' mean and smallest theta_a; and each paper predictor's share of it."""
    rows, spl = [], paper.WINDSOR_SPL_ZERO_INCURSION
    for tolerance in paper.TOLERANCES:
        label, key = paper.TOLERANCE_LABELS[tolerance], f"ceiling.{tolerance}"
        rows += [
            Headline(stage, f"{key}.gain", f"ceiling, {label}: the arcs' mean theta_a / smallest - 1",
                     f">= {spl['next_step'][tolerance] / spl['static'][tolerance] - 1:+.0%} (next step over static)",
                     fmt="{:+.1%}"),
            Headline(stage, f"{key}.n_arcs", "... arcs"),
            Headline(stage, f"{key}.mean_theta_a", "... their mean theta_a (deg)"),
            Headline(stage, f"{key}.min_theta_a", "... their smallest theta_a (deg)"),
            Headline(stage, f"{key}.static_spl", "... static's max mean SPL at zero incursion on them (deg)"),
            *[Headline(stage, f"{predictor}.{tolerance}.ceiling_share", f"... {name}'s share of the ceiling",
                       fmt="{:.0%}") for predictor, name in (("long_range", "long range"), ("next_step", "next step"),
                                                             ("mlp", "the MLP"))],
        ]
    return rows
