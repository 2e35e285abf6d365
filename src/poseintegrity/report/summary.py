"""``reports/summary.md``: what held of the papers' claims, then every stage's headline figures beside the papers'.

It opens with one screen (:func:`~poseintegrity.report.claims.claims_section`): each claim, ours per world, each
predictor's share of the ceiling, a verdict and why. The sections below follow the questions a reader asks next
(:data:`~poseintegrity.report.headlines.SECTIONS`): the predictors, the envelopes and why they end, the fits, the PnP
variants, the tracking, the rendered world's realism, the ground truth; then a link to the machine-dependent figures
(wall times, speed-ups: :mod:`~poseintegrity.report.timing_page`), which the summary never holds, so that two runs
write the same summary on any machine. Each stage writes
``reports/metrics/<stage>.json``; :data:`~poseintegrity.report.headlines.HEADLINES` says which keys are headline
figures, what the papers reported for them and the project's target where there is one. A stage that has not run
yet shows "not run", a key its metrics lack "not measured", rather than a stale or invented number.
"""

from __future__ import annotations

import json
from pathlib import Path

from poseintegrity.report.claims import claims_section
from poseintegrity.report.deciding import deciding_section
from poseintegrity.report.headline_file import HEADLINE_FILE
from poseintegrity.report.headlines import HEADLINES, SECTIONS, section_heading
from poseintegrity.report.lookup import MISSING, absent, lookup
from poseintegrity.report.recorded import recorded_section, recorded_source
from poseintegrity.report.timing_page import TIMING_PAGE


def read_metrics(metrics_dir: Path) -> dict[str, dict]:
    """Every stage's ``<stage>.json`` of ``metrics_dir`` by stage name (not the headline file stage 07 writes from
    them)."""
    return {p.stem: json.loads(p.read_text()) for p in sorted(Path(metrics_dir).glob("*.json"))
            if p.name != HEADLINE_FILE}


def _fmt(value, fmt: str = "{:.4g}", missing: str = "not run") -> str:
    if value is MISSING:
        return missing
    if value is None:
        return "none"
    if isinstance(value, float):
        return fmt.format(value)
    if isinstance(value, list):
        return ", ".join(str(item) for item in value) or "none"
    return str(value)


def figure(path: str, text: str) -> list[str]:
    """A figure inline: a Markdown image relative to ``reports/summary.md``."""
    return [f"![{text}]({path})", ""]


def _predictor_figures(metrics: dict[str, dict]) -> list[str]:
    """The SPL-vs-R_i curves of every predictor per world with the ceiling drawn: stage 04 draws them with the
    ceiling (issue 38), so a run whose predictors.json has none has no such figure."""
    if lookup(metrics, "predictors", "ceiling") is MISSING:
        return ["SPL vs R_i per predictor with the ceiling drawn (`figures/04_ceiling.png`): "
                f"{absent(metrics, 'predictors')} (this run's stage 04 wrote no ceiling).", ""]
    return figure("figures/04_ceiling.png", "SPL vs R_i of every predictor per world, the ceiling drawn")


def _envelope_figures(metrics: dict[str, dict]) -> list[str]:
    """Why each envelope ends (figure of stage 02), then the arcs that decide each headline."""
    return [*figure("figures/02_envelope_causes.png", "why each envelope ends, per world and tolerance"),
            *deciding_section(metrics)]


def _realism_notes(metrics: dict[str, dict]) -> list[str]:
    """On recorded data, why no bar is judged; for an artifacts.json of before R6 and R7 became comparisons, that its
    count still holds them."""
    described = lookup(metrics, "artifacts", "realism.description_only")
    lines = [f"Realism bars: {described}.", ""] if isinstance(described, str) else []
    if lookup(metrics, "artifacts", "realism.passed.r6_hardest_arc") is not MISSING:
        lines += ["This artifacts.json was written before R6 and R7 became comparisons (issue 41): its count of bars "
                  "passed still holds them (re-run stage 02).", ""]
    return lines


