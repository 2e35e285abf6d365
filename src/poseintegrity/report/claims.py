"""The summary's first section (issue 41): each claim of the two papers, ours on each world, each predictor's share of
the ceiling, one verdict per claim by one rule (:data:`RULE`), and one line of why that links to the section below
which shows it.

Every number it shows is a value of the metrics files, rounded as shown: none is computed here. A key that the stage
which ran did not write (``ceiling`` before issue 38, say) is "not measured"; a stage that did not run, "not run".

The ceiling (issue 38): a predictor that knew every arc's theta_a would reach mean SPL = mean theta_a at zero
incursion, and the static baseline reaches about the smallest theta_a, so mean / min - 1 (``ceiling.<tolerance>.gain``
of predictors.json and validation.json) bounds any predictor's gain over static; (SPL - static SPL) / (mean theta_a -
static SPL) (``<predictor>.<tolerance>.ceiling_share``) is the share of it a predictor reaches.

The verdict compares ours on each world with the paper's margin (:func:`gain_grade`, :func:`level_grade`); the
weakest world decides. The paper's margins are read from :mod:`poseintegrity.paper_results`.
"""

from __future__ import annotations

from collections.abc import Callable

import re
from dataclasses import dataclass

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines import ENDINGS, section_heading
from poseintegrity.report.lookup import MISSING, absent, lookup
from poseintegrity.report.recorded import recorded_source
from poseintegrity.worlds import FIRST, world_order

TITLE = "What held, where, and by how much"
VERDICTS = ("reproduced", "direction only", "not reproduced")  # grades 0, 1, 2 of one world
NOT_APPLICABLE, UNMEASURED = "not applicable", "no world here measured it"
RULE = ("**Verdict**, one per claim, the weakest world deciding: *reproduced*: ours goes the paper's way by at least "
        "half the paper's margin (a gain over the claim's baseline; for a rate or an error: at least as good as the "
        "paper's); *direction only*: its way, by less; *not reproduced*: not its way, or no operating point at zero "
        "incursion (none); *not applicable*: no world here measures it. Rows marked ours are no claim of the "
        "papers: no verdict.")
SPL, SHARE, RATE = "{:.1f}", "{:.0%}", "{:.2%}"
NAMES = {"static": "static", "long_range": "long range", "next_step": "next step", "mlp": "MLP",
         "error_long_range": "error long range", "error_next_step": "error next step",
         "error_next_step_observed": "observed error next step", "error_combined": "error combined"}
TABLES = {"long_range": "Tables I, III", "next_step": "Tables II, III"}
OURS = ("error_long_range", "error_next_step", "error_next_step_observed", "error_combined")  # issue 38: k, not n_t
PNP_VARIANTS = {"epnp": "EPnP", "p3p": "P3P", "ap3p": "AP3P"}  # the paper's three (V-A, Fig. 6)
POSE_METHODS = {"usac_magsac": "USAC", **PNP_VARIANTS}


@dataclass(frozen=True)
class World:
    """One world of the run: ``stage`` holds its predictors (predictors.json for the first world, validation.json for
    the held-out one); ``prefix`` leads to its blocks in artifacts.json and pnp.json ("" or "worlds.<name>.")."""

    name: str
    stage: str
    prefix: str


def metric_worlds(metrics: dict[str, dict]) -> list[World]:
    """The run's worlds whose predictors were evaluated: the first (where the operating points are chosen) and, when
    there is one, the held-out one (``validation.json`` ``world``)."""
    validation = metrics.get("validation", {})
    first = validation.get("chosen_on") or next(iter(world_order(metrics.get("generate", {}).get("worlds", {}))), FIRST)
    held_out = validation.get("world")
    return [World(first, "predictors", "")] + ([World(held_out, "validation", f"worlds.{held_out}.")]
                                               if held_out else [])


