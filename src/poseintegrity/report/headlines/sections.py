"""A row of the stage pages (:class:`Headline`: a key of ``reports/metrics/<stage>.json`` beside the papers' figure and
the project's target) and the sections the rows are shown in, on the rendered world and on recorded data."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Headline:
    """One row: ``key`` is a dotted path into ``metrics/<stage>.json``."""

    stage: str
    key: str
    label: str
    paper: str = "-"
    target: str = "-"
    fmt: str = "{:.4g}"  # how a float is shown, e.g. "{:+.1%}" for a relative improvement
    section: str | None = None  # the SECTIONS entry it is shown in, when not its stage's (e.g. a world's bars)
    judged_by: str | None = None  # the key of the stage's own pass/fail of the target (report/targets.py)
    why: str = ""  # what the reader needs beside the target's pass or fail

    @property
    def shown_in(self) -> str:
        return self.section or STAGE_SECTIONS.get(self.stage, self.stage)


# The summary's sections after its first one (report/claims.py), in the order a reader asks: (title, what it holds).
# A row is shown in its stage's section unless it names another (Headline.section).
SECTIONS = {
    "predictors": ("Predictors", "Stage 04 · localization-envelope predictors on the main world (Windsor et al. V, "
                   "Tables I-III)"),
    "validation": ("Predictors on the held-out world", "Stage 04 · the validation world, nothing tuned on it: the "
                   "main world's operating points applied unchanged, and its own sweep"),
    "envelopes": ("Envelopes and why they end", "Stage 02 · how each envelope ends (`artifacts.json` "
                  "`envelope_causes`, Windsor et al. IV-C, IV-E), and the arcs that decide each headline"),
    "fits": ("Fits", "Stage 03 · artifact models, mean RMSE over the whole dataset from the first 4 stops (Fig. 2)"),
    "pnp": ("PnP variants", "Stage 05 · PnP variants (Windsor et al. V-A, Fig. 6), and the long range predictor on "
            "each (stage 04)"),
    "tracking": ("Tracking", "Stage 06 · marker tracking (Black & Salcudean, IEEE TIM 2024, DOI "
                 "10.1109/TIM.2024.3398108, section III)"),
    "realism": ("The rendered world's realism", "Stages 01-02 · the rendered robot datasets (Windsor et al. IV-D) and "
                "the realism bars, properties the paper's real data had (III-B, IV-C)"),
    "ground_truth": ("Ground truth", "Stages 01-02 · the board whose pose judges each estimate (IV-C), what it adds "
                     "to the errors (R11), and the boards that cannot judge the tolerance"),
}
STAGE_SECTIONS = {"generate": "realism", "artifacts": "realism"}  # stages without a section of their own

RECORDED_SECTIONS = {  # the sections' titles on recorded data (generate.source a folder): no rendered world
    "predictors": ("Predictors", "Stage 04 · localization-envelope predictors on your first world (Windsor et al. V, "
                   "Tables I-III)"),
    "validation": ("Predictors on the held-out world", "Stage 04 · the held-out world (your second world): the first "
                   "world's operating points applied unchanged, and its own sweep"),
    "realism": ("Your datasets described", "Stage 02 · artifact extraction on your datasets (Windsor et al. III-B, "
                "IV-C); the realism values describe them, none is judged"),
    "tracking": ("Tracking", "Stage 06 · marker tracking on its own simulation, not on your datasets (Black & "
                 "Salcudean, IEEE TIM 2024, DOI 10.1109/TIM.2024.3398108, section III)"),
}


def section_heading(section: str, recorded: bool) -> tuple[str, str]:
    """(title, what it holds) of a summary section, on recorded data or the rendered world."""
    return RECORDED_SECTIONS.get(section, SECTIONS[section]) if recorded else SECTIONS[section]
