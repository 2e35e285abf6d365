"""The summary's first section: each claim of the two papers, judged as the paper measured it, on each world.

One measure in the paper's column and ours: the gain over the claim's baseline (static, the MLP, or for the tracking
the paper's own figure), ours with its 90 % interval, and for a localization predictor its share of the ceiling beside
it. One verdict per claim by one rule (:data:`RULE`), and the caveat the verdict needs beside it, linked to the stage
page that shows it (:mod:`~poseintegrity.report.stage_pages`). A two-part claim is two rows. Where we measured a claim
another way too (our tracking sigmas, the paper's fixed n_t), that is a named variant in a table of its own, never the
claim's row.

Every number it shows is a value of the metrics files, rounded as shown: none is computed here but the count of
realism bars failed (bars - bars passed). A key that the stage which ran did not write is "not measured"; a stage that
did not run, "not run".

The ceiling: a predictor that knew every arc's theta_a would reach mean SPL = mean theta_a at zero incursion, and the
static baseline reaches about the smallest theta_a, so mean / min - 1 (``ceiling.<tolerance>.gain`` of
predictors.json and validation.json) bounds any predictor's gain over static; (SPL - static SPL) / (mean theta_a -
static SPL) (``<predictor>.<tolerance>.ceiling_share``) is the share of it a predictor reaches.

The verdict reads the interval of our gain over each claim's baseline on each world (:func:`interval_grade`: a point
value over 21 arcs moves by tens of points with one arc); the weakest world decides. The paper's figures are read from
:mod:`poseintegrity.paper_results`.
"""

from __future__ import annotations

from dataclasses import dataclass

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.envelope_causes import ENDINGS
from poseintegrity.report.lookup import MISSING, absent
from poseintegrity.report.reader import RATE, SHARE, SPL, Reader
from poseintegrity.report.recorded import recorded_source
from poseintegrity.report.stage_pages import page_path, section_link
from poseintegrity.world_order import FIRST, world_order

TITLE = "What held, where, and by how much"
VERDICTS = ("reproduced", "undecided", "not reproduced")  # grades 0, 1, 2 of one world
NOT_APPLICABLE, UNMEASURED = "not applicable", "no world here measures it"
RULE = ("**Verdict**, the weakest world deciding, read from the 90 % interval of our gain over the claim's baseline, "
        "never from its point value: *reproduced*, the interval lies above zero (on the paper's side of its figure); "
        "*undecided*, it holds zero; *not reproduced*, it lies below zero, or no operating point reaches zero "
        "incursion; *not applicable*, no world measures it. No interval: undecided.")
TABLES = {"long_range": "Tables I, III", "next_step": "Tables II, III"}
PNP_VARIANTS = {"epnp": "EPnP", "p3p": "P3P", "ap3p": "AP3P"}  # the paper's three (V-A, Fig. 6)
MARKERS = {"a_markers3_drop1": "m1", "a_markers3": "m2", "a_markers3_drop3": "m3", "a_markers3_drop4": "m4"}
# tracking.json success_rates of motion (a) with one marker removed (track.drop_marker is m2's, the headline before)


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
    """One line of the table: ``cells`` are ours per world; ``caveat`` is what the verdict needs beside it, ``link``
    the page that shows it."""

    claim: str
    paper: str
    cells: list[str]
    verdict: str
    caveat: str
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


def _weakest(grades: dict[int, int]) -> int:
    """The index of the world whose grade decides the verdict (the first of the weakest)."""
    return max(grades, key=lambda i: (grades[i], -i))


def _relative(read: Reader, stage: str, entry: str) -> str:
    """A relative gain with its interval, "+18% [-5%, +34%]" (``<entry>.relative_gain``, ``<entry>.interval``)."""
    return " ".join(filter(None, (read.text(stage, f"{entry}.relative_gain", "{:+.0%}"),
                                  read.interval(stage, f"{entry}.interval.relative_gain", "{:+.0%}"))))