@dataclass(frozen=True)
class Row:
    """One line of the table: ``cells`` are ours per world; ``why`` is one phrase, ``link`` the section showing it."""

    claim: str
    paper: str
    cells: list[str]
    verdict: str
    why: str
    link: str


def gain_grade(gain: float | None, margin: float) -> int:
    """One world's grade (index into :data:`VERDICTS`) of a claim that a predictor gains ``margin`` (the paper's,
    relative) over its baseline: 0 for at least half of it, 1 for less, 2 for none (``gain`` <= 0 or None)."""
    if gain is None or gain <= 0:
        return 2
    return 0 if gain >= margin / 2 else 1


def level_grade(ours: float | None, theirs: float, higher_is_better: bool) -> int:
    """One world's grade of a claim that a rate (``higher_is_better``) or an error reaches the paper's value ``theirs``:
    0 for at least as good, 2 otherwise."""
    if ours is None:
        return 2
    return 0 if (ours >= theirs if higher_is_better else ours <= theirs) else 2


def verdict(grades: list[int]) -> str:
    """The claim's word: the weakest of its worlds' grades; :data:`NOT_APPLICABLE` when no world measured it."""
    return VERDICTS[max(grades)] if grades else NOT_APPLICABLE


def _gain(ours, baseline) -> float | None:
    """ours / baseline - 1 (for the verdict only, never shown); None when ours is None (no operating point)."""
    if ours is None:
        return None
    return float("inf") if baseline is None or baseline <= 0 else ours / baseline - 1


def anchor(title: str) -> str:
    """The link GitHub gives a heading: lower case, punctuation dropped, spaces as hyphens."""
    return "#" + re.sub(r"[^\w\- ]", "", title.lower()).replace(" ", "-")


class Reader:
    """The metrics of a run, read for the table: :meth:`text` shows one value as read, :meth:`value` gives it for a
    verdict (MISSING when absent)."""

    def __init__(self, metrics: dict[str, dict]):
        self.metrics = metrics

    def value(self, stage: str, key: str):
        return lookup(self.metrics, stage, key)

    def text(self, stage: str, key: str, fmt: str = SPL) -> str:
        value = lookup(self.metrics, stage, key)
        if value is MISSING:
            return absent(self.metrics, stage)
        if value is None:
            return "none"
        return fmt.format(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else str(value)

    def share(self, stage: str, *entries: str) -> str:
        """The predictor's share of the ceiling at each of ``entries`` (``<predictor>.<tolerance>``), e.g. "22% of
        ceiling" or "9% · 10% of ceiling"; "ceiling share not measured" when the metrics hold none of them."""
        if all(self.value(stage, f"{entry}.ceiling_share") is MISSING for entry in entries):
            return "ceiling share " + absent(self.metrics, stage)
        return " · ".join(self.text(stage, f"{entry}.ceiling_share", SHARE) for entry in entries) + " of ceiling"


def _weakest(grades: dict[int, int]) -> int:
    """The index of the world whose grade decides the verdict (the first of the weakest)."""
    return max(grades, key=lambda i: (grades[i], -i))


def _ceiling_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Issue 38's ceiling per world and tolerance (no claim of the paper's: no verdict), the paper's lower bound (its
    mean theta_a is at least its next step's SPL), and why ours is lower: R6 and R7 of each world."""
    cells = [" · ".join(f"{read.text(world.stage, f'ceiling.{t}.gain', '{:+.0%}')} "
                        f"({read.text(world.stage, f'ceiling.{t}.n_arcs', '{:g}')} arcs)" for t in paper.TOLERANCES)
             if read.value(world.stage, "ceiling") is not MISSING else absent(read.metrics, world.stage)
             for world in worlds]
    theirs = paper.WINDSOR_SPL_ZERO_INCURSION
    bound = " · ".join(f">= {theirs['next_step'][t] / theirs['static'][t] - 1:+.0%}" for t in paper.TOLERANCES)
    spreads = [f"{w.name} {read.text('artifacts', f'{w.prefix}realism.min_theta_a_2mm3deg')} deg, "
               f"{read.text('artifacts', f'{w.prefix}realism.arc_theta_a_mean_over_min_2mm3deg', '{:.2f}')}"
               for w in worlds if read.value("artifacts", f"{w.prefix}realism.min_theta_a_2mm3deg") is not MISSING]
    why = "R6 hardest arc, R7 spread: " + (" · ".join(spreads) or absent(read.metrics, "artifacts"))
    return Row("ceiling: the most any predictor gains over static, 2 mm/3 deg · 4 mm/10 deg (issue 38)",
               f"{bound} (the paper's lab: 7.0 deg, >= 2)", cells, "-", why, links["realism"])


