"""The summary's section beyond the papers (report/beyond_papers.py, report/population_table.py): our own
predictors per world and tolerance, and the population of rendered worlds; every number the metrics' value."""

import copy

from poseintegrity.report.beyond_papers import TITLE as BEYOND
from poseintegrity.report.summary import render_summary
from report.metrics_fixtures import COMMITTED, OURS, TOLERANCES, WORLDS
from report.summary_reading import assert_shows, ends, get, section

OURS_NAMES = {"error_next_step_observed": "observed error next step"}  # no claim's name begins another's


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
