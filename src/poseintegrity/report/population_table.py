"""The population's table (``population.json``, stage 08): each predictor's share of the ceiling over the rendered
worlds, at each world's own operating point and at the point chosen on the other worlds, and the worlds in which it
beats long range."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.names import NAMES
from poseintegrity.report.lookup import MISSING
from poseintegrity.report.reader import SHARE, Reader

POPULATION_ROWS = ("static", "long_range", "next_step", "mlp", "error_long_range", "error_next_step",
                   "error_next_step_observed", "hazard_next_step", "hazard_long_range")
# the table's rows (the hazard's others' point is the h chosen on the training worlds' held-out curves,
# population/hazard.py)


def population_lines(metrics: dict[str, dict], reports: str = "") -> list[str]:
    """The population's lines (``population.json``): per predictor and tolerance, the median share of the
    ceiling over the worlds with its 10-90 % range at the world's own operating point and at the point chosen on the
    other worlds, the share of worlds with zero incursion at that point, and the worlds in which it beats long range
    with the sign test's p. No lines when the population has not run. reports : the path from the page to reports/
    ("" from the summary, "../" from a stage page), for the figure's link."""
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
    return [f"**On a population of {n} rendered worlds** (each the paper's protocol, drawn from params.yaml "
            f"`population`{truth}): the median share of the ceiling over the worlds [its 10-90 % range], at each "
            "world's own operating point and at the point chosen on the other worlds (`population.json` `rule`), "
            "both against the world's own static baseline (static's own share is 0 by definition); the worlds in "
            "which it beats long range at their own points, won-lost (two-sided sign test). "
            f"[Figure]({reports}figures/08_population.png).", "",
            f"| predictor | {head} |", "| --- |" + " --- |" * 3 * len(paper.TOLERANCES)] + [
            f"| {NAMES[p]} | " + " | ".join(cell(p, t) for t in paper.TOLERANCES) + " |"
            for p in POPULATION_ROWS if read.value("population", f"across.{paper.TOLERANCES[0]}.{p}") is not MISSING]