def _deciding_arc(read: Reader, world: World, predictor: str, tolerance: str) -> str:
    """Which arc holds the predictor's n_t on ``world`` and how its envelope ends (artifacts.json ``envelope_causes``,
    report/deciding.py)."""
    entry = f"{predictor}.{tolerance}"
    arcs = read.value(world.stage, f"{entry}.decided_by")
    if arcs is MISSING or not arcs:
        return f"{world.name}: no arc holds its n_t"
    causes = read.value("artifacts", f"{world.prefix}envelope_causes")
    row = next((c for c in causes if c.get("dataset") == arcs[0] and c.get("tolerance") == tolerance),
               {}) if isinstance(causes, list) else {}
    ending = ENDINGS.get(row.get("cause"), f"on {row.get('cause')}").split(" (")[0]  # without the parenthesis
    ends = f", which ends {ending} at {SPL.format(row['theta_a'])} deg" if row.get("theta_a") is not None else ""
    return f"{world.name}: {arcs[0]} holds n_t at {read.text(world.stage, f'{entry}.best_n_t', '{:g}')}{ends}"


def _over_static_row(read: Reader, worlds: list[World], predictor: str, tolerance: str, links: dict[str, str]) -> Row:
    """Tables I-III: the predictor's max mean SPL at zero incursion beside static's, its n_t, its ceiling share."""
    theirs = paper.WINDSOR_SPL_ZERO_INCURSION
    margin = theirs[predictor][tolerance] / theirs["static"][tolerance] - 1
    entry, static = f"{predictor}.{tolerance}", f"static.{tolerance}.max_mean_spl_zero_incursion"
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        spl = read.value(world.stage, f"{entry}.max_mean_spl_zero_incursion")
        if spl is MISSING or read.value(world.stage, static) is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        grades[i] = gain_grade(_gain(spl, read.value(world.stage, static)), margin)
        cells.append(f"{read.text(world.stage, f'{entry}.max_mean_spl_zero_incursion')} vs "
                     f"{read.text(world.stage, static)}, n_t {read.text(world.stage, f'{entry}.best_n_t', '{:g}')}; "
                     f"{read.share(world.stage, entry)}")
    why = _deciding_arc(read, worlds[_weakest(grades)], predictor, tolerance) if grades else UNMEASURED
    return Row(f"{NAMES[predictor]} over static, {paper.TOLERANCE_LABELS[tolerance]} ({TABLES[predictor]})",
               f"{theirs[predictor][tolerance]:.1f} vs {theirs['static'][tolerance]:.1f} deg ({margin:+.0%}), n_t "
               f"{paper.WINDSOR_THRESHOLDS[predictor][tolerance]}", cells, verdict(list(grades.values())), why,
               links["envelopes"])


def _graded_gain(read: Reader, worlds: list[World], key: str, margin: float,
                 cell: Callable[[str], str]) -> tuple[list[str], dict[int, int]]:
    """(cells, grades) of a claim judged on one relative gain ``key`` per world against the paper's ``margin``: a
    world without the key shows why (``absent``) and is not graded; the others show ``cell(stage)``."""
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        gain = read.value(world.stage, key)
        if gain is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        grades[i] = gain_grade(gain, margin)
        cells.append(cell(world.stage))
    return cells, grades