def _held_by(read: Reader, world: World, predictor: str, tolerance: str) -> str:
    """Why the weakest world's operating point sits where it does: its ceiling, how many arcs hold the predictor's
    operating point and static's size (they incur at the next bolder one), and how the first of them ends."""
    n_arcs = read.value(world.stage, f"ceiling.{tolerance}.n_arcs")
    of = f" of {n_arcs:g}" if isinstance(n_arcs, (int, float)) else ""
    held = {p: read.value(world.stage, f"{p}.{tolerance}.decided_by") for p in (predictor, "static")}
    held = {p: arcs if isinstance(arcs, list) else [] for p, arcs in held.items()}
    ceiling = f"ceiling {read.text(world.stage, f'ceiling.{tolerance}.gain', '{:+.0%}')}"
    if not held[predictor]:
        return f"{world.name}: {ceiling}; no arc holds its operating point"
    arc = held[predictor][0]
    causes = read.value("artifacts", f"{world.prefix}envelope_causes")
    row = next((c for c in causes if c.get("dataset") == arc and c.get("tolerance") == tolerance),
               {}) if isinstance(causes, list) else {}
    ending = ENDINGS.get(row.get("cause"), f"on {row.get('cause')}").split(" (")[0]  # without the parenthesis
    ends = f", ending {ending} at {SPL.format(row['theta_a'])} deg" if row.get("theta_a") is not None else ""
    return (f"{world.name}: {ceiling}; {len(held[predictor])}{of} arcs hold n_t "
            f"{read.text(world.stage, f'{predictor}.{tolerance}.best_n_t', '{:g}')} ({arc}{ends}), "
            f"{len(held['static'])} static's size")


def _over_static_row(read: Reader, worlds: list[World], predictor: str, tolerance: str, links: dict[str, str]) -> Row:
    """Tables I-III: the predictor's relative gain over static at zero incursion with its interval (the verdict reads
    the interval of the gain), the two SPLs and its n_t, and its share of the ceiling with its interval."""
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
        spl = read.text(world.stage, f"{entry}.max_mean_spl_zero_incursion")
        cells.append(f"{_relative(read, world.stage, entry)} ({spl} vs {read.text(world.stage, static)} deg, n_t "
                     f"{read.text(world.stage, f'{entry}.best_n_t', '{:g}')}); {read.share(world.stage, entry)}")
    caveat = _held_by(read, worlds[_weakest(grades)], predictor, tolerance) if grades else UNMEASURED
    return Row(f"{paper.TOLERANCE_LABELS[tolerance]}: {'long range' if predictor == 'long_range' else 'next step'} "
               f"over static ({TABLES[predictor]})",
               f"{margin:+.0%} ({theirs[predictor][tolerance]:.1f} vs {theirs['static'][tolerance]:.1f} deg, n_t "
               f"{paper.WINDSOR_THRESHOLDS[predictor][tolerance]})", cells, verdict(list(grades.values())), caveat,
               links["envelopes"])


