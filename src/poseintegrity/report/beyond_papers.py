"""The summary's section on our own predictors, which are no claim of either paper: the localization envelope
predicted from the predicted error (operating point k, chosen on the main world) and from the failure hazard
(operating point h, chosen on the population's worlds), each world's share of the ceiling with its interval; then the
population's table (:mod:`~poseintegrity.report.population_table`)."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.lookup import MISSING, absent
from poseintegrity.report.names import NAMES
from poseintegrity.report.population_table import population_lines
from poseintegrity.report.reader import SHARE, Reader

TITLE = "Beyond the papers (ours)"
ERROR = ("error_long_range", "error_next_step", "error_next_step_observed", "error_combined")  # operating point k
HAZARD = ("hazard_next_step", "hazard_long_range")  # operating point h, chosen on the population


def _error_cell(read: Reader, stage: str, predictor: str) -> str:
    """Per tolerance: the predictor's share of the ceiling with its interval, and its k."""
    if read.value(stage, predictor) is MISSING:
        return absent(read.metrics, stage)
    return " · ".join(f"{read.share(stage, f'{predictor}.{t}')}, k "
                      f"{read.text(stage, f'{predictor}.{t}.best_k', '{:.3g}')}" for t in paper.TOLERANCES)


def _hazard_cell(read: Reader, world: str, predictor: str) -> str:
    """Per tolerance: the hazard predictor's share of the ceiling at the population's h, its interval over the
    world's scenes, and its R_i there."""
    at = f"hazard.worlds.{world}"
    if read.value("predictors", at) is MISSING:
        return absent(read.metrics, "predictors")
    return " · ".join(
        "no h qualified" if read.value("predictors", f"{at}.{t}.{predictor}.share") is MISSING else
        f"{read.text('predictors', f'{at}.{t}.{predictor}.share', SHARE)} "
        f"{read.interval('predictors', f'{at}.{t}.{predictor}.share_interval', SHARE)} of ceiling, R_i "
        f"{read.text('predictors', f'{at}.{t}.{predictor}.incursion_rate', '{:.2f}')}" for t in paper.TOLERANCES)


def beyond_section(metrics: dict[str, dict], worlds: list) -> list[str]:
    """Markdown lines: our predictors per world (2 mm/3 deg · 4 mm/10 deg), then the population's table."""
    read = Reader(metrics)
    rows = [(NAMES[p], [_error_cell(read, w.stage, p) for w in worlds]) for p in ERROR
            if any(read.value(w.stage, p) is not MISSING for w in worlds)]
    if read.value("predictors", "hazard.trained_on_arcs") not in (MISSING, 0):
        rows += [(NAMES[p], [_hazard_cell(read, w.name, p) for w in worlds]) for p in HAZARD]
    lines = [f"## {TITLE}", ""]
    if rows:
        lines += ["Predictors that stop where k x the predicted localization error reaches the tolerance (k chosen at "
                  "zero incursion on the main world), and on the failure hazard (h chosen on the population's "
                  "worlds, not these); each cell 2 mm/3 deg · 4 mm/10 deg.", "",
                  "| predictor | " + " | ".join(f"ours: {w.name}" for w in worlds) + " |",
                  "| --- |" + " --- |" * len(worlds)]
        lines += [f"| {name} | " + " | ".join(cells) + " |" for name, cells in rows]
        lines.append("")
    population = population_lines(metrics)
    return lines + population + ([""] if population else []) if rows or population else []
