"""The failure hazard's evidence (prediction/hazard/stop_evidence.py): a stop's images averaged, its trends read
from no later stop."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from poseintegrity.prediction.hazard.stop_evidence import EVIDENCE, stop_evidence
from prediction.hazard.hazard_synthetic import arc_frames


def test_the_evidence_of_a_stop_is_the_mean_of_its_images_and_its_trend_reads_no_later_stop():
    frames = arc_frames("w", "a", [100, 80, 60, 40, 20, 10, 5, 0])
    evidence = stop_evidence(frames, "usac_magsac", (2.0, 3.0))
    assert list(evidence["stop"]) == list(range(8)) and set(EVIDENCE) <= set(evidence.columns)
    assert evidence.loc[0, "log_inliers"] == pytest.approx(np.log1p(100.5))  # counts 100 and 101
    assert evidence.loc[7, "posed_share"] == 0.0 and evidence.loc[7, "log_inliers"] == 0.0
    # the least squares slope of three equally spaced stops is (x_i - x_{i-2}) / 2; a later stop changes nothing
    x = evidence["log_inliers"].to_numpy()
    assert evidence.loc[4, "log_inliers_slope"] == pytest.approx((x[4] - x[2]) / 2)
    assert evidence.loc[4, "log_inliers_acceleration"] == pytest.approx(x[4] - 2 * x[3] + x[2])
    cut = stop_evidence(frames[frames["stop"] <= 4], "usac_magsac", (2.0, 3.0))
    pd.testing.assert_frame_equal(cut, evidence.iloc[:5], check_dtype=False)
    assert evidence["kinematic_error"].isna().all()  # a column stage 02 did not write stays missing (NaN)