def _mlp_over_static_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Table I, the claim's first half: the MLP over static at each tolerance, its relative gain with its interval and
    its share of the ceiling (the weaker tolerance decides)."""
    theirs = paper.WINDSOR_SPL_ZERO_INCURSION
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        if read.value(world.stage, f"mlp.{paper.TOLERANCES[0]}") is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        grades[i] = max(2 if read.value(world.stage, f"mlp.{t}.max_mean_spl_zero_incursion") is None else
                        interval_grade(read.value(world.stage, f"mlp.{t}.interval.gain")) for t in paper.TOLERANCES)
        cells.append(" · ".join(_relative(read, world.stage, f"mlp.{t}") for t in paper.TOLERANCES) + "; "
                     + read.share(world.stage, *(f"mlp.{t}" for t in paper.TOLERANCES)))
    world = worlds[_weakest(grades)] if grades else None
    caveat = (f"{world.name}: the MLP's fits are non-physical in "
              f"{read.text(world.stage, 'fit_status.mlp.non_physical', SHARE)} of its rows" if world else UNMEASURED)
    return Row("both tolerances: MLP over static (Table I)",
               " · ".join(f"{theirs['mlp'][t] / theirs['static'][t] - 1:+.0%}" for t in paper.TOLERANCES)
               + " (" + " · ".join(f"{theirs['mlp'][t]:.1f}" for t in paper.TOLERANCES) + " vs 7.0 deg)", cells,
               verdict(list(grades.values())), caveat, links["fits"])


def _arcs_holding(read: Reader, world: World, tolerance: str) -> str:
    """How many arcs hold long range's and the MLP's operating points at ``tolerance`` on ``world``, of how many."""
    held = [read.value(world.stage, f"{p}.{tolerance}.decided_by") for p in ("long_range", "mlp")]
    n_arcs = read.text(world.stage, f"ceiling.{tolerance}.n_arcs", "{:g}")
    counts = " · ".join(str(len(arcs)) if isinstance(arcs, list) else "-" for arcs in held)
    return f"{paper.TOLERANCE_LABELS[tolerance]}: n_t held by {counts} of {n_arcs} arcs"


def _over_mlp_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Table I, the claim's second half: long range over the MLP, judged per tolerance on the paired difference of the
    two on the same draws (the weaker tolerance decides); the relative gain is the mean of both, as the paper's."""
    pair = "intervals.{}.pairs.long_range vs mlp.difference"
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        if read.value(world.stage, "long_range.relative_improvement_vs_mlp") is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        grades[i] = max(interval_grade(read.value(world.stage, pair.format(t))) for t in paper.TOLERANCES)
        differences = " · ".join(
            f"{read.text(world.stage, pair.format(t).replace('difference', 'point'), '{:+.1f}')} deg "
            f"{read.interval(world.stage, pair.format(t), '{:+.1f}')}".rstrip() for t in paper.TOLERANCES)
        cells.append(f"{read.text(world.stage, 'long_range.relative_improvement_vs_mlp', '{:+.1%}')} "
                     f"({differences})")
    world = worlds[_weakest(grades)] if grades else None
    caveat = f"{world.name}: " + "; ".join(_arcs_holding(read, world, t) for t in paper.TOLERANCES) if world \
        else UNMEASURED
    return Row("both tolerances: long range over the MLP (Table I)",
               f"{paper.WINDSOR_IMPROVEMENTS['long_range_vs_mlp']:+.1%} (mean of both)", cells,
               verdict(list(grades.values())), caveat, links["fits"])


def _lines_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Fig. 7: long range over static on the straight lines (V-A); a world's lines resampled one by one."""
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        if read.value(world.stage, "straight_line.relative_improvement") is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        spl = read.value(world.stage, "straight_line.long_range_max_mean_spl_zero_incursion")
        grades[i] = 2 if spl is None else interval_grade(read.value(world.stage, "straight_line.interval.gain"))
        cells.append(f"{read.text(world.stage, 'straight_line.relative_improvement', '{:+.0%}')} "
                     f"{read.interval(world.stage, 'straight_line.interval.relative_gain', '{:+.0%}')} ("
                     f"{read.text(world.stage, 'straight_line.long_range_max_mean_spl_zero_incursion')} vs "
                     f"{read.text(world.stage, 'straight_line.static_max_mean_spl_zero_incursion')} mm)")
    world = worlds[_weakest(grades)] if grades else None
    spread = f"{world.prefix}realism.line_x_a_mean_over_min_2mm3deg" if world else ""
    caveat = (f"{world.name}: {read.text(world.stage, 'straight_line.n_lines', '{:g}')} lines of one scene; their "
              f"spread, R8, is {read.text('artifacts', spread, '{:.2f}')} (bar >= 1.4)" if world else UNMEASURED)
    return Row("2 mm/3 deg: straight lines, long range over static (Fig. 7)",
               f"{paper.WINDSOR_IMPROVEMENTS['straight_line_vs_static']:+.0%}", cells, verdict(list(grades.values())),
               caveat, links["realism"])


