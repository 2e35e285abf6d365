"""The report's detail pages, one per stage (``reports/stages/<stage>.md``), which ``reports/summary.md`` links.

Each page holds the sections of :data:`~poseintegrity.report.headlines.sections.SECTIONS` that its stage's metrics fill:
one table per section, ours beside the papers' and the target, each target judged pass or fail with its reason
(:mod:`~poseintegrity.report.targets`), then what the section shows below its table (its figures, the arcs that decide
each headline, the boards that cannot judge the tolerance). A stage that has not run yet shows "not run", a key its
metrics lack "not measured", rather than a stale or invented number. On recorded data no target is judged (the rendered
world's bars are properties of the paper's data a rendered world is held to) and a row whose key a stage that ran did
not write is left out.
"""

from __future__ import annotations

import re

from poseintegrity.report.deciding import deciding_section
from poseintegrity.report.headlines import HEADLINES, Headline, section_heading
from poseintegrity.report.lookup import MISSING, absent, lookup
from poseintegrity.report.population_table import population_lines
from poseintegrity.report.recorded import recorded_source
from poseintegrity.report.targets import judged, target_cell

PAGES_DIR = "stages"  # under reports/
PAGES = {  # a stage's page -> (its title, the sections it holds)
    "01_generate_datasets": ("Stages 01-02 · the datasets, their realism and their ground truth", ("realism",
                                                                                                      "ground_truth")),
    "02_extract_artifacts": ("Stage 02 · the envelopes and why each ends", ("envelopes",)),
    "03_fit_artifact_models": ("Stage 03 · the artifact models", ("fits",)),
    "04_predictor_sweeps": ("Stage 04 · the predictors, on the main world and the held-out one", ("predictors",
                                                                                                  "validation")),
    "05_pnp_variants": ("Stage 05 · the PnP variants", ("pnp",)),
    "06_marker_tracking": ("Stage 06 · marker tracking", ("tracking",)),
    "08_population": ("Stage 08 · the predictors on a population of rendered worlds", ()),
}


def page_path(page: str) -> str:
    """A page's path relative to ``reports/``."""
    return f"{PAGES_DIR}/{page}.md"


def section_page(section: str) -> str:
    """The page that holds ``section``."""
    return next(page for page, (_, sections) in PAGES.items() if section in sections)


def anchor(title: str) -> str:
    """The link GitHub gives a heading: lower case, punctuation dropped, spaces as hyphens."""
    return "#" + re.sub(r"[^\w\- ]", "", title.lower()).replace(" ", "-")


def section_link(section: str, recorded: bool) -> str:
    """The link from ``reports/summary.md`` to a section: its page and its heading there."""
    return page_path(section_page(section)) + anchor(section_heading(section, recorded)[0])


def _fmt(value, fmt: str = "{:.4g}", missing: str = "not run") -> str:
    if value is MISSING:
        return missing
    if value is None:
        return "none"
    if isinstance(value, float):
        return fmt.format(value)
    if isinstance(value, list) and value and all(isinstance(v, float) or v is None for v in value):
        return "[" + ", ".join("none" if v is None else fmt.format(v) for v in value) + "]"  # an interval
    if isinstance(value, list):
        return ", ".join(str(item) for item in value) or "none"
    return str(value)


def figure(path: str, text: str) -> list[str]:
    """A figure inline: ``path`` relative to ``reports/``, linked from a page one folder below it."""
    return [f"![{text}](../{path})", ""]


def _predictor_figures(metrics: dict[str, dict]) -> list[str]:
    """The SPL-vs-R_i curves of every predictor per world with the ceiling drawn (stage 04), when it drew them."""
    if lookup(metrics, "predictors", "ceiling") is MISSING:
        return ["SPL vs R_i per predictor with the ceiling drawn (`figures/04_ceiling.png`): "
                f"{absent(metrics, 'predictors')} (this run's stage 04 wrote no ceiling).", ""]
    return [*figure("figures/04_ceiling.png", "SPL vs R_i of every predictor per world, the ceiling drawn"),
            *figure("figures/02_error_calibration.png", "the predicted error against the measured, before theta_a")]


