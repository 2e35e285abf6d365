"""``reports/summary.md`` (report/summary.py): at most 200 lines, its first section 40; every link leads to a page
stage 07 writes and a heading on it, and none outside the repository."""

import re

import pytest

from poseintegrity.report.claims import TITLE
from poseintegrity.report.stage_pages import render_pages
from poseintegrity.report.summary import render_summary
from report.metrics_fixtures import COMMITTED, FIXTURES, RECORDED
from report.report_text import report_text
from report.summary_reading import section
from repository import ROOT, outside_references


def test_the_summary_points_nowhere_outside_the_repository():
    summary = ROOT / "reports" / "summary.md"
    assert "docs/references.md" in render_summary({})
    assert outside_references(render_summary({}), summary.parent) == []


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