def _pnp_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Fig. 6: on each of the paper's three PnP variants, long range beats static (no margin published)."""
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        shown, variant_grades = [], []
        for method, name in PNP_VARIANTS.items():
            spl = read.value(world.stage, f"pnp.{method}.max_mean_spl_zero_incursion")
            if spl is MISSING or read.value(world.stage, f"pnp.{method}.static_max_mean_spl_zero_incursion") is MISSING:
                continue
            variant_grades.append(2 if spl is None else interval_grade(
                read.value(world.stage, f"pnp.{method}.interval.gain")))
            shown.append(f"{name} {read.text(world.stage, f'pnp.{method}.max_mean_spl_zero_incursion')} vs "
                         f"{read.text(world.stage, f'pnp.{method}.static_max_mean_spl_zero_incursion')} deg "
                         f"{read.interval(world.stage, f'pnp.{method}.interval.relative_gain', '{:+.0%}')}".rstrip())
        if variant_grades:
            grades[i] = max(variant_grades)
        cells.append(" · ".join(shown) or absent(read.metrics, world.stage))
    world = worlds[_weakest(grades)] if grades else None
    caveat = f"{world.name}: frames without a pose: " + ", ".join(
        f"{name} {read.text('pnp', f'{world.prefix}methods.{method}.failure_rate', '{:.0%}')}"
        for method, name in {"usac_magsac": "USAC", **PNP_VARIANTS}.items()) if world else UNMEASURED
    return Row("2 mm/3 deg: PnP variants, long range over static on EPnP · P3P · AP3P (Fig. 6)",
               "beats static on each", cells,
               verdict(list(grades.values())), caveat, links["pnp"])


def _trials(read: Reader, stage: str, at: str) -> str:
    """Simulated live trials (``at``: a ``live`` block of ``stage``'s metrics) as the paper gives them: the share of
    the envelope used against static's, the interval of the gain, the incursions of the trials."""
    return (f"{read.text(stage, f'{at}.envelope_share', '{:.1%}')} vs "
            f"{read.text(stage, f'{at}.static_envelope_share', '{:.1%}')}, gain "
            f"{read.interval(stage, f'{at}.interval.envelope_share_gain', '{:+.1%}')}; "
            f"incursions {read.text(stage, f'{at}.incursions', '{:g}')} of "
            f"{read.text(stage, f'{at}.n_trials', '{:g}')}")


