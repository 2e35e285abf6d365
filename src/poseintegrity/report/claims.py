"""The summary's first section (issue 41): each claim of the two papers, ours on each world, each predictor's share of
the ceiling, one verdict per claim by one rule (:data:`RULE`), and one line of why that links to the section below
which shows it.

Every number it shows is a value of the metrics files, rounded as shown: none is computed here. A key that the stage
which ran did not write (``ceiling`` before issue 38, say) is "not measured"; a stage that did not run, "not run".

The ceiling (issue 38): a predictor that knew every arc's theta_a would reach mean SPL = mean theta_a at zero
incursion, and the static baseline reaches about the smallest theta_a, so mean / min - 1 (``ceiling.<tolerance>.gain``
of predictors.json and validation.json) bounds any predictor's gain over static; (SPL - static SPL) / (mean theta_a -
static SPL) (``<predictor>.<tolerance>.ceiling_share``) is the share of it a predictor reaches.

The verdict reads the interval of our gain over each claim's baseline on each world (:func:`interval_grade`; issue 49:
a point value over 21 arcs moves by tens of points with one arc); the weakest world decides. The paper's figures are
read from :mod:`poseintegrity.paper_results`.
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
VERDICTS = ("reproduced", "undecided", "not reproduced")  # grades 0, 1, 2 of one world
NOT_APPLICABLE, UNMEASURED = "not applicable", "no world here measures it"
RULE = ("**Verdict**, one per claim, the weakest world deciding, read from the 90 % interval of our gain over the "
        "claim's baseline (static, the MLP, or the paper's own rate or error), never from its point value. The "
        "interval resamples what the result rests on: the scenes with replacement, the operating point chosen again "
        "at zero incursion in each draw (`predict.intervals`); the tracking's 5-s blocks of frames "
        "(`track.evaluation`). *reproduced*: the interval lies above zero, on the paper's side; *undecided*: it holds "
        "zero, so these data cannot tell; *not reproduced*: it lies below zero, or there is no operating point at zero incursion; *not applicable*: no world "
        "here measures it. A world whose metrics hold no interval is undecided. Rows marked ours are no claim of the "
        "papers: no verdict.")
SPL, SHARE, RATE = "{:.1f}", "{:.0%}", "{:.2%}"
NAMES = {"static": "static", "long_range": "long range", "next_step": "next step", "mlp": "MLP",
         "error_long_range": "error long range", "error_next_step": "error next step",
         "error_next_step_observed": "observed error next step", "error_combined": "error combined",
         "hazard_next_step": "hazard next step", "hazard_long_range": "hazard long range"}
TABLES = {"long_range": "Tables I, III", "next_step": "Tables II, III"}
OURS = ("error_long_range", "error_next_step", "error_next_step_observed", "error_combined")  # issue 38: k, not n_t
HAZARD = ("hazard_next_step", "hazard_long_range")  # issue 50: h, chosen on the population
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


def interval_grade(interval) -> int:
    """One world's grade (index into :data:`VERDICTS`) of a claim by the interval [low, high] of our gain over its
    baseline (None at an end: no operating point there, lower than any gain): 0 when the low end lies above zero, 2
    when the high end lies below zero or is None (no operating point in most draws), 1 otherwise (the interval holds
    zero, or there is no interval)."""
    if not isinstance(interval, (list, tuple)) or len(interval) != 2:
        return 1
    low, high = interval
    if high is None or high < 0:
        return 2
    return 0 if low is not None and low > 0 else 1


def verdict(grades: list[int]) -> str:
    """The claim's word: the weakest of its worlds' grades; :data:`NOT_APPLICABLE` when no world measured it."""
    return VERDICTS[max(grades)] if grades else NOT_APPLICABLE


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

    def interval(self, stage: str, key: str, fmt: str = SPL) -> str:
        """An interval [low, high] as "[low, high]" (an end without an operating point: "none"); "" when absent."""
        value = lookup(self.metrics, stage, key)
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            return ""
        return "[" + ", ".join("none" if end is None else fmt.format(end) for end in value) + "]"

    def share(self, stage: str, *entries: str) -> str:
        """The predictor's share of the ceiling at each of ``entries`` (``<predictor>.<tolerance>``) with its interval,
        e.g. "22% [5%, 40%] of ceiling" or "9% [..] · 10% [..] of ceiling"; "ceiling share not measured" when the
        metrics hold none of them."""
        if all(self.value(stage, f"{entry}.ceiling_share") is MISSING for entry in entries):
            return "ceiling share " + absent(self.metrics, stage)
        return " · ".join(" ".join(filter(None, (self.text(stage, f"{entry}.ceiling_share", SHARE), self.interval(
            stage, f"{entry}.interval.ceiling_share", SHARE)))) for entry in entries) + " of ceiling"

    def gain(self, stage: str, key: str, unit: str = "deg") -> str:
        """A gain (``key``: ``<...>.gain``, and ``<...>.interval.gain`` beside it) as "+2.4 deg [-0.9, +5.1]"."""
        return " ".join(filter(None, (f"{self.text(stage, key, '{:+.1f}')} {unit}",
                                      self.interval(stage, key.rsplit('.', 1)[0] + ".interval.gain", "{:+.1f}"))))


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


def _held_by(read: Reader, world: World, predictor: str, tolerance: str) -> str:
    """How many arcs hold the predictor's operating point and static's size on ``world`` (they incur at the next
    bolder one), of how many, the first of them and how its envelope ends (artifacts.json ``envelope_causes``,
    report/deciding.py)."""
    n_arcs = read.value(world.stage, f"ceiling.{tolerance}.n_arcs")
    of = f" of {n_arcs:g}" if isinstance(n_arcs, (int, float)) else ""
    held = {p: read.value(world.stage, f"{p}.{tolerance}.decided_by") for p in (predictor, "static")}
    held = {p: arcs if isinstance(arcs, list) else [] for p, arcs in held.items()}
    if not held[predictor]:
        return f"{world.name}: no arc holds its operating point; static held by {len(held['static'])}{of} arcs"
    arc = held[predictor][0]
    causes = read.value("artifacts", f"{world.prefix}envelope_causes")
    row = next((c for c in causes if c.get("dataset") == arc and c.get("tolerance") == tolerance),
               {}) if isinstance(causes, list) else {}
    ending = ENDINGS.get(row.get("cause"), f"on {row.get('cause')}").split(" (")[0]  # without the parenthesis
    ends = f", which ends {ending} at {SPL.format(row['theta_a'])} deg" if row.get("theta_a") is not None else ""
    return (f"{world.name}: {len(held[predictor])}{of} arcs hold n_t at "
            f"{read.text(world.stage, f'{predictor}.{tolerance}.best_n_t', '{:g}')} ({arc}{ends}); static held by "
            f"{len(held['static'])}")


def _arcs_holding(read: Reader, world: World, tolerance: str) -> str:
    """How many arcs hold long range's and the MLP's operating points at ``tolerance`` on ``world``, of how many."""
    held = [read.value(world.stage, f"{p}.{tolerance}.decided_by") for p in ("long_range", "mlp")]
    n_arcs = read.text(world.stage, f"ceiling.{tolerance}.n_arcs", "{:g}")
    counts = " · ".join(str(len(arcs)) if isinstance(arcs, list) else "-" for arcs in held)
    return f"{paper.TOLERANCE_LABELS[tolerance]}: n_t held by {counts} of {n_arcs} arcs"


def _over_static_row(read: Reader, worlds: list[World], predictor: str, tolerance: str, links: dict[str, str]) -> Row:
    """Tables I-III: the predictor's max mean SPL at zero incursion beside static's, the gain with its interval (the
    verdict reads it), the relative gain as the paper gives it, its n_t, its ceiling share with its interval."""
    theirs = paper.WINDSOR_SPL_ZERO_INCURSION
    margin = theirs[predictor][tolerance] / theirs["static"][tolerance] - 1
    entry, static = f"{predictor}.{tolerance}", f"static.{tolerance}.max_mean_spl_zero_incursion"
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        spl = read.value(world.stage, f"{entry}.max_mean_spl_zero_incursion")
        if spl is MISSING or read.value(world.stage, static) is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        grades[i] = 2 if spl is None else interval_grade(read.value(world.stage, f"{entry}.interval.gain"))
        cells.append(f"{read.text(world.stage, f'{entry}.max_mean_spl_zero_incursion')} vs "
                     f"{read.text(world.stage, static)}: {read.gain(world.stage, f'{entry}.gain')} "
                     f"({read.text(world.stage, f'{entry}.relative_gain', '{:+.0%}')}), n_t "
                     f"{read.text(world.stage, f'{entry}.best_n_t', '{:g}')}; {read.share(world.stage, entry)}")
    why = _held_by(read, worlds[_weakest(grades)], predictor, tolerance) if grades else UNMEASURED
    return Row(f"{NAMES[predictor]} over static, {paper.TOLERANCE_LABELS[tolerance]} ({TABLES[predictor]})",
               f"{theirs[predictor][tolerance]:.1f} vs {theirs['static'][tolerance]:.1f} deg ({margin:+.0%}), n_t "
               f"{paper.WINDSOR_THRESHOLDS[predictor][tolerance]}", cells, verdict(list(grades.values())), why,
               links["envelopes"])


def _mlp_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Table I: the MLP's max mean SPL and ceiling share per tolerance; the claim is long range's gain over it, judged
    per tolerance on the paired difference of the two on the same draws (the weaker tolerance decides)."""
    margin = paper.WINDSOR_IMPROVEMENTS["long_range_vs_mlp"]
    pair = "intervals.{}.pairs.long_range vs mlp.difference"
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        if read.value(world.stage, "long_range.relative_improvement_vs_mlp") is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        grades[i] = max(interval_grade(read.value(world.stage, pair.format(t))) for t in paper.TOLERANCES)
        spl = " · ".join(read.text(world.stage, f"mlp.{t}.max_mean_spl_zero_incursion") for t in paper.TOLERANCES)
        shares = read.share(world.stage, *(f"mlp.{t}" for t in paper.TOLERANCES))
        differences = " · ".join(
            f"{read.text(world.stage, pair.format(t).replace('difference', 'point'), '{:+.1f}')} deg "
            f"{read.interval(world.stage, pair.format(t), '{:+.1f}')}".rstrip() for t in paper.TOLERANCES)
        cells.append(f"{spl} ({shares}); long range "
                     f"{read.text(world.stage, 'long_range.relative_improvement_vs_mlp', '{:+.1%}')}: {differences}")
    world = worlds[_weakest(grades)] if grades else None
    why = (f"{world.name}: the MLP's fits are non-physical in "
           f"{read.text(world.stage, 'fit_status.mlp.non_physical', SHARE)} of its rows; "
           + "; ".join(_arcs_holding(read, world, t) for t in paper.TOLERANCES) if world else UNMEASURED)
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


