"""How the envelopes end (``artifacts.json`` ``envelope_cause_counts``, stage 02,
:mod:`~poseintegrity.localization.envelope_causes`): the endings in words and a count of envelopes per ending and
tolerance."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.sections import Headline

ENDINGS = {  # how an envelope ends (artifacts.json envelope_causes, localization/envelope_causes.py), in words
    "estimate": "on the estimate", "ground_truth": "on a ground-truth fault",
    "resolution": "within the ground truth's resolution (moved across by <= R11's bar)", "no_pose": "without a pose",
    "censored": "never (censored)", "unmeasured": "unread: not measured to its end (no trusted ground truth)"}


def cause_rows(stage: str, prefix: str, section: str, world: str = "") -> list[Headline]:
    """artifacts.json ``envelope_cause_counts``: per tolerance, how many envelopes (arcs and lines) end on the
    estimate, on a ground-truth fault, within the ground truth's resolution, without a pose, never (censored), or
    unread (:mod:`~poseintegrity.localization.envelope_causes`)."""
    at = f"{world} world: " if world else ""
    rows = []
    for tolerance in paper.TOLERANCES:
        label = paper.TOLERANCE_LABELS[tolerance]
        for cause, text in ENDINGS.items():
            rows.append(Headline(stage, f"{prefix}envelope_cause_counts.{tolerance}.{cause}",
                                 f"{at}envelopes ending {text}, {label}",
                                 target="0" if cause == "ground_truth" and tolerance == "2mm_3deg" else "-",
                                 section=section))
    return rows
