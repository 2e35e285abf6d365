"""The summary's first section (report/claims.py): one screen before any stage table, every number in it the metrics
files' value, every verdict the one its stated rule gives. The expected values and verdicts are written here from the
metrics by hand (plain dict access and the rule as the section states it), not through the report's code."""

import copy
import json
import re

import pytest

from poseintegrity import paper_results as paper
from poseintegrity.report.claims import RULE, TITLE, interval_grade
from poseintegrity.report.headline_file import HEADLINE_FILE, headline_metrics
from poseintegrity.report.summary import read_metrics, render_summary
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


def section(summary: str) -> list[str]:
    """The first section's lines, from its heading to the next heading."""
    start = summary.index(f"## {TITLE}")
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
    """claim -> (the values each world's cell shows, the values its why shows, its verdict), from the metrics."""
    spl = paper.WINDSOR_SPL_ZERO_INCURSION
    out = {}

    def share(stage, predictor, t):
        return m[stage][predictor][t].get("ceiling_share")

    def weakest(grades):
        return max(range(len(grades)), key=lambda i: (grades[i], -i))

    ceiling = [[x for t in TOLERANCES for x in (get(m, s, f"ceiling.{t}.gain"), get(m, s, f"ceiling.{t}.n_arcs"))]
               if "ceiling" in m[s] else [] for s, _ in WORLDS]
    r6r7 = [get(m, "artifacts", f"{p}realism.{k}") for _, p in WORLDS
            for k in ("min_theta_a_2mm3deg", "arc_theta_a_mean_over_min_2mm3deg")]
    out["ceiling"] = (ceiling, r6r7, "-")
    for predictor, name in (("long_range", "long range"), ("next_step", "next step")):
        for t in TOLERANCES:
            entries = [get(m, s, f"{predictor}.{t}") for s, _ in WORLDS]
            statics = [get(m, s, f"static.{t}.max_mean_spl_zero_incursion") for s, _ in WORLDS]
            cells = [[e["max_mean_spl_zero_incursion"], st, e.get("gain"), *ends(e, "gain"), e.get("relative_gain"),
                      e["best_n_t"], share(s, predictor, t), *ends(e, "ceiling_share")]
                     for e, st, (s, _) in zip(entries, statics, WORLDS)]
            grades = [2 if e["max_mean_spl_zero_incursion"] is None else grade(e.get("interval", {}).get("gain"))
                      for e in entries]
            w = weakest(grades)
            arcs, static_arcs = entries[w]["decided_by"], get(m, WORLDS[w][0], f"static.{t}.decided_by")
            cause = next(c for c in get(m, "artifacts", f"{WORLDS[w][1]}envelope_causes")
                         if c["dataset"] == arcs[0] and c["tolerance"] == t)
            out[f"{name} over static, {paper.TOLERANCE_LABELS[t]}"] = (
                cells, [len(arcs), get(m, WORLDS[w][0], f"ceiling.{t}.n_arcs") if "ceiling" in m[WORLDS[w][0]] else None,
                        entries[w]["best_n_t"], cause["theta_a"], len(static_arcs)], verdict(grades))
    pair = "long_range vs mlp"
    pairs = [[get(m, s, "intervals")[t]["pairs"][pair] if "intervals" in m[s] else {} for t in TOLERANCES]
             for s, _ in WORLDS]
    grades = [max(grade(p.get("difference")) for p in world) for world in pairs]
    w = weakest(grades)
    out["MLP"] = ([[get(m, s, f"mlp.{t}.max_mean_spl_zero_incursion") for t in TOLERANCES]
                   + [x for t in TOLERANCES for x in (share(s, "mlp", t), *ends(get(m, s, f"mlp.{t}"), "ceiling_share"))]
                   + [get(m, s, "long_range.relative_improvement_vs_mlp")]
                   + [x for p in world for x in (p.get("point"), *p.get("difference", []))]
                   for (s, _), world in zip(WORLDS, pairs)],
                  [get(m, WORLDS[w][0], "fit_status.mlp.non_physical")]
                  + [x for t in TOLERANCES for x in (*(len(get(m, WORLDS[w][0], f"{p}.{t}.decided_by"))
                                                       for p in ("long_range", "mlp")),
                                                     get(m, WORLDS[w][0], f"ceiling.{t}.n_arcs")
                                                     if "ceiling" in m[WORLDS[w][0]] else None)], verdict(grades))
    for predictor in OURS:
        if predictor in m["predictors"]:
            out[f"ours: {OURS_NAMES.get(predictor, predictor.replace('_', ' '))}"] = (
                [[x for t in TOLERANCES for x in (get(m, s, f"{predictor}.{t}.max_mean_spl_zero_incursion"),
                                                   get(m, s, f"{predictor}.{t}.best_k"), share(s, predictor, t),
                                                   *ends(get(m, s, f"{predictor}.{t}"), "ceiling_share"))]
                 for s, _ in WORLDS], [], "-")
    hazard = m["predictors"].get("hazard", {})
    for predictor in ("hazard_next_step", "hazard_long_range") if hazard.get("trained_on_arcs") else ():
        cells = []
        for world in ("main", "validation"):
            entries = [hazard["worlds"][world][t][predictor] for t in TOLERANCES]
            cells.append([x for e in entries if "share" in e
                          for x in (e["share"], *(e["share_interval"]), e["incursion_rate"])])
        out[f"ours: {predictor.replace('_', ' ')}"] = (cells, [], "-")
    lines = [get(m, s, "straight_line") for s, _ in WORLDS]
    grades = [2 if line["long_range_max_mean_spl_zero_incursion"] is None else grade(line.get("interval", {}).get("gain"))
              for line in lines]
    r8 = f"{WORLDS[weakest(grades)][1]}realism.line_x_a_mean_over_min_2mm3deg"
    out["straight lines"] = ([[line["relative_improvement"], line["long_range_max_mean_spl_zero_incursion"],
                               line["static_max_mean_spl_zero_incursion"], *ends(line, "gain")] for line in lines],
                             [lines[weakest(grades)].get("n_lines"), get(m, "artifacts", r8)], verdict(grades))
    variants = ("epnp", "p3p", "ap3p")
    pnp = [[get(m, s, f"pnp.{v}") for v in variants] for s, _ in WORLDS]
    grades = [max(2 if e["max_mean_spl_zero_incursion"] is None else grade(e.get("interval", {}).get("gain"))
                  for e in entries) for entries in pnp]
    out["PnP variants"] = ([[x for e in entries
                             for x in (e["max_mean_spl_zero_incursion"], e["static_max_mean_spl_zero_incursion"],
                                       *ends(e, "gain"))]
                            for entries in pnp],
                           [get(m, "pnp", f"{WORLDS[weakest(grades)][1]}methods.{v}.failure_rate")
                            for v in ("usac_magsac", *variants)], verdict(grades))
    live = m["predictors"]["live"]  # the main world's only: validation.json has none
    grades = [2 if live["incursions"] else grade(live.get("interval", {}).get("envelope_share_gain"))]
    out["live trials"] = ([[live["n_t"], live["incursions"], live["n_trials"], live["envelope_share"],
                            live["static_envelope_share"], *ends(live, "envelope_share_gain")], []],
                          [m["predictors"]["next_step"][live["tolerance"]]["best_n_t"],
                           len(m["predictors"]["static"][live["tolerance"]]["decided_by"]),
                           m["predictors"]["ceiling"][live["tolerance"]]["n_arcs"] if "ceiling" in m["predictors"]
                           else None], verdict(grades))
    rates, black = m["tracking"]["success_rates"], paper.BLACK_RESULTS
    intervals = m["tracking"].get("intervals", {})
    for n in (4, 3):
        interval = intervals.get("success_rates", {}).get(f"a_markers{n}")
        out[f"correct pose, {n} markers"] = ([[rates[f"a_markers{n}"], *(interval or [])], []], [rates[f"b_markers{n}"]],
                                             verdict([level(interval, black["success_rate"][f"markers{n}"], True)]))
    mm, deg = m["tracking"]["rms_axis_mm"], m["tracking"]["rms_euler_deg"]
    mm_interval = intervals.get("rms_axis_mm", {}).get("ukf")
    deg_interval = intervals.get("rms_euler_deg", {}).get("ukf")
    out["accuracy"] = ([[mm["ukf"], *(mm_interval or []), deg["ukf"], *(deg_interval or [])], []],
                       [mm["no_filter"], deg["no_filter"]],
                       verdict([max(level(mm_interval, black["rms_mm"]["ukf"], False),
                                    level(deg_interval, black["rms_deg"]["ukf"], False))]))
    return out


