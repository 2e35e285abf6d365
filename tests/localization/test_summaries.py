"""Stage 02's summaries per PnP method (localization/summaries.py) on worlds whose answers are known."""

import pandas as pd
import pytest

from loc_worlds import PROTOCOL, linear, world
from poseintegrity.localization.envelope import envelopes, headline
from poseintegrity.localization.summaries import FAILURE_STATUSES, failure_shares, method_summary


def test_method_summary():
    table = pd.concat([world({"a": linear(2.3)}).assign(method=m) for m in ("epnp", "p3p")], ignore_index=True)
    table.loc[table.method == "p3p", "n_inliers"] += 10
    summary = method_summary(table, headline(envelopes(table, [(2.0, 3.0)], PROTOCOL.envelope), PROTOCOL.envelope)
                             ).set_index("method")
    assert summary.loc["p3p", "mean_n_inliers_first_stop"] == summary.loc["epnp", "mean_n_inliers_first_stop"] + 10
    assert summary.loc["epnp", "n_frames"] == 40
    assert summary.loc["epnp", "failure_rate"] == pytest.approx(0.0)  # n_i = 100 - 2.3 theta > 0 up to 42.75
    assert "mean_theta_a_arc_2mm_3deg" in summary.columns


def test_failure_shares_by_method_and_status():
    """p3p: 4 of its 40 frames fail, 3 without consensus and 1 with too few inliers; epnp: none."""
    table = pd.concat([world({"a": linear(2.3)}).assign(method=m) for m in ("epnp", "p3p")], ignore_index=True)
    p3p = table.index[table.method == "p3p"]
    table.loc[p3p[:3], "status"] = "no_consensus"
    table.loc[p3p[3], "status"] = "too_few_inliers"
    shares = failure_shares(table)
    assert list(shares.columns) == list(FAILURE_STATUSES)  # every status, in a fixed order
    assert shares.loc["p3p", "no_consensus"] == pytest.approx(3 / 40)
    assert shares.loc["p3p", "too_few_inliers"] == pytest.approx(1 / 40)
    assert shares.loc["p3p"].sum() == pytest.approx(4 / 40) and (shares.loc["epnp"] == 0.0).all()
    table.loc[p3p[4], "status"] = "pnp_failed"  # a status of an older table is kept, not dropped
    assert failure_shares(table).loc["p3p", "pnp_failed"] == pytest.approx(1 / 40)
