"""A frame's artifacts (localization/frame_artifacts.py): the inlier geometry of a known square, and a failed PnP
result's zero inliers and NaN geometry."""

import numpy as np
import pytest

from poseintegrity.localization.frame_artifacts import frame_artifacts
from poseintegrity.localization.pnp import PnPResult, failed

K = np.array([[500.0, 0.0, 0.0], [0.0, 500.0, 0.0], [0.0, 0.0, 1.0]])


def test_inlier_geometry_of_a_known_square():
    """Four inliers at the corners of a 100 px square (exact projections) and one outlier."""
    T = np.eye(4)
    T[2, 3] = 500.0
    X = np.array([[0, 0, 0], [100, 0, 0], [100, 100, 0], [0, 100, 0], [50, 50, 0]], dtype=float)
    x = X[:, :2].copy()
    x[4] += 40.0  # the outlier
    result = PnPResult(T, np.arange(4), 4, "ok")
    row = frame_artifacts(result, X, x, K, n_keypoints=10, model_size=8, point_covariances=np.zeros((5, 3, 3)),
                          inlier_threshold_px=0.6)
    assert row["covariance_status"] == "ok"  # exact pixels of exact points: nothing to expect an error from
    assert row["sigma_px"] == pytest.approx(0.0) and row["sigma_t_pred_mm"] == pytest.approx(0.0)
    assert row["n_inliers"] == 4 and row["n_matches"] == 5 and row["inlier_ratio"] == pytest.approx(0.8)
    assert row["reproj_error_px"] == pytest.approx(0.0)
    assert row["inlier_spread_px"] == pytest.approx(np.sqrt(2) * 50)
    assert row["inlier_hull_area_px2"] == pytest.approx(1e4)
    assert row["model_coverage"] == pytest.approx(0.5)


def test_failed_result_has_zero_inliers_and_nan_geometry():
    row = frame_artifacts(failed("no_consensus", "no consensus: none of 100 samples ..."), np.zeros((2, 3)),
                          np.zeros((2, 2)), K, 10, 8, np.zeros((2, 3, 3)), 0.6)
    assert row["n_inliers"] == 0 and row["inlier_ratio"] == 0.0 and np.isnan(row["inlier_spread_px"])
    assert row["covariance_status"] == "no_pose" and np.isnan(row["sigma_t_pred_mm"])