def _live_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Fig. 9, V-C: next step supervising the robot, no incursion and more of the envelope used than by static; judged
    on the held-out trials (``live.heldout``: each scene's n_t and static's size chosen on the other scenes)."""
    live, held = paper.WINDSOR_LIVE, "live.heldout"
    cells, grades = [], {}
    for i, world in enumerate(worlds):
        if read.value(world.stage, f"{held}.envelope_share") is MISSING:
            cells.append(absent(read.metrics, world.stage))
            continue
        incursions = read.value(world.stage, f"{held}.incursions")
        grades[i] = 2 if incursions not in (0, 0.0) else interval_grade(
            read.value(world.stage, f"{held}.interval.envelope_share_gain"))
        n_t = read.value(world.stage, f"{held}.n_t")
        n_t = f"{min(n_t.values()):g}-{max(n_t.values()):g}" if isinstance(n_t, dict) and n_t else "-"
        cells.append(f"{_trials(read, world.stage, held)}, n_t {n_t} by scene")
    caveat = UNMEASURED
    if grades:
        world = worlds[_weakest(grades)]
        caveat = (f"{world.name}: n_t chosen on the other scenes; the paper chose its n_t "
                  f"{live['n_t']} on the data it was judged beside")
    return Row("4 mm/10 deg: live trials, next step, n_t held out (Fig. 9)",
               f"{live['envelope_share']:.1%} vs {live['static_envelope_share']:.1%} of the envelope; "
               f"incursions {live['incursions']} of {live['n_trials']}, n_t {live['n_t']}", cells,
               verdict(list(grades.values())), caveat, links["predictors"])


def _tracking_cells(worlds: list[World], text: str) -> list[str]:
    """Stage 06 simulates its own scene whatever the worlds: its value in the first column, "-" in the others."""
    return [text] + ["-"] * (len(worlds) - 1)


def _level_grade(read: Reader, key: str, theirs: float, higher_is_better: bool) -> int:
    """The grade of a claim that the tracking's rate or error (its interval at ``key`` of tracking.json) is at least as
    good as the paper's ``theirs``: the interval of our gain over it (ours - theirs for a rate, theirs - ours for an
    error) read by :func:`interval_grade`."""
    interval = read.value("tracking", key)
    if not isinstance(interval, (list, tuple)) or len(interval) != 2 or None in interval:
        return interval_grade(None)
    gains = [end - theirs if higher_is_better else theirs - end for end in interval]
    return interval_grade(sorted(gains))


def _markers_row(read: Reader, worlds: list[World], markers: int, links: dict[str, str]) -> Row:
    """Black and Salcudean III: the share of frames with the correct pose on motion (a); with 3 markers, the mean of
    the four ways to remove one (the paper does not say which it removed), each shown."""
    theirs = paper.BLACK_RESULTS["success_rate"][f"markers{markers}"]
    key = "success_rates.a_markers4" if markers == 4 else "success_rates.a_markers3_mean"
    measured = read.value("tracking", key) is not MISSING
    grades = [_level_grade(read, f"intervals.{key}", theirs, True)] if measured else []
    cell = (f"{read.text('tracking', key, RATE)} {read.interval('tracking', f'intervals.{key}', RATE)}".rstrip()
            if measured else absent(read.metrics, "tracking"))
    if measured and markers == 3:
        cell = "mean of the four removals " + cell + "; " + " · ".join(
            f"{name} {read.text('tracking', f'success_rates.{k}', '{:.1%}')}" for k, name in MARKERS.items())
    caveat = (f"the stress motion (b): {read.text('tracking', f'success_rates.b_markers{markers}', RATE)}"
              if measured else UNMEASURED)
    if measured and markers == 3:
        caveat = ("the paper does not say which marker it removed (each removal's interval is on the tracking page); "
                  + caveat)
    return Row(f"correct pose, {markers} markers (Black & Salcudean III)", f"{theirs:.2%}",
               _tracking_cells(worlds, cell), verdict(grades), caveat, links["tracking"])


PACE = "paper_pace"  # tracking.json: the accuracy recording at the pace the paper's lag and errors imply


def _errors(read: Reader, mm: str, deg: str, lag: str, intervals: dict[str, str]) -> str:
    """The tracking's RMS errors as the paper reports them (per axis, mm; Euler angles, deg) and the lag (ms), keys of
    tracking.json, each with its interval where ``intervals`` names one (by "mm", "deg", "lag"), e.g.
    "1.31 mm [1.25, 1.38] / 4.03 deg [3.36, 4.60], lag 82 ms"."""
    def shown(name: str, key: str, fmt: str, unit: str) -> str:
        return " ".join(filter(None, (f"{read.text('tracking', key, fmt)} {unit}",
                                      read.interval("tracking", intervals.get(name, ""), fmt))))

    return (f"{shown('mm', mm, '{:.2f}', 'mm')} / {shown('deg', deg, '{:.2f}', 'deg')}, "
            f"lag {shown('lag', lag, '{:.0f}', 'ms')}")


def _accuracy_row(read: Reader, worlds: list[World], links: dict[str, str]) -> Row:
    """Black and Salcudean III: RMS position (mm, per axis) and Euler-angle (deg) error with the UKF and the lag, with
    the published sigmas on a hand motion at the paper's pace (``paper_pace.published``)."""
    theirs = paper.BLACK_RESULTS
    at = f"{PACE}.published"
    keys = (f"{at}.axis_mm", f"{at}.euler_deg")
    measured = all(read.value("tracking", key) is not MISSING for key in keys)
    grades = [max(_level_grade(read, f"{at}.intervals.axis_mm", theirs["rms_mm"]["ukf"], False),
                  _level_grade(read, f"{at}.intervals.euler_deg", theirs["rms_deg"]["ukf"], False))] if measured else []
    cell = (_errors(read, *keys, f"{at}.lag_ms", {name: f"{at}.intervals.{figure}" for name, figure in (
        ("mm", "axis_mm"), ("deg", "euler_deg"), ("lag", "lag_ms"))}) if measured else absent(read.metrics, "tracking"))
    caveat = (f"a hand at {read.text('tracking', f'{PACE}.pace.euler_rad_s.mean', '{:.3f}')} rad/s and "
              f"{read.text('tracking', f'{PACE}.pace.velocity_mm_s.mean', '{:.1f}')} mm/s per axis (RMS), the pace at "
              "which the paper's lag alone gives its errors; the orientation lags "
              f"{read.text('tracking', f'{at}.euler_lag_ms', '{:.0f}')} ms" if measured else UNMEASURED)
    return Row("accuracy with the UKF, published sigmas, the paper's pace (Black & Salcudean III, Fig. 9)",
               f"{theirs['rms_mm']['ukf']:g} mm / {theirs['rms_deg']['ukf']:g} deg, lag {theirs['lag_ms']:g} ms",
               _tracking_cells(worlds, cell), verdict(grades), caveat, links["tracking"])