@pytest.mark.parametrize("fixture", FIXTURES)
def test_every_number_of_the_first_section_is_the_metrics_value_and_every_verdict_follows_the_rule(fixture):
    metrics = FIXTURES[fixture]
    rows = table(render_summary(metrics))
    expected = expectations(metrics)
    assert len(rows) == len(expected)  # a row per claim, and issue 38's where the metrics hold them
    for claim, (cells, why, word) in expected.items():
        found = [row for label, row in rows.items() if label.startswith(claim)]
        assert len(found) == 1, f"{claim}: {list(rows)}"
        paper_cell, *ours, shown_verdict, shown_why = found[0]
        assert shown_verdict == word, f"{claim}: {shown_verdict}, by the rule {word}"
        for world, (cell, values) in enumerate(zip(ours, cells)):
            assert_shows(cell, values, f"{claim}, world {world}")
        assert_shows(shown_why, why, f"{claim}, why")
        assert "](#" in shown_why  # it links to the section below that shows it


def test_a_run_without_the_ceiling_says_so():
    rows = table(render_summary(OLD))
    assert rows[next(c for c in rows if c.startswith("ceiling"))][1:3] == ["not measured", "not measured"]
    assert all("ceiling share not measured" in cell for claim, row in rows.items()
               if claim.startswith(("long range over", "next step over", "MLP")) for cell in row[1:3])
    assert not any(claim.startswith("ours") for claim in rows)  # issue 38's predictors: rows only once measured
    text = render_summary(OLD)
    assert "(this run's stage 04 wrote no ceiling)" in text and "figures/04_ceiling.png)" not in text
    assert "![why each envelope ends, per world and tolerance](figures/02_envelope_causes.png)" in text
    assert "![SPL vs R_i" in render_summary(FIXTURES["issue 38"])  # inline once stage 04 draws it


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
               if claim.startswith("long range over static, 2 mm/3 deg"))
    assert row[-2] == "reproduced"
    metrics["validation"]["long_range"]["2mm_3deg"]["interval"]["gain"] = [-0.4, 9.0]  # one world's interval holds zero
    row = next(cells for claim, cells in table(render_summary(metrics)).items()
               if claim.startswith("long range over static, 2 mm/3 deg"))
    assert row[-2] == "undecided"
    metrics["validation"]["long_range"]["2mm_3deg"]["interval"]["gain"] = [-3.0, -0.5]  # below zero
    row = next(cells for claim, cells in table(render_summary(metrics)).items()
               if claim.startswith("long range over static, 2 mm/3 deg"))
    assert row[-2] == "not reproduced"


