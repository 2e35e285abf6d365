"""The summary's first section (report/claims.py): one screen before any stage table, every number in it the metrics
files' value, every verdict the one its stated rule gives. The expected values and verdicts are written here from the
metrics by hand (plain dict access and the rule as the section states it), not through the report's code."""

import copy
import json
import re

import pytest

from poseintegrity import paper_results as paper
from poseintegrity.report.beyond_papers import TITLE as BEYOND
from poseintegrity.report.claims import RULE, TITLE, interval_grade
from poseintegrity.report.headline_file import HEADLINE_FILE, headline_metrics
from poseintegrity.report.stage_pages import render_pages
from poseintegrity.report.summary import read_metrics, render_summary
from report_text import report_text
from repository import ROOT
from test_report_recorded import RECORDED

COMMITTED = read_metrics(ROOT / "reports" / "metrics")  # the paper-scale run
TOLERANCES = paper.TOLERANCES
WORLDS = (("predictors", ""), ("validation", "worlds.validation."))  # (stage, prefix in artifacts.json / pnp.json)
OURS = ("error_long_range", "error_next_step", "error_next_step_observed", "error_combined")
OURS_NAMES = {"error_next_step_observed": "observed error next step"}  # no claim's name begins another's


def with_issue_38(metrics: dict) -> dict:
    """The committed metrics with the keys issue 38 adds (CONTRACTS.md), each value distinct."""
    metrics = copy.deepcopy(metrics)
    for w, stage in enumerate(("predictors", "validation")):
        table = metrics[stage]
        table["ceiling"] = {t: {"n_arcs": 17 - w - i, "mean_theta_a": 21.3 + i, "min_theta_a": 14.6 - w,
                                "static_spl": table["static"][t]["max_mean_spl_zero_incursion"],
                                "gain": 0.471 + 0.2 * i + w} for i, t in enumerate(TOLERANCES)}
        for j, predictor in enumerate(("long_range", "next_step", "mlp")):
            for i, t in enumerate(TOLERANCES):
                table[predictor][t]["ceiling_share"] = 0.2 + 0.1 * j + 0.03 * i - 0.5 * w
        for j, predictor in enumerate(OURS):
            table[predictor] = {t: {"max_mean_spl_zero_incursion": 17.0 + j + i + w, "best_k": 2.5 + j,
                                    "best_n_t": None, "decided_by": [], "ceiling_share": 0.55 + 0.01 * j - 0.1 * i}
                                for i, t in enumerate(TOLERANCES)}
    return metrics


def before_issue_49(metrics: dict) -> dict:
    """The metrics as a run before issue 49 wrote them: no interval anywhere (every verdict then undecided)."""
    metrics = copy.deepcopy(metrics)
    for stage in ("predictors", "validation", "tracking"):
        table = metrics[stage]
        table.pop("intervals", None)
        for entry in table.values():
            if isinstance(entry, dict):
                entry.pop("interval", None)
                for value in entry.values():
                    if isinstance(value, dict) and "max_mean_spl_zero_incursion" in value:  # a predictor's entry
                        for key in ("interval", "gain", "relative_gain"):
                            value.pop(key, None)
    return metrics


def before_issue_38(metrics: dict) -> dict:
    """The metrics as a run before issue 38 wrote them: no ceiling, no shares, no error predictors (no intervals), and
    none of what came later (issue 50's hazard)."""
    metrics = before_issue_49(metrics)
    for stage in ("predictors", "validation"):
        table = metrics[stage]
        for key in ("ceiling", *OURS, "hazard", "hazard_next_step", "hazard_long_range"):
            table.pop(key, None)
        for entry in table.values():
            for value in entry.values() if isinstance(entry, dict) else ():
                if isinstance(value, dict):
                    value.pop("ceiling_share", None)
    return metrics


OLD = before_issue_38(COMMITTED)
FIXTURES = {"committed": COMMITTED, "before issue 49": before_issue_49(COMMITTED), "before issue 38": OLD,
            "issue 38": with_issue_38(OLD)}


def section(summary: str, title: str = TITLE) -> list[str]:
    """A section's lines (the first section's by default), from its heading to the next heading."""
    start = summary.index(f"## {title}")
    return summary[start:].split("\n## ", 1)[0].splitlines()