def claim_rows(metrics: dict[str, dict], worlds: list[World], links: dict[str, str]) -> list[Row]:
    """The claims' rows: Tables I-III, Table I's two halves, Figs. 7, 6 and 9, then Black and Salcudean's success
    rates and accuracy. ``links``: section name -> its link."""
    read = Reader(metrics)
    rows = [_over_static_row(read, worlds, predictor, tolerance, links)
            for predictor in ("long_range", "next_step") for tolerance in paper.TOLERANCES]
    return [*rows, _mlp_over_static_row(read, worlds, links), _over_mlp_row(read, worlds, links),
            _lines_row(read, worlds, links), _pnp_row(read, worlds, links), _live_row(read, worlds, links),
            _markers_row(read, worlds, 4, links), _markers_row(read, worlds, 3, links),
            _accuracy_row(read, worlds, links)]


def variant_rows(metrics: dict[str, dict], links: dict[str, str]) -> list[tuple[str, str, str, str]]:
    """Our other measurements of a claim, named and beside it, no verdict: (variant, the claim's paper figure, ours,
    link). The tracking with our sigmas at the paper's pace and on our motion (a); the live trials at the paper's fixed
    n_t."""
    read, live, black = Reader(metrics), paper.WINDSOR_LIVE, paper.BLACK_RESULTS
    tracking = (_errors(read, "rms_axis_mm.ukf", "rms_euler_deg.ukf", "lag_ms.ukf", {
                    "mm": "intervals.rms_axis_mm.ukf", "deg": "intervals.rms_euler_deg.ukf"})
                + "; the published sigmas on it: "
                f"{read.text('tracking', 'sigmas_motion_a.published.axis_mm', '{:.1f}')} mm, lag "
                f"{read.text('tracking', 'sigmas_motion_a.published.lag_ms', '{:.0f}')} ms")
    fixed = _trials(read, "predictors", "live")
    ours = f"{PACE}.ours"
    pace = (_errors(read, f"{ours}.axis_mm", f"{ours}.euler_deg", f"{ours}.lag_ms", {
                "mm": f"{ours}.intervals.axis_mm", "deg": f"{ours}.intervals.euler_deg"}) + "; no filter "
            f"{read.text('tracking', f'{PACE}.no_filter.axis_mm', '{:.2f}')} mm / "
            f"{read.text('tracking', f'{PACE}.no_filter.euler_deg', '{:.2f}')} deg")
    return [("accuracy, our sigmas at the paper's pace",
             f"{black['rms_mm']['ukf']:g} mm / {black['rms_deg']['ukf']:g} deg", pace, links["tracking"]),
            ("accuracy, our sigmas on our motion (a), ten times faster",
             f"{black['rms_mm']['ukf']:g} mm / {black['rms_deg']['ukf']:g} deg", tracking, links["tracking"]),
            (f"live trials at the paper's n_t {live['n_t']}, chosen with these arcs in view",
             f"{live['envelope_share']:.1%} vs {live['static_envelope_share']:.1%}", fixed, links["predictors"])]


