"""Every target of the report judged (report/targets.py): the bars read off their text, the realism bars by the stage
that measured them, so that the rows and the count of bars passed agree."""

import re

import pytest

from poseintegrity.report.headlines import HEADLINES
from poseintegrity.report.stage_pages import render_pages
from poseintegrity.report.summary import render_summary
from poseintegrity.report.targets import UnjudgeableTarget, bar_holds, judgeable
from report.metrics_fixtures import COMMITTED


@pytest.mark.parametrize("target, value, holds", [
    ("<= 3", 2.9, True), ("<= 3", 3.1, False), (">= 0.8", 0.696, False), ("< 1", 1.0, False), ("> 1", 1.5, True),
    (">= 90 %", 0.83, False), (">= 90 %", 0.95, True), ("<= 50 %", 0.05, True),  # a share against a bar in percent
    ("10-35", 6.344, False), ("10-35", 10.0, True), ("0.3-1.5", 0.1833, False), ("0", 0.0, True), ("0", 1.0, False),
    ("<= 0.5 (generate.calibration.max_rms_px)", 0.066, True),
])
def test_a_bar_read_off_its_text(target, value, holds):
    assert bar_holds(target, value) is holds


@pytest.mark.parametrize("target", ["> the arcs' (R5's row)", "0, and the smallest theta_a <= 12 deg", "fast"])
def test_a_bar_that_is_no_comparison_is_refused(target):
    with pytest.raises(UnjudgeableTarget, match="judged_by"):
        bar_holds(target, 1.0)


def test_every_target_is_judged():
    """No row carries a target nobody judges: its text is a comparison, or it names its stage's judgement."""
    assert [h.label for h in HEADLINES if not judgeable(h.target, h.judged_by)] == []


def test_every_realism_bar_has_its_row_and_the_rows_agree_with_the_count():
    """Each bar of artifacts.json realism.passed is the judgement of some row, and the rows judged fail on the page
    are the bars the stage failed: the reader can match "N of 16" to the rows."""
    passed = COMMITTED["artifacts"]["realism"]["passed"]
    judged_by = {h.judged_by.rsplit(".", 1)[1] for h in HEADLINES if h.judged_by and h.judged_by.startswith("realism.")}
    assert set(passed) - {"r11_truth_accuracy"} <= judged_by  # R11: its own rows, each read off its text
    page = render_pages(COMMITTED)["stages/01_generate_datasets.md"]
    failing_rows = {h.judged_by.rsplit(".", 1)[1] for h in HEADLINES
                    if h.judged_by and h.judged_by.startswith("realism.") and f"| {h.label} |" in page
                    and re.search(re.escape(f"| {h.label} |") + r"[^\n]*: fail", page)}
    assert failing_rows == {bar for bar, ok in passed.items() if not ok}
    assert "Bars failed on the main world: " in page and f"({len(failing_rows)} of {len(passed)})" in page


def test_the_summary_counts_the_targets_the_pages_judge():
    summary, pages = render_summary(COMMITTED), "\n".join(render_pages(COMMITTED).values())
    n, passing, failing = map(int, re.search(r"Of (\d+) targets on the stage pages, (\d+) pass, (\d+) fail",
                                             summary).groups())
    rows = [line for line in pages.splitlines() if line.startswith("| ") and line.split(" | ")[-1].strip(" |") != "-"
            and "---" not in line and not line.startswith("| figure |")]
    judged = [line for line in rows if re.search(r": (pass|fail)\b", line.split(" | ")[-1])]
    assert n == len(judged) and failing == sum(": fail" in line.split(" | ")[-1] for line in judged)
    assert passing == n - failing
    assert failing == len(re.findall(r"^- \[", summary.split("## Targets", 1)[1].split("\n## ", 1)[0], re.M))