def _mlp_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Table I: the MLP's max mean SPL and ceiling share per tolerance; the claim is long range's gain over it."""
    margin = paper.WINDSOR_IMPROVEMENTS["long_range_vs_mlp"]

    def cell(stage: str) -> str:
        spl = " · ".join(read.text(stage, f"mlp.{t}.max_mean_spl_zero_incursion") for t in paper.TOLERANCES)
        shares = read.share(stage, *(f"mlp.{t}" for t in paper.TOLERANCES))
        return f"{spl} ({shares}); long range {read.text(stage, 'long_range.relative_improvement_vs_mlp', '{:+.1%}')}"

    cells, grades = _graded_gain(read, worlds, "long_range.relative_improvement_vs_mlp", margin, cell)
    world = worlds[_weakest(grades)] if grades else None
    why = (f"{world.name}: the MLP's fits are non-physical in "
           f"{read.text(world.stage, 'fit_status.mlp.non_physical', SHARE)} of its rows" if world else UNMEASURED)
    theirs = paper.WINDSOR_SPL_ZERO_INCURSION["mlp"]
    return Row("MLP, and long range over it (Table I)", " · ".join(f"{theirs[t]:.1f}" for t in paper.TOLERANCES)
               + f" deg; long range {margin:+.1%}", cells, verdict(list(grades.values())), why, links["fits"])


def _ours_row(read: Reader, worlds: list[World], predictor: str, links: dict[str, str]) -> Row:
    """Issue 38's predictors on the predicted error: beside the paper's, no claim of theirs (no verdict)."""
    cells = []
    for world in worlds:
        if read.value(world.stage, predictor) is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        cells.append(" · ".join(f"{read.text(world.stage, f'{predictor}.{t}.max_mean_spl_zero_incursion')}, k "
                                f"{read.text(world.stage, f'{predictor}.{t}.best_k', '{:.3g}')}, "
                                f"{read.share(world.stage, f'{predictor}.{t}')}" for t in paper.TOLERANCES))
    return Row(f"ours: {NAMES[predictor]}, 2 mm/3 deg · 4 mm/10 deg (issue 38)", "-", cells, "-",
               f"its operating point is the safety factor k, chosen on {worlds[0].name}", links["predictors"])


def _lines_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Fig. 7: long range over static on the straight lines (V-A)."""
    margin = paper.WINDSOR_IMPROVEMENTS["straight_line_vs_static"]

    def cell(stage: str) -> str:
        return (f"{read.text(stage, 'straight_line.relative_improvement', '{:+.1%}')} ("
                f"{read.text(stage, 'straight_line.long_range_max_mean_spl_zero_incursion')} vs "
                f"{read.text(stage, 'straight_line.static_max_mean_spl_zero_incursion')} mm)")

    cells, grades = _graded_gain(read, worlds, "straight_line.relative_improvement", margin, cell)
    world = worlds[_weakest(grades)] if grades else None
    why = (f"{world.name}: R8, lines' mean / smallest x_a, is "
           f"{read.text('artifacts', f'{world.prefix}realism.line_x_a_mean_over_min_2mm3deg', '{:.2f}')}"
           if world else UNMEASURED)
    return Row("straight lines: long range over static, 2 mm/3 deg (Fig. 7)", f"{margin:+.1%}", cells,
               verdict(list(grades.values())), why, links["realism"])