def _envelope_figures(metrics: dict[str, dict]) -> list[str]:
    """Why each envelope ends (figure of stage 02), then the arcs that decide each headline."""
    return [*figure("figures/02_envelope_causes.png", "why each envelope ends, per world and tolerance"),
            *deciding_section(metrics)]


def _realism_notes(metrics: dict[str, dict]) -> list[str]:
    """The bars that failed, by name (artifacts.json ``realism.passed``); on recorded data, why no bar is judged."""
    described = lookup(metrics, "artifacts", "realism.description_only")
    if isinstance(described, str):
        return [f"Realism bars: {described}.", ""]
    lines = []
    for prefix, world in (("", "main world"), ("worlds.validation.", "validation world")):
        passed = lookup(metrics, "artifacts", f"{prefix}realism.passed")
        if isinstance(passed, dict):
            failed = [bar for bar, ok in passed.items() if not ok]
            lines += [f"Bars failed on the {world}: {', '.join(failed) or 'none'} ({len(failed)} of {len(passed)}).",
                      ""]
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


def shown(metrics: dict[str, dict], h: Headline) -> str:
    """A row's value as its table shows it ("not run", "not measured", "none" where there is none)."""
    return _fmt(lookup(metrics, h.stage, h.key), h.fmt, absent(metrics, h.stage))


def row_judgement(metrics: dict[str, dict], h: Headline) -> bool | None:
    """Whether the row meets its target (None: no target, or nothing to judge)."""
    return judged(metrics, h.stage, h.target, h.judged_by, lookup(metrics, h.stage, h.key))


def section_lines(section: str, metrics: dict[str, dict], recorded: bool) -> list[str]:
    """One section: its heading, what it holds, its table (ours, the paper's, the target judged) and its extras."""
    title, holds = section_heading(section, recorded)
    lines = [f"## {title}", "", f"{holds}.", ""]
    if recorded and "note" in metrics.get(section, {}):  # e.g. validation.json of one world: nothing held out
        return [*lines, f"{metrics[section]['note']}.", ""]
    lines += ["| figure | ours | paper | target |", "| --- | --- | --- | --- |"]
    skipped = False
    for h in (h for h in HEADLINES if h.shown_in == section and not (recorded and h.stage == "generate")):
        value = lookup(metrics, h.stage, h.key)
        if recorded and h.stage in metrics and (value is MISSING or skipped and h.label.startswith("...")):
            skipped = True  # and so is a "..." row that continues it
            continue
        skipped = False
        target = "-" if recorded else target_cell(row_judgement(metrics, h), h.target, h.why)
        lines.append(f"| {h.label} | {shown(metrics, h)} | {h.paper} | {target} |")
    lines.append("")
    return lines + (EXTRAS[section](metrics) if section in EXTRAS else [])


def render_page(page: str, metrics: dict[str, dict]) -> str:
    """Markdown of one stage's page."""
    recorded = recorded_source(metrics) is not None
    title, sections = PAGES[page]
    lines = [f"# {title}", "", "Generated by stage 07 from `reports/metrics/*.json`; the summary is "
             "[../summary.md](../summary.md). \"none\": the stage ran and found no such value; \"not run\": no "
             "metrics yet.", ""]
    for section in sections:
        lines += section_lines(section, metrics, recorded)
    if page == "08_population":
        lines += population_lines(metrics, "../") or [f"The population: {absent(metrics, 'population')}.", ""]
    return "\n".join(lines)


def render_pages(metrics: dict[str, dict]) -> dict[str, str]:
    """Every stage's page: its path relative to ``reports/`` -> its Markdown."""
    return {page_path(page): render_page(page, metrics) for page in PAGES}
