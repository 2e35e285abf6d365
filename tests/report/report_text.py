"""The whole report a run writes: the summary and every stage's page, as one text to search."""

from poseintegrity.report.stage_pages import render_pages
from poseintegrity.report.summary import render_summary


def report_text(metrics: dict) -> str:
    """``reports/summary.md`` then each ``reports/stages/<stage>.md`` of ``metrics``."""
    return "\n".join([render_summary(metrics), *render_pages(metrics).values()])