def _pnp_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Fig. 6: on each of the paper's three PnP variants, long range beats static (no margin published)."""
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        shown, variant_grades = [], []
        for method, name in PNP_VARIANTS.items():
            spl = read.value(world.stage, f"pnp.{method}.max_mean_spl_zero_incursion")
            static = read.value(world.stage, f"pnp.{method}.static_max_mean_spl_zero_incursion")
            if spl is MISSING or static is MISSING:
                continue
            variant_grades.append(gain_grade(_gain(spl, static), 0.0))
            shown.append(f"{name} {read.text(world.stage, f'pnp.{method}.max_mean_spl_zero_incursion')} vs "
                         f"{read.text(world.stage, f'pnp.{method}.static_max_mean_spl_zero_incursion')}")
        if variant_grades:
            grades[i] = max(variant_grades)
        cells.append(" · ".join(shown) or absent(read.metrics, world.stage))
    world = worlds[_weakest(grades)] if grades else None
    why = f"{world.name}: frames without a pose: " + ", ".join(
        f"{name} {read.text('pnp', f'{world.prefix}methods.{method}.failure_rate', '{:.1%}')}"
        for method, name in POSE_METHODS.items()) if world else UNMEASURED
    return Row("PnP variants: long range over static on EPnP · P3P · AP3P, 2 mm/3 deg (Fig. 6)",
               "beats static on each", cells, verdict(list(grades.values())), why, links["pnp"])


def _live_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Fig. 9, V-C: next step at a fixed n_t, no incursion and more of the envelope used than by static."""
    live = paper.WINDSOR_LIVE
    margin = live["envelope_share"] / live["static_envelope_share"] - 1
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        share, static = (read.value(world.stage, f"live.{key}") for key in ("envelope_share", "static_envelope_share"))
        if share is MISSING or static is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        incursions = read.value(world.stage, "live.incursions")
        grades[i] = 2 if incursions not in (0, 0.0) else gain_grade(_gain(share, static), margin)
        cells.append(f"n_t {read.text(world.stage, 'live.n_t', '{:g}')}: "
                     f"{read.text(world.stage, 'live.incursions', '{:g}')} incursions in "
                     f"{read.text(world.stage, 'live.n_trials', '{:g}')}; "
                     f"{read.text(world.stage, 'live.envelope_share', '{:.1%}')} of the envelope vs static "
                     f"{read.text(world.stage, 'live.static_envelope_share', '{:.1%}')}")
    if grades:
        world = worlds[_weakest(grades)]
        tolerance = read.value(world.stage, "live.tolerance")
        why = (f"{world.name}: next step's own n_t at {paper.TOLERANCE_LABELS.get(tolerance, tolerance)} is "
               f"{read.text(world.stage, f'next_step.{tolerance}.best_n_t', '{:g}')}")
    else:
        why = UNMEASURED
    return Row(f"live trials: next step at n_t {live['n_t']}, 4 mm/10 deg (Fig. 9)",
               f"{live['incursions']} incursions in {live['n_trials']}; {live['envelope_share']:.1%} of the envelope "
               f"vs static {live['static_envelope_share']:.1%}", cells, verdict(list(grades.values())), why,
               links["predictors"])


def _tracking_cells(worlds: list[World], text: str) -> list[str]:
    """Stage 06 simulates its own scene whatever the worlds: its value in the first column, "-" in the others."""
    return [text] + ["-"] * (len(worlds) - 1)


def _markers_row(read: Reader, worlds: list[World], markers: int, links: dict[str, str]) -> Row:
    """Black and Salcudean III: the share of frames with the correct pose, with 4 or 3 markers (motion (a))."""
    theirs = paper.BLACK_RESULTS["success_rate"][f"markers{markers}"]
    ours = read.value("tracking", f"success_rates.a_markers{markers}")
    grades = [] if ours is MISSING else [level_grade(ours, theirs, higher_is_better=True)]
    cell = ("simulation, motion (a): " + read.text("tracking", f"success_rates.a_markers{markers}", RATE)
            if grades else absent(read.metrics, "tracking"))
    why = f"the stress motion (b): {read.text('tracking', f'success_rates.b_markers{markers}', RATE)}" if grades \
        else UNMEASURED
    return Row(f"correct pose, {markers} markers (Black & Salcudean III)", f"{theirs:.2%}",
               _tracking_cells(worlds, cell), verdict(grades), why, links["tracking"])


def _accuracy_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Black and Salcudean III: RMS position (mm, per axis) and Euler-angle (deg) error with the UKF."""
    theirs = paper.BLACK_RESULTS
    mm, deg = read.value("tracking", "rms_axis_mm.ukf"), read.value("tracking", "rms_euler_deg.ukf")
    grades = [] if MISSING in (mm, deg) else [max(level_grade(mm, theirs["rms_mm"]["ukf"], higher_is_better=False),
                                                  level_grade(deg, theirs["rms_deg"]["ukf"], higher_is_better=False))]
    cell = (f"simulation: {read.text('tracking', 'rms_axis_mm.ukf', '{:.2f}')} mm / "
            f"{read.text('tracking', 'rms_euler_deg.ukf', '{:.2f}')} deg" if grades
            else absent(read.metrics, "tracking"))
    why = (f"without the filter: {read.text('tracking', 'rms_axis_mm.no_filter', '{:.2f}')} mm / "
           f"{read.text('tracking', 'rms_euler_deg.no_filter', '{:.2f}')} deg" if grades else UNMEASURED)
    return Row("accuracy: RMS error per axis with the UKF (Black & Salcudean III)",
               f"{theirs['rms_mm']['ukf']:g} mm / {theirs['rms_deg']['ukf']:g} deg", _tracking_cells(worlds, cell),
               verdict(grades), why, links["tracking"])