def table(summary: str) -> dict[str, list[str]]:
    """The first section's table of claims (its first table; the population's follows it): claim -> its cells
    (paper, ours per world, verdict, why)."""
    lines = section(summary)
    start = next(i for i, line in enumerate(lines) if line.startswith("| claim"))
    end = next((i for i in range(start, len(lines)) if not lines[i].startswith("| ")), len(lines))
    rows = [line.strip("|").split(" | ") for line in lines[start:end] if "---" not in line]
    return {cells[0].strip(): [c.strip() for c in cells[1:]] for cells in rows[1:]}


def get(metrics: dict, stage: str, key: str):
    """The value at a dotted key, KeyError when absent (the test's own reading)."""
    value = metrics[stage]
    for part in key.split("."):
        value = value[part]
    return value


def numbers(cell: str) -> list[tuple[float, float]]:
    """Each number shown in a cell as (value, half of its last digit), percentages as fractions; the tolerances' and
    the markers' names are labels, not values."""
    cell = re.sub(r"\d mm/\d+ deg|\(\w\)", "", cell.split("](")[0])
    found = []
    for sign, digits, decimals, percent in re.findall(r"(?<![\w.])([+-]?)(\d+)(?:\.(\d+))?(%?)(?![\w])", cell):
        value = float(f"{sign}{digits}.{decimals or 0}")
        half = 0.5 * 10.0 ** -len(decimals)
        found.append((value / 100, half / 100) if percent else (value, half))
    return found


def assert_shows(cell: str, values: list, where: str):
    """The numbers of ``cell`` are ``values`` in order (None: not shown, "none"), each within its rounding."""
    shown, expected = numbers(cell), [v for v in values if v is not None]
    assert len(shown) == len(expected), f"{where}: {cell!r} shows {shown}, expected {expected}"
    for (value, half), want in zip(shown, expected):
        assert abs(value - want) <= half * (1 + 1e-9) + 1e-12, f"{where}: {cell!r}: {value} is not {want}"


def verdict(grades: list[int]) -> str:
    """The rule as the section states it: the weakest world decides; no world, not applicable."""
    return ("reproduced", "undecided", "not reproduced")[max(grades)] if grades else "not applicable"


def grade(interval) -> int:
    """One world, by the rule's words: the interval of our gain above zero; below zero or none; else (it holds zero,
    or there is none) undecided."""
    if not isinstance(interval, list):
        return 1
    low, high = interval
    return 2 if high is None or high < 0 else 0 if low is not None and low > 0 else 1


def level(interval, theirs: float, higher_is_better: bool) -> int:
    """A rate's or an error's grade: the interval of ours minus the paper's (theirs minus ours for an error)."""
    if not isinstance(interval, list) or None in interval:
        return 1
    return grade(sorted(end - theirs if higher_is_better else theirs - end for end in interval))


def ends(entry: dict, key: str) -> list:
    """An interval's two ends as a cell shows them (None: "none", not a number), nothing when the metrics hold none."""
    interval = entry.get("interval", {}).get(key) if isinstance(entry, dict) else None
    return list(interval) if isinstance(interval, list) else []


