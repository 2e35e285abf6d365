"""Where the hazard stops the robot (prediction/hazard/stopping.py), on hazards whose answers are known by hand."""

from __future__ import annotations

import numpy as np

from poseintegrity.prediction.hazard.stopping import stop_on_failure_probability, stop_on_next_hazard


def test_the_stopping_rules_stop_where_the_hazard_first_reaches_h():
    theta = np.arange(6) * 2.0
    hazard_next = np.array([0.9, 0.9, 0.1, 0.3, 0.2, np.nan])  # 3 stops sampled: read from the last of them on
    found = stop_on_next_hazard(theta, hazard_next, 3, np.array([0.05, 0.25, 0.5]))
    assert list(found.theta_p) == [4.0, 6.0, 10.0] and list(found.status) == ["stopped", "stopped", "end_of_path"]
    ahead = np.array([0.0, 0.0, 0.1, 0.2, 0.5])  # stops 1-5: failed by 0, 0, 0.1, 0.28, 0.64
    found = stop_on_failure_probability(theta, ahead, 3, np.array([0.05, 0.2, 0.5, 0.9]))
    assert list(found.theta_p) == [4.0, 6.0, 8.0, 10.0] and list(found.status) == ["root"] * 3 + ["censored"]
    early = stop_on_failure_probability(theta, np.array([0.6, 0.0, 0.0, 0.0, 0.0]), 3, np.array([0.5]))
    assert early.theta_p[0] == 0.0  # as the paper's long range, the end may lie among the sampled stops
    assert np.isnan(stop_on_next_hazard(theta[:2], hazard_next[:2], 3, np.array([0.1])).theta_p).all()
