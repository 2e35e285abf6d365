"""The summary's first section (report/claims.py): one screen before any stage table, every number in it the metrics
files' value, every verdict the one its stated rule gives. The expected values and verdicts are written here from the
metrics by hand (plain dict access and the rule as the section states it), not through the report's code."""

import copy

import pytest

from poseintegrity import paper_results as paper
from poseintegrity.report.claims import RULE, interval_grade
from poseintegrity.report.summary import render_summary
from report.metrics_fixtures import COMMITTED, FIXTURES, OLD, TOLERANCES, WORLDS
from report.report_text import report_text
from report.summary_reading import assert_shows, ends, get, section, table


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