def expectations(m: dict) -> dict[str, tuple[list[list], list, str]]:
    """claim -> (the values each world's cell shows, the values its caveat shows, its verdict), from the metrics."""
    out = {}

    def share(stage, predictor, t):
        return m[stage][predictor][t].get("ceiling_share")

    def weakest(grades):
        return max(range(len(grades)), key=lambda i: (grades[i], -i))

    for predictor, name in (("long_range", "long range"), ("next_step", "next step")):
        for t in TOLERANCES:
            entries = [get(m, s, f"{predictor}.{t}") for s, _ in WORLDS]
            statics = [get(m, s, f"static.{t}.max_mean_spl_zero_incursion") for s, _ in WORLDS]
            cells = [[e.get("relative_gain"), *ends(e, "relative_gain"), e["max_mean_spl_zero_incursion"], st,
                      e["best_n_t"], share(s, predictor, t), *ends(e, "ceiling_share")]
                     for e, st, (s, _) in zip(entries, statics, WORLDS)]
            grades = [2 if e["max_mean_spl_zero_incursion"] is None else grade(e.get("interval", {}).get("gain"))
                      for e in entries]
            w = weakest(grades)
            stage = WORLDS[w][0]
            arcs, static_arcs = entries[w]["decided_by"], get(m, stage, f"static.{t}.decided_by")
            cause = next(c for c in get(m, "artifacts", f"{WORLDS[w][1]}envelope_causes")
                         if c["dataset"] == arcs[0] and c["tolerance"] == t)
            ceiling = m[stage].get("ceiling", {}).get(t, {})
            out[f"{paper.TOLERANCE_LABELS[t]}: {name} over static"] = (
                cells, [ceiling.get("gain"), len(arcs), ceiling.get("n_arcs"), entries[w]["best_n_t"],
                        cause["theta_a"], len(static_arcs)], verdict(grades))
    mlp = [[get(m, s, f"mlp.{t}") for t in TOLERANCES] for s, _ in WORLDS]
    grades = [max(2 if e["max_mean_spl_zero_incursion"] is None else grade(e.get("interval", {}).get("gain"))
                  for e in world) for world in mlp]
    out["both tolerances: MLP over static"] = (
        [[x for e in world for x in (e.get("relative_gain"), *ends(e, "relative_gain"))]
         + [x for e in world for x in (e.get("ceiling_share"), *ends(e, "ceiling_share"))] for world in mlp],
        [get(m, WORLDS[weakest(grades)][0], "fit_status.mlp.non_physical")], verdict(grades))
    pair = "long_range vs mlp"
    pairs = [[get(m, s, "intervals")[t]["pairs"][pair] if "intervals" in m[s] else {} for t in TOLERANCES]
             for s, _ in WORLDS]
    grades = [max(grade(p.get("difference")) for p in world) for world in pairs]
    w = weakest(grades)
    out["both tolerances: long range over the MLP"] = (
        [[get(m, s, "long_range.relative_improvement_vs_mlp")]
         + [x for p in world for x in (p.get("point"), *p.get("difference", []))]
         for (s, _), world in zip(WORLDS, pairs)],
        [x for t in TOLERANCES for x in (*(len(get(m, WORLDS[w][0], f"{p}.{t}.decided_by")) for p in ("long_range", "mlp")),
                                         m[WORLDS[w][0]].get("ceiling", {}).get(t, {}).get("n_arcs"))], verdict(grades))
    lines = [get(m, s, "straight_line") for s, _ in WORLDS]
    grades = [2 if line["long_range_max_mean_spl_zero_incursion"] is None else grade(line.get("interval", {}).get("gain"))
              for line in lines]
    r8 = f"{WORLDS[weakest(grades)][1]}realism.line_x_a_mean_over_min_2mm3deg"
    out["2 mm/3 deg: straight lines"] = (
        [[line["relative_improvement"], *ends(line, "relative_gain"), line["long_range_max_mean_spl_zero_incursion"],
          line["static_max_mean_spl_zero_incursion"]] for line in lines],
        [lines[weakest(grades)].get("n_lines"), get(m, "artifacts", r8), 1.4], verdict(grades))
    variants = ("epnp", "p3p", "ap3p")
    pnp = [[get(m, s, f"pnp.{v}") for v in variants] for s, _ in WORLDS]
    grades = [max(2 if e["max_mean_spl_zero_incursion"] is None else grade(e.get("interval", {}).get("gain"))
                  for e in entries) for entries in pnp]
    out["2 mm/3 deg: PnP variants"] = (
        [[x for e in entries for x in (e["max_mean_spl_zero_incursion"], e["static_max_mean_spl_zero_incursion"],
                                       *ends(e, "relative_gain"))] for entries in pnp],
        [get(m, "pnp", f"{WORLDS[weakest(grades)][1]}methods.{v}.failure_rate") for v in ("usac_magsac", *variants)],
        verdict(grades))
    helds = [m[stage].get("live", {}).get("heldout") for stage, _ in WORLDS]  # each world's held-out trials
    grades = [2 if held["incursions"] else grade(held.get("interval", {}).get("envelope_share_gain"))
              for held in helds if held]
    out["4 mm/10 deg: live trials"] = (
        [[held["envelope_share"], held["static_envelope_share"], *ends(held, "envelope_share_gain"), held["incursions"],
          held["n_trials"], min(held["n_t"].values()), max(held["n_t"].values())] if held else [] for held in helds],
        [paper.WINDSOR_LIVE["n_t"]] if grades else [], verdict(grades))  # the caveat: the paper's n_t
    rates, black = m["tracking"]["success_rates"], paper.BLACK_RESULTS
    intervals = m["tracking"].get("intervals", {})
    interval = intervals.get("success_rates", {}).get("a_markers4")
    out["correct pose, 4 markers"] = ([[rates["a_markers4"], *(interval or [])], []], [rates["b_markers4"]],
                                      verdict([level(interval, black["success_rate"]["markers4"], True)]))
    if "a_markers3_mean" in rates:
        interval = intervals.get("success_rates", {}).get("a_markers3_mean")
        out["correct pose, 3 markers"] = (
            [[rates["a_markers3_mean"], *(interval or []), rates["a_markers3_drop1"], rates["a_markers3"],
              rates["a_markers3_drop3"], rates["a_markers3_drop4"]], []], [rates["b_markers3"]],
            verdict([level(interval, black["success_rate"]["markers3"], True)]))
    else:
        out["correct pose, 3 markers"] = ([[], []], [], "not applicable")
    pace = m["tracking"].get("paper_pace")
    if pace:
        published = pace["published"]
        mm, deg = published["intervals"]["axis_mm"], published["intervals"]["euler_deg"]
        out["accuracy with the UKF"] = (
            [[published["axis_mm"], *mm, published["euler_deg"], *deg, published["lag_ms"],
              *published["intervals"]["lag_ms"]], []],
            [pace["pace"]["euler_rad_s"]["mean"], pace["pace"]["velocity_mm_s"]["mean"], published["euler_lag_ms"]],
            verdict([max(level(mm, black["rms_mm"]["ukf"], False), level(deg, black["rms_deg"]["ukf"], False))]))
    else:
        out["accuracy with the UKF"] = ([[], []], [], "not applicable")
    return out