def test_nothing_run_is_not_run_and_no_world_is_not_applicable():
    rows = table(render_summary({}))
    assert rows and all(row[-2] in ("not applicable", "-") for row in rows.values())
    assert rows[next(c for c in rows if c.startswith("long range over"))][1] == "not run"
    no_lines = table(render_summary({"predictors": {"straight_line": {"tolerance": "2mm_3deg"}}}))  # no lines
    assert no_lines[next(c for c in no_lines if c.startswith("straight"))][-2] == "not applicable"


@pytest.mark.parametrize("metrics", [COMMITTED, FIXTURES["issue 38"], RECORDED],
                         ids=["rendered", "issue 38", "recorded"])
def test_the_first_section_is_one_screen_before_any_stage_table(metrics):
    summary = render_summary(metrics)
    lines = section(summary)
    assert len(lines) <= 40
    first_table = summary.index("| figure | ours | paper | target |")
    assert summary.index(f"## {TITLE}") < first_table
    assert summary.index(f"## {TITLE}") < summary.find("## Your recorded data") or "Your recorded" not in summary
    header = next(line for line in lines if line.startswith("| claim"))
    worlds = [cell for cell in header.split(" | ") if cell.startswith("ours: ")]
    expected = ["ours: lab_a", "ours: lab_b"] if metrics is RECORDED else ["ours: main", "ours: validation"]
    assert worlds == expected


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
def test_every_link_of_the_first_section_leads_to_a_heading_below_it(metrics):
    """GitHub's heading links: lower case, punctuation dropped, spaces as hyphens."""
    summary = render_summary(metrics)
    headings = {"#" + re.sub(r"[^\w\- ]", "", line.lstrip("#").strip().lower()).replace(" ", "-")
                for line in summary.splitlines() if line.startswith("## ")}
    links = set(re.findall(r"\]\((#[^)]+)\)", "\n".join(section(summary))))
    assert {"#the-rendered-worlds-realism" if metrics is COMMITTED else "#your-datasets-described",
            "#envelopes-and-why-they-end", "#predictors", "#pnp-variants", "#tracking", "#fits"} == links
    assert links <= headings