def board_warnings(metrics: dict[str, dict]) -> list[str]:
    """The message stage 02 printed for each board that cannot judge the tolerance (artifacts.json
    ``board_warnings``), each once."""
    warnings = lookup(metrics, "artifacts", "board_warnings")
    if warnings is MISSING:
        return [f"Boards that cannot judge the tolerance: {absent(metrics, 'artifacts')}.", ""]
    messages = list(dict.fromkeys(warning["message"] for warning in warnings))
    if not messages:
        return ["Boards that cannot judge the tolerance: none (every board is trusted in most of its frames).", ""]
    return ["Boards that cannot judge the tolerance (stage 02's warnings):", "", *(f"- {m}" for m in messages), ""]


EXTRAS = {"predictors": _predictor_figures, "envelopes": _envelope_figures, "realism": _realism_notes,
          "ground_truth": board_warnings}  # what a section shows below its table


def render_summary(metrics: dict[str, dict]) -> str:
    """Markdown: the first screen (report/claims.py), then one table per section, ours beside the paper's and the
    target, with the figures, the arcs that decide each headline (report/deciding.py) and the board warnings; then
    what holds on another machine, and where the machine-dependent figures are.

    On recorded data (:func:`~poseintegrity.report.recorded.recorded_source`) the section on the user's datasets
    follows the first screen and replaces stage 01's rendered-world rows; no target is shown (the rendered world's
    bars are not judged on recorded data) and a row whose key a stage that ran did not write (a rendered world's
    name, say) is left out rather than shown as "not measured"."""
    recorded = recorded_source(metrics) is not None
    lines = ["# Summary of the latest run", "",
             "Generated by stage 07 from `reports/metrics/*.json`. Paper figures (per tolerance where the paper gives",
             "them): Windsor et al., IEEE RA-L 9(5), 2024; Black and Salcudean, IEEE Transactions on Instrumentation and",
             "Measurement, 2024, DOI 10.1109/TIM.2024.3398108 (see `docs/references.md`). \"none\": the stage ran and",
             "found no such value (e.g. no threshold n_t <= 100 reaches zero incursions); \"not run\": no metrics yet.", "",
             *claims_section(metrics), *recorded_section(metrics)]
    for section in SECTIONS:
        title, holds = section_heading(section, recorded)
        lines += [f"## {title}", "", f"{holds}.", ""]
        if recorded and "note" in metrics.get(section, {}):  # e.g. validation.json of one world: nothing held out
            lines += [f"{metrics[section]['note']}.", ""]
            continue
        lines += ["| figure | ours | paper | target |", "| --- | --- | --- | --- |"]
        skipped = False
        for h in (h for h in HEADLINES if h.shown_in == section and not (recorded and h.stage == "generate")):
            value = lookup(metrics, h.stage, h.key)
            if recorded and h.stage in metrics and (value is MISSING or skipped and h.label.startswith("...")):
                skipped = True  # and so is a "..." row that continues it
                continue
            skipped = False
            shown = _fmt(value, h.fmt, absent(metrics, h.stage))
            lines.append(f"| {h.label} | {shown} | {h.paper} | {'-' if recorded else h.target} |")
        lines.append("")
        lines += EXTRAS[section](metrics) if section in EXTRAS else []
    lines += ["## Same numbers on another machine", "", MACHINE_NOTE, "", "## Machine-dependent figures", "",
              f"Stage wall times and the tracking filter's speed-ups change with the machine and its load: they are on "
              f"[{TIMING_PAGE}]({TIMING_PAGE}), not here.", ""]
    return "\n".join(lines)


# What README "Same numbers on any x86-64 machine" measured of the figures above
MACHINE_NOTE = ("OpenCV, numpy, OpenBLAS, torch and numba run capped at AVX2 on every x86-64 machine "
                "(`poseintegrity/dispatch`), so SIFT and every figure that follows from it are the same on an AVX-512 "
                "machine, and a stage run again with the same params writes the same bytes into every data and metrics "
                "file.")