@pytest.mark.parametrize("fixture", FIXTURES)
def test_every_number_of_the_first_section_is_the_metrics_value_and_every_verdict_follows_the_rule(fixture):
    metrics = FIXTURES[fixture]
    rows = table(render_summary(metrics))
    expected = expectations(metrics)
    assert len(rows) == len(expected)  # a row per claim, a two-part claim two rows
    for claim, (cells, caveat, word) in expected.items():
        found = [row for label, row in rows.items() if label.startswith(claim)]
        assert len(found) == 1, f"{claim}: {list(rows)}"
        paper_cell, *ours, shown_verdict, shown_caveat = found[0]
        assert shown_verdict == word, f"{claim}: {shown_verdict}, by the rule {word}"
        for world, (cell, values) in enumerate(zip(ours, cells)):
            assert_shows(cell, values, f"{claim}, world {world}")
        assert_shows(shown_caveat, caveat, f"{claim}, caveat")
        assert "](stages/" in shown_caveat  # it links to the stage page that shows it


def test_the_data_line_and_the_variants_show_the_metrics_values():
    """What the data are (bars failed per world, the hardest arc, the ceiling) and our named variants of a claim."""
    m = COMMITTED
    lines = section(render_summary(m))
    data = next(line for line in lines if line.startswith("**The data are rendered"))
    realism = [get(m, "artifacts", f"{p}realism") for _, p in WORLDS]
    assert_shows(data, [x for r in realism for x in (r["n_bars"] - r["n_bars_passed"], r["n_bars"])]
                 + [realism[0]["min_theta_a_2mm3deg"], 7.0, m["predictors"]["ceiling"]["2mm_3deg"]["gain"], 0.99],
                 "the data line")
    variants = {row[0]: row[1:] for row in (line.strip("|").split(" | ") for line in lines
                                            if line.startswith("| [") and "---" not in line)}
    pace = next(cells for name, cells in variants.items() if "the paper's pace" in name)
    ours, no_filter = m["tracking"]["paper_pace"]["ours"], m["tracking"]["paper_pace"]["no_filter"]
    assert_shows(pace[1], [ours["axis_mm"], *ours["intervals"]["axis_mm"], ours["euler_deg"],
                           *ours["intervals"]["euler_deg"], ours["lag_ms"], no_filter["axis_mm"], no_filter["euler_deg"]],
                 "our sigmas at the paper's pace")
    tracking = next(cells for name, cells in variants.items() if "motion (a)" in name)
    t = m["tracking"]
    assert_shows(tracking[1], [t["rms_axis_mm"]["ukf"], *t["intervals"]["rms_axis_mm"]["ukf"], t["rms_euler_deg"]["ukf"],
                               *t["intervals"]["rms_euler_deg"]["ukf"], t["lag_ms"]["ukf"],
                               t["sigmas_motion_a"]["published"]["axis_mm"], t["sigmas_motion_a"]["published"]["lag_ms"]],
                 "our sigmas")
    live = m["predictors"]["live"]
    fixed = next(cells for name, cells in variants.items() if "paper's n_t" in name)
    assert_shows(fixed[1], [live["envelope_share"], live["static_envelope_share"],
                            *live["interval"]["envelope_share_gain"], live["incursions"], live["n_trials"]], "fixed n_t")