def data_line(metrics: dict[str, dict], worlds: list[World], links: dict[str, str]) -> str:
    """What the data are: rendered (or the user's recordings), how many realism bars each world fails, and what its
    hardest arc does to every gain over static."""
    read = Reader(metrics)
    source = recorded_source(metrics)
    if source is not None:
        return (f"**The data are your recordings** (`{source}`): no realism bar is judged on them; the tracking runs "
                "on its own simulation.")
    failed = []
    for world in worlds:
        bars, passed = (read.value("artifacts", f"{world.prefix}realism.{k}") for k in ("n_bars", "n_bars_passed"))
        if isinstance(bars, int) and isinstance(passed, int):
            failed.append(f"{world.name} {bars - passed} of {bars}")
    hardest = read.text("artifacts", "realism.min_theta_a_2mm3deg")
    ceiling = read.text("predictors", f"ceiling.{paper.TOLERANCES[0]}.gain", "{:+.0%}")
    return (f"**The data are rendered, not recorded** (no real robot data exists for us). Realism bars failed: "
            f"{', '.join(failed) or absent(metrics, 'artifacts')}. The main world's hardest arc ends at {hardest} deg "
            f"against the paper's 7.0, which caps every gain over static at {ceiling} (2 mm/3 deg; the paper's at "
            f"least +99%). The tracking data are simulated. [Which bars]({links['realism']}).")


def glossary(links: dict[str, str]) -> list[str]:
    """Five lines: the words the table uses."""
    return [f"- **theta_a**: the actual envelope, the viewing angle (deg; mm on the lines) at which localization first "
            f"misses the tolerance, 2 mm/3 deg or 4 mm/10 deg ([why each ends]({links['envelopes']})).",
            "- **SPL, R_i**: the safe path length the robot travels before it stops (eq. 3) and the incursion rate, "
            "the share of arcs where it stops past theta_a (eq. 4); a predictor is scored by its largest mean SPL at "
            "R_i = 0.",
            "- **n_t, k**: the operating point, the inlier threshold n_t of the paper's predictors (the safety factor "
            f"k of ours on the predicted error, [stage 04]({links['predictors']})).",
            "- **ceiling, share**: the most any predictor can gain over static on a world (mean theta_a / smallest - "
            "1); a predictor's share of the ceiling is its gain over static over that.",
            "- **worlds**: *main* (21 arcs in 7 scenes; operating points chosen on it), *validation* (held out, "
            f"nothing tuned on it), [a population of 12]({page_path('08_population')}); intervals are 90 %, scenes "
            "resampled, the operating point chosen again in each draw."]


def claims_section(metrics: dict[str, dict]) -> list[str]:
    """Markdown lines of the first section: what the data are, the glossary, the rule, the claims and the variants."""
    recorded = recorded_source(metrics) is not None
    links = {section: section_link(section, recorded)
             for section in ("predictors", "envelopes", "fits", "pnp", "tracking", "realism")}
    worlds = metric_worlds(metrics)
    lines = [f"## {TITLE}", "", data_line(metrics, worlds, links), "", *glossary(links), "", RULE, "",
             "| claim (paper) | paper: gain over baseline | " + " | ".join(f"ours: {world.name}" for world in worlds)
             + " | verdict | caveat |", "| --- | --- |" + " --- |" * len(worlds) + " --- | --- |"]
    lines += [f"| {row.claim} | {row.paper} | " + " | ".join(row.cells)
              + f" | {row.verdict} | [{row.caveat}]({row.link}) |" for row in claim_rows(metrics, worlds, links)]
    lines += ["", "**Our variants of a claim** (named, no verdict):", "", "| variant | paper | ours |",
              "| --- | --- | --- |"]
    lines += [f"| [{name}]({link}) | {theirs} | {ours} |" for name, theirs, ours, link in variant_rows(metrics, links)]
    return [*lines, ""]