def test_the_population_has_a_line_per_predictor_on_the_first_screen():
    """population.json (issue 49) on the first screen: per predictor and tolerance the median share with its 10-90 %
    range at its own and at the others' point, the zero-incursion share of worlds, and the paired wins against long
    range (a pair written the other way, "long_range vs mlp", read as the MLP's losses)."""
    across = {t: {p: {"own": {"median_share": 0.3 + i / 100, "share_10_90": [0.1, 0.5]},
                      "others": {"median_share": 0.2, "share_10_90": [None, 0.4], "zero_incursion_worlds": 0.75}}
                  for i, p in enumerate(("long_range", "next_step", "mlp", "error_next_step"))} for t in TOLERANCES}
    pairs = {t: {"next_step vs long_range": {"wins": 9, "losses": 3, "ties": 0, "sign_test_p": 0.146},
                 "error_next_step vs long_range": {"wins": 11, "losses": 1, "ties": 0, "sign_test_p": 0.0063},
                 "long_range vs mlp": {"wins": 10, "losses": 2, "ties": 0, "sign_test_p": 0.039}} for t in TOLERANCES}
    metrics = copy.deepcopy(COMMITTED) | {"population": {"n_worlds": 12, "across": across, "paired": {"own": pairs}}}
    lines = section(render_summary(metrics))
    assert any(line.startswith("**On a population of 12 rendered worlds**") for line in lines)
    rows = {line.split(" | ")[0].strip("| "): line.strip("|").split(" | ")[1:] for line in lines
            if line.startswith("| ") and "own point" not in line and "---" not in line}
    assert_shows(rows["MLP"][2], [2, 10, 0.039], "MLP against long range")  # 2 won, 10 lost
    assert_shows(rows["error next step"][2], [11, 1, 0.0063], "error next step")
    assert_shows(rows["next step"][0], [0.31, 0.1, 0.5], "next step, own point")
    assert_shows(rows["next step"][1], [0.2, 0.4, 0.75], "next step, others' point")  # the low end: none
    assert "long range" in rows and "error long range" not in rows  # a line per predictor the population holds
    assert len(lines) <= 40
    unrun = {stage: entry for stage, entry in COMMITTED.items() if stage != "population"}
    assert not any("population" in line for line in section(render_summary(unrun)))  # not run: no lines