def test_a_run_without_the_ceiling_says_so():
    rows = table(render_summary(OLD))
    assert all("ceiling share not measured" in cell for claim, row in rows.items()
               if claim.startswith(("2 mm/3 deg: long", "2 mm/3 deg: next", "4 mm", "both tolerances: MLP"))
               and "live" not in claim for cell in row[1:3])
    text = report_text(OLD)
    assert "of ceiling, k " not in render_summary(OLD)  # our predictors: rows only once measured
    assert "(this run's stage 04 wrote no ceiling)" in text and "04_ceiling.png)" not in text
    assert "![why each envelope ends, per world and tolerance](../figures/02_envelope_causes.png)" in text
    assert "![SPL vs R_i" in report_text(FIXTURES["issue 38"])  # on stage 04's page once it draws it


def test_the_rule_word_for_word():
    """Each verdict word of the rule, at its bounds: the interval of our gain, not its point value, decides."""
    cases = ([0.1, 2.0], [1e-9, 0.5], [0.0, 2.0], [-1.0, 2.0], [None, 2.0], [-2.0, -0.1], [-2.0, 0.0], [None, None],
             None, [1.0])
    assert [interval_grade(c) for c in cases] == [0, 0, 1, 1, 1, 2, 1, 2, 1, 1]
    for word in ("*reproduced*", "*undecided*", "*not reproduced*", "*not applicable*", "weakest world", "interval"):
        assert word in RULE


def test_a_planted_table_whose_verdict_the_interval_flips():
    """The same point values, two intervals: a gain whose interval clears zero is reproduced, the same gain whose
    interval holds zero is undecided; the point value never decides."""
    metrics = copy.deepcopy(COMMITTED)
    for stage in ("predictors", "validation"):
        entry = metrics[stage]["long_range"]["2mm_3deg"]
        entry["max_mean_spl_zero_incursion"], entry["gain"] = 20.0, 7.0
        entry["interval"] = dict(entry.get("interval", {}), gain=[0.4, 9.0])
    row = next(cells for claim, cells in table(render_summary(metrics)).items()
               if claim.startswith("2 mm/3 deg: long range over static"))
    assert row[-2] == "reproduced"
    metrics["validation"]["long_range"]["2mm_3deg"]["interval"]["gain"] = [-0.4, 9.0]  # one world's interval holds zero
    row = next(cells for claim, cells in table(render_summary(metrics)).items()
               if claim.startswith("2 mm/3 deg: long range over static"))
    assert row[-2] == "undecided"
    metrics["validation"]["long_range"]["2mm_3deg"]["interval"]["gain"] = [-3.0, -0.5]  # below zero
    row = next(cells for claim, cells in table(render_summary(metrics)).items()
               if claim.startswith("2 mm/3 deg: long range over static"))
    assert row[-2] == "not reproduced"


def test_nothing_run_is_not_run_and_no_world_is_not_applicable():
    rows = table(render_summary({}))
    assert rows and all(row[-2] == "not applicable" for row in rows.values())
    assert rows[next(c for c in rows if "long range over static" in c)][1] == "not run"
    no_lines = table(render_summary({"predictors": {"straight_line": {"tolerance": "2mm_3deg"}}}))  # no lines
    assert no_lines[next(c for c in no_lines if "straight lines" in c)][-2] == "not applicable"