def _hazard_row(read: Reader, worlds: list[World], predictor: str, links: dict[str, str]) -> Row:
    """Issue 50's hazard predictors at the h chosen on the population (predictors.json ``hazard``), applied unchanged
    to each world: its share of the ceiling [interval over its scenes] and R_i; no claim of the paper's."""
    cells = []
    for world in worlds:
        at = f"hazard.worlds.{world.name}"
        if read.value("predictors", at) is MISSING:
            cells.append(absent(read.metrics, "predictors"))
            continue
        cells.append(" · ".join(
            "no h qualified" if read.value("predictors", f"{at}.{t}.{predictor}.share") is MISSING else
            f"{read.text('predictors', f'{at}.{t}.{predictor}.share', SHARE)} "
            f"{read.interval('predictors', f'{at}.{t}.{predictor}.share_interval', SHARE)}, R_i "
            f"{read.text('predictors', f'{at}.{t}.{predictor}.incursion_rate', '{:.2f}')}" for t in paper.TOLERANCES))
    return Row(f"ours: {NAMES[predictor]}, share of ceiling, 2 mm/3 deg · 4 mm/10 deg (issue 50)", "-", cells, "-",
               "its operating point h was chosen on other rendered worlds, not on these", links["predictors"])


def _lines_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Fig. 7: long range over static on the straight lines (V-A); a world's lines resampled one by one."""
    margin = paper.WINDSOR_IMPROVEMENTS["straight_line_vs_static"]
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        if read.value(world.stage, "straight_line.relative_improvement") is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        spl = read.value(world.stage, "straight_line.long_range_max_mean_spl_zero_incursion")
        grades[i] = 2 if spl is None else interval_grade(read.value(world.stage, "straight_line.interval.gain"))
        cells.append(f"{read.text(world.stage, 'straight_line.relative_improvement', '{:+.1%}')} ("
                     f"{read.text(world.stage, 'straight_line.long_range_max_mean_spl_zero_incursion')} vs "
                     f"{read.text(world.stage, 'straight_line.static_max_mean_spl_zero_incursion')} mm; gain "
                     f"{read.interval(world.stage, 'straight_line.interval.gain', '{:+.1f}') or 'no interval'} mm)")
    world = worlds[_weakest(grades)] if grades else None
    why = (f"{world.name}: {read.text(world.stage, 'straight_line.n_lines', '{:g}')} lines of one scene, resampled "
           f"one by one; R8, lines' mean / smallest x_a, is "
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
            variant_grades.append(2 if spl is None else interval_grade(
                read.value(world.stage, f"pnp.{method}.interval.gain")))
            shown.append(f"{name} {read.text(world.stage, f'pnp.{method}.max_mean_spl_zero_incursion')} vs "
                         f"{read.text(world.stage, f'pnp.{method}.static_max_mean_spl_zero_incursion')} "
                         f"{read.interval(world.stage, f'pnp.{method}.interval.gain', '{:+.1f}')}".rstrip())
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
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        share, static = (read.value(world.stage, f"live.{key}") for key in ("envelope_share", "static_envelope_share"))
        if share is MISSING or static is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        incursions = read.value(world.stage, "live.incursions")
        grades[i] = 2 if incursions not in (0, 0.0) else interval_grade(
            read.value(world.stage, "live.interval.envelope_share_gain"))
        cells.append(f"n_t {read.text(world.stage, 'live.n_t', '{:g}')}: "
                     f"{read.text(world.stage, 'live.incursions', '{:g}')} incursions in "
                     f"{read.text(world.stage, 'live.n_trials', '{:g}')}; "
                     f"{read.text(world.stage, 'live.envelope_share', '{:.1%}')} of the envelope vs static "
                     f"{read.text(world.stage, 'live.static_envelope_share', '{:.1%}')} "
                     f"{read.interval(world.stage, 'live.interval.envelope_share_gain', '{:+.1%}')}".rstrip())
    if grades:
        world = worlds[_weakest(grades)]
        tolerance = read.value(world.stage, "live.tolerance")
        static = read.value(world.stage, f"static.{tolerance}.decided_by")
        why = (f"{world.name}: next step's own n_t at {paper.TOLERANCE_LABELS.get(tolerance, tolerance)} is "
               f"{read.text(world.stage, f'next_step.{tolerance}.best_n_t', '{:g}')}; static's size held by "
               f"{len(static) if isinstance(static, list) else '-'} of "
               f"{read.text(world.stage, f'ceiling.{tolerance}.n_arcs', '{:g}')} arcs")
    else:
        why = UNMEASURED
    return Row(f"live trials: next step at n_t {live['n_t']}, 4 mm/10 deg (Fig. 9)",
               f"{live['incursions']} incursions in {live['n_trials']}; {live['envelope_share']:.1%} of the envelope "
               f"vs static {live['static_envelope_share']:.1%}", cells, verdict(list(grades.values())), why,
               links["predictors"])


def _tracking_cells(worlds: list[World], text: str) -> list[str]:
    """Stage 06 simulates its own scene whatever the worlds: its value in the first column, "-" in the others."""
    return [text] + ["-"] * (len(worlds) - 1)


def _level_grade(read: Reader, key: str, theirs: float, higher_is_better: bool) -> int:
    """The grade of a claim that the tracking's rate or error (``key`` of tracking.json, its interval at
    ``intervals.<key>``) is at least as good as the paper's ``theirs``: the interval of our gain over it (ours - theirs
    for a rate, theirs - ours for an error) read by :func:`interval_grade`."""
    interval = read.value("tracking", f"intervals.{key}")
    if not isinstance(interval, (list, tuple)) or len(interval) != 2 or None in interval:
        return interval_grade(None)
    gains = [end - theirs if higher_is_better else theirs - end for end in interval]
    return interval_grade(sorted(gains))


def _markers_row(read: Reader, worlds: list[World], markers: int, links: dict[str, str]) -> Row:
    """Black and Salcudean III: the share of frames with the correct pose, with 4 or 3 markers (motion (a))."""
    theirs = paper.BLACK_RESULTS["success_rate"][f"markers{markers}"]
    key = f"success_rates.a_markers{markers}"
    grades = [] if read.value("tracking", key) is MISSING else [_level_grade(read, key, theirs, True)]
    shown = f"{read.text('tracking', key, RATE)} {read.interval('tracking', f'intervals.{key}', RATE)}".rstrip()
    cell = f"simulation, motion (a): {shown}" if grades else absent(read.metrics, "tracking")
    why = f"the stress motion (b): {read.text('tracking', f'success_rates.b_markers{markers}', RATE)}" if grades \
        else UNMEASURED
    return Row(f"correct pose, {markers} markers (Black & Salcudean III)", f"{theirs:.2%}",
               _tracking_cells(worlds, cell), verdict(grades), why, links["tracking"])


def _accuracy_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Black and Salcudean III: RMS position (mm, per axis) and Euler-angle (deg) error with the UKF."""
    theirs = paper.BLACK_RESULTS
    keys = ("rms_axis_mm.ukf", "rms_euler_deg.ukf")
    grades = [] if any(read.value("tracking", key) is MISSING for key in keys) else [max(
        _level_grade(read, keys[0], theirs["rms_mm"]["ukf"], False),
        _level_grade(read, keys[1], theirs["rms_deg"]["ukf"], False))]
    cell = (f"simulation: {read.text('tracking', keys[0], '{:.2f}')} mm "
            f"{read.interval('tracking', f'intervals.{keys[0]}', '{:.2f}')} / "
            f"{read.text('tracking', keys[1], '{:.2f}')} deg "
            f"{read.interval('tracking', f'intervals.{keys[1]}', '{:.2f}')}"
            .replace("  ", " ").rstrip() if grades else absent(read.metrics, "tracking"))
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
    if read.value("predictors", "hazard.trained_on_arcs") not in (MISSING, 0):
        rows += [_hazard_row(read, worlds, predictor, links) for predictor in HAZARD]
    rows += [_lines_row(read, worlds, links), _pnp_row(read, worlds, links), _live_row(read, worlds, links),
             _markers_row(read, worlds, 4, links), _markers_row(read, worlds, 3, links),
             _accuracy_row(read, worlds, links)]
    return rows


POPULATION_ROWS = ("static", "long_range", "next_step", "mlp", "error_long_range", "error_next_step",
                   "error_next_step_observed", "hazard_next_step", "hazard_long_range")
# the summary's lines of the population (issue 49; the hazard's, issue 50: its others' point is the h chosen on the
# training worlds' held-out curves, population/hazard.py)


def population_lines(metrics: dict[str, dict]) -> list[str]:
    """The population's lines (``population.json``, issue 49): per predictor and tolerance, the median share of the
    ceiling over the worlds with its 10-90 % range at the world's own operating point and at the point chosen on the
    other worlds, the share of worlds with zero incursion at that point, and the worlds in which it beats long range
    with the sign test's p. No lines when the population has not run."""
    read = Reader(metrics)
    if read.value("population", "n_worlds") is MISSING:
        return []

    def cell(predictor: str, tolerance: str) -> str:
        at = f"across.{tolerance}.{predictor}"
        own = (f"{read.text('population', f'{at}.own.median_share', SHARE)} "
               f"{read.interval('population', f'{at}.own.share_10_90', SHARE)}")
        others = (f"{read.text('population', f'{at}.others.median_share', SHARE)} "
                  f"{read.interval('population', f'{at}.others.share_10_90', SHARE)}, zero incursion in "
                  f"{read.text('population', f'{at}.others.zero_incursion_worlds', SHARE)} of worlds")
        pair, won, lost = f"paired.own.{tolerance}.{predictor} vs long_range", "wins", "losses"
        if read.value("population", pair) is MISSING:  # the pair read the other way: "long_range vs mlp"
            pair, won, lost = f"paired.own.{tolerance}.long_range vs {predictor}", "losses", "wins"
        wins = "-" if predictor in ("long_range", "static") else (
            f"{read.text('population', f'{pair}.{won}', '{:g}')}-{read.text('population', f'{pair}.{lost}', '{:g}')} "
            f"(p {read.text('population', f'{pair}.sign_test_p', '{:.2f}')})")
        return f"{own} | {others} | {wins}"

    n = read.text("population", "n_worlds", "{:g}")
    head = " | ".join(f"{paper.TOLERANCE_LABELS[t]}: own point | others' point | beats long range, worlds"
                      for t in paper.TOLERANCES)
    r11 = read.value("population", "ground_truth.r11_passed_worlds")
    truth = f"; R11 passed in {r11} of them" if r11 is not MISSING else ""
    return [f"**On a population of {n} rendered worlds** (issue 49; each the paper's protocol, drawn from params.yaml "
            f"`population`{truth}): the median share of the ceiling over the worlds [its 10-90 % range], at each "
            "world's own operating point and at the point chosen on the other worlds (`population.json` `rule`), "
            "both against the world's own static baseline (static's own share is 0 by definition); the worlds in "
            "which it beats long range at their own points, won-lost (two-sided sign test). "
            "[Figure](figures/08_population.png).", "",
            f"| predictor | {head} |", "| --- |" + " --- |" * 3 * len(paper.TOLERANCES)] + [
            f"| {NAMES[p]} | " + " | ".join(cell(p, t) for t in paper.TOLERANCES) + " |"
            for p in POPULATION_ROWS if read.value("population", f"across.{paper.TOLERANCES[0]}.{p}") is not MISSING]


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
             "is (its SPL - static's) / (mean theta_a - static's): it compares predictors fairly across worlds. "
             f"Figures: {figures}.", "",
             RULE, "",
             "| claim (paper) | paper | " + " | ".join(f"ours: {world.name}" for world in worlds)
             + " | verdict | why |", "| --- | --- |" + " --- |" * len(worlds) + " --- | --- |"]
    lines += [f"| {row.claim} | {row.paper} | " + " | ".join(row.cells)
              + f" | {row.verdict} | [{row.why}]({row.link}) |" for row in rows]
    population = population_lines(metrics)
    return [*lines, "", *population, *([""] if population else [])]