def claim_rows(metrics: dict[str, dict], worlds: list[World], links: dict[str, str]) -> list[Row]:
    """The table's rows: the ceiling, Tables I-III, issue 38's predictors where the metrics hold them, Figs. 7, 6 and
    9, then Black and Salcudean's success rates and accuracy. ``links``: section name -> its anchor."""
    read = Reader(metrics)
    rows = [_ceiling_row(read, worlds, links)]
    rows += [_over_static_row(read, worlds, predictor, tolerance, links)
             for predictor in ("long_range", "next_step") for tolerance in paper.TOLERANCES]
    rows.append(_mlp_row(read, worlds, links))
    rows += [_ours_row(read, worlds, predictor, links) for predictor in OURS
             if any(read.value(world.stage, predictor) is not MISSING for world in worlds)]
    rows += [_lines_row(read, worlds, links), _pnp_row(read, worlds, links), _live_row(read, worlds, links),
             _markers_row(read, worlds, 4, links), _markers_row(read, worlds, 3, links),
             _accuracy_row(read, worlds, links)]
    return rows


def claims_section(metrics: dict[str, dict]) -> list[str]:
    """Markdown lines of the first section: what held, on which world, by how much, and why not (module docstring)."""
    recorded = recorded_source(metrics) is not None
    links = {section: anchor(section_heading(section, recorded)[0])
             for section in ("predictors", "envelopes", "fits", "pnp", "tracking", "realism")}
    worlds = metric_worlds(metrics)
    rows = claim_rows(metrics, worlds, links)
    figures = (f"[SPL vs R_i of every predictor, the ceiling drawn]({links['predictors']}) · "
               f"[why each envelope ends]({links['envelopes']})")
    lines = [f"## {TITLE}", "",
             "Each claim of the two papers beside ours on each world, read from `reports/metrics/*.json`. The "
             "**ceiling** is the most any predictor can gain over static: the arcs' mean theta_a / smallest - 1 "
             "(issue 38; the paper's is at least its next step over static). A predictor's **share of the ceiling** "
             "is (its SPL - static's) / (mean theta_a - static's): it compares predictors fairly across worlds.", "",
             RULE, "",
             "| claim (paper) | paper | " + " | ".join(f"ours: {world.name}" for world in worlds)
             + " | verdict | why |", "| --- | --- |" + " --- |" * len(worlds) + " --- | --- |"]
    lines += [f"| {row.claim} | {row.paper} | " + " | ".join(row.cells)
              + f" | {row.verdict} | [{row.why}]({row.link}) |" for row in rows]
    return [*lines, "", f"Figures: {figures}.", ""]