@pytest.mark.parametrize("metrics", [COMMITTED, FIXTURES["issue 38"], RECORDED],
                         ids=["rendered", "issue 38", "recorded"])
def test_the_summary_is_200_lines_its_first_section_40(metrics):
    summary = render_summary(metrics)
    assert len(summary.splitlines()) <= 200
    lines = section(summary)
    assert len(lines) <= 40
    assert summary.index(f"## {TITLE}") < summary.find("## Your recorded data") or "Your recorded" not in summary
    header = next(line for line in lines if line.startswith("| claim"))
    worlds = [cell for cell in header.split(" | ") if cell.startswith("ours: ")]
    expected = ["ours: lab_a", "ours: lab_b"] if metrics is RECORDED else ["ours: main", "ours: validation"]
    assert worlds == expected
    assert sum(line.startswith("- **") for line in lines) == 5  # the glossary
    assert not re.search(r"[Ii]ssues? \d", report_text(metrics))  # no issue numbers for the reader


def test_the_headline_file_holds_the_headline_of_each_world():
    """headline.json (what DVC shows): per world and tolerance the paper's four predictors and their ceiling shares
    with their intervals, issue 38's shares under ``ours``, R11 and the tracking success rates; at most ~120 values;
    the committed one is stage 07's from the committed metrics."""
    full = headline_metrics(FIXTURES["issue 38"])
    assert list(full) == ["main", "validation", "tracking"]
    main = full["main"]["2mm_3deg"]
    assert main["long_range"] == COMMITTED["predictors"]["long_range"]["2mm_3deg"]["max_mean_spl_zero_incursion"]
    assert main["long_range_ceiling_share"] == FIXTURES["issue 38"]["predictors"]["long_range"]["2mm_3deg"][
        "ceiling_share"] and "static_ceiling_share" not in main
    assert full["validation"]["ours"]["4mm_10deg"]["error_combined_ceiling_share"] == pytest.approx(
        0.55 + 0.01 * OURS.index("error_combined") - 0.1)  # ours: the shares alone (their SPLs stay detailed)
    assert "error_combined" not in full["validation"]["ours"]["4mm_10deg"]
    shares = headline_metrics(COMMITTED)["main"]["2mm_3deg"]
    assert [shares["long_range_ceiling_share_low"], shares["long_range_ceiling_share_high"]] == COMMITTED[
        "predictors"]["long_range"]["2mm_3deg"]["interval"]["ceiling_share"]  # each share's interval: two values
    assert full["validation"]["r11_p99_E_t_mm"] == COMMITTED["artifacts"]["worlds"]["validation"]["realism"][
        "truth_accuracy"]["p99_E_t_truth_mm"]
    assert full["tracking"]["a_markers3"] == COMMITTED["tracking"]["success_rates"]["a_markers3"]

    def count(block):
        return sum(count(v) if isinstance(v, dict) else 1 for v in block.values())

    assert 24 <= count(full) <= count(headline_metrics(COMMITTED)) <= 120  # what `dvc metrics diff` can show
    committed = json.loads((ROOT / "reports" / "metrics" / HEADLINE_FILE).read_text())
    assert committed == json.loads(json.dumps(headline_metrics(COMMITTED)))
    recorded = headline_metrics(RECORDED)
    assert recorded == {"lab_a": {"2mm_3deg": {"static": 20.5, "long_range": 25.0}}}  # what the metrics hold, no more


@pytest.mark.parametrize("metrics", [COMMITTED, RECORDED], ids=["rendered", "recorded"])
def test_every_link_of_the_summary_leads_to_a_page_and_a_heading_on_it(metrics):
    """GitHub's heading links: lower case, punctuation dropped, spaces as hyphens; every page the summary links is one
    stage 07 writes, every figure one the stages draw."""
    summary, pages = render_summary(metrics), render_pages(metrics)
    for target in re.findall(r"\]\(([^)#]*)(#[^)]+)?\)", summary):
        path, heading = target
        if path.startswith("figures/"):
            assert (ROOT / "reports" / path).exists(), path
            continue
        text = summary if path == "" else pages.get(path)
        assert text is not None or path in ("timing.md",), path
        if heading and text is not None:
            headings = {"#" + re.sub(r"[^\w\- ]", "", line.lstrip("#").strip().lower()).replace(" ", "-")
                        for line in text.splitlines() if line.startswith("#")}
            assert heading in headings, (path, heading)
    links = set(re.findall(r"\]\((stages/[^)#]+)", "\n".join(section(summary))))
    assert len(links) >= 5  # the claims' caveats lead to the stage pages


