"""``reports/metrics/headline.json`` (report/headline_file.py): the few numbers DVC shows, from the detailed
metrics."""

import json

import pytest

from poseintegrity.report.headline_file import HEADLINE_FILE, headline_metrics
from report.metrics_fixtures import COMMITTED, FIXTURES, OURS, RECORDED
from repository import ROOT


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
