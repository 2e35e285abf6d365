"""The discrete-time hazard's rows (prediction/hazard/risk_sets.py): which stops were at risk, which failed."""

from __future__ import annotations

import pandas as pd

from poseintegrity.prediction.hazard.risk_sets import LONG_RANGE, long_range_rows, next_step_rows
from poseintegrity.prediction.hazard.stop_evidence import stop_evidence, with_trends
from prediction.hazard.hazard_synthetic import THETA, arc_frames


def test_the_risk_set_ends_at_the_failing_stop_and_a_censored_arc_never_fails():
    evidence = with_trends(stop_evidence(arc_frames("w", "a", [100] * 8), "usac_magsac", (2.0, 3.0)))
    envelopes = pd.DataFrame({"world": ["w"], "dataset": ["a"], "theta_a": [10.0], "censored": [False]})
    rows = next_step_rows(evidence, envelopes, n_sampled_stops=4)
    # stops 3 (6.75 deg) and 4 (9.0 deg) are at risk (theta_a > theta_i); stop 5 (11.25) is the first past theta_a
    assert list(rows["stop"]) == [3, 4] and list(rows["failed"]) == [0, 1]
    ahead = long_range_rows(evidence, envelopes, n_sampled_stops=4)  # from stop 1 on, the sampled stops among them
    assert list(ahead["theta_deg"]) == list(THETA[1:6]) and list(ahead["failed"]) == [0, 0, 0, 0, 1]
    assert (ahead["ahead_deg"] == ahead["theta_deg"] - THETA[3]).all() and list(ahead.columns[:len(LONG_RANGE)]) \
        == list(LONG_RANGE)
    censored = envelopes.assign(theta_a=THETA[-1], censored=True)
    assert next_step_rows(evidence, censored, n_sampled_stops=4)["failed"].sum() == 0
    assert long_range_rows(evidence, censored, n_sampled_stops=4)["failed"].sum() == 0