def test_the_population_has_a_line_per_predictor_beyond_the_papers():
    """population.json in the summary's section beyond the papers: per predictor and tolerance the median share with its 10-90 %
    range at its own and at the others' point, the zero-incursion share of worlds, and the paired wins against long
    range (a pair written the other way, "long_range vs mlp", read as the MLP's losses)."""
    across = {t: {p: {"own": {"median_share": 0.3 + i / 100, "share_10_90": [0.1, 0.5]},
                      "others": {"median_share": 0.2, "share_10_90": [None, 0.4], "zero_incursion_worlds": 0.75}}
                  for i, p in enumerate(("long_range", "next_step", "mlp", "error_next_step"))} for t in TOLERANCES}
    pairs = {t: {"next_step vs long_range": {"wins": 9, "losses": 3, "ties": 0, "sign_test_p": 0.146},
                 "error_next_step vs long_range": {"wins": 11, "losses": 1, "ties": 0, "sign_test_p": 0.0063},
                 "long_range vs mlp": {"wins": 10, "losses": 2, "ties": 0, "sign_test_p": 0.039}} for t in TOLERANCES}
    metrics = copy.deepcopy(COMMITTED) | {"population": {"n_worlds": 12, "across": across, "paired": {"own": pairs}}}
    lines = section(render_summary(metrics), BEYOND)
    lines = lines[next(i for i, line in enumerate(lines) if line.startswith("**On a population")):]
    assert any(line.startswith("**On a population of 12 rendered worlds**") for line in lines)
    rows = {line.split(" | ")[0].strip("| "): line.strip("|").split(" | ")[1:] for line in lines
            if line.startswith("| ") and "own point" not in line and "---" not in line}
    assert_shows(rows["MLP"][2], [2, 10, 0.039], "MLP against long range")  # 2 won, 10 lost
    assert_shows(rows["error next step"][2], [11, 1, 0.0063], "error next step")
    assert_shows(rows["next step"][0], [0.31, 0.1, 0.5], "next step, own point")
    assert_shows(rows["next step"][1], [0.2, 0.4, 0.75], "next step, others' point")  # the low end: none
    assert "long range" in rows and "error long range" not in rows  # a line per predictor the population holds
    unrun = {stage: entry for stage, entry in COMMITTED.items() if stage != "population"}
    assert "**On a population" not in render_summary(unrun)  # not run: no lines


def test_our_predictors_beyond_the_papers_show_the_metrics_values():
    """The section on our own predictors: per world and tolerance the share of the ceiling with its interval and k
    (error predictors), or the share at the population's h with its interval and R_i (hazard predictors)."""
    m = COMMITTED
    lines = section(render_summary(m), BEYOND)
    rows = {line.strip("|").split(" | ")[0].strip(): [c.strip() for c in line.strip("|").split(" | ")[1:]]
            for line in lines[:next(i for i, line in enumerate(lines) if line.startswith("**On a population"))]
            if line.startswith("| ") and "---" not in line and not line.startswith("| predictor")}
    for predictor in OURS:
        for (stage, _), cell in zip(WORLDS, rows[OURS_NAMES.get(predictor, predictor.replace("_", " "))]):
            entries = [get(m, stage, f"{predictor}.{t}") for t in TOLERANCES]
            assert_shows(cell, [x for e in entries for x in (e["ceiling_share"], *ends(e, "ceiling_share"), e["best_k"])],
                         f"{predictor} on {stage}")
    hazard = m["predictors"]["hazard"]["worlds"]
    for predictor in ("hazard_next_step", "hazard_long_range"):
        for world, cell in zip(("main", "validation"), rows[predictor.replace("_", " ")]):
            entries = [hazard[world][t][predictor] for t in TOLERANCES]
            assert_shows(cell, [x for e in entries if "share" in e
                                for x in (e["share"], *e["share_interval"], e["incursion_rate"])], predictor)
