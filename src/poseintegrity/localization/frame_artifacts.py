"""Pose estimation artifacts per frame (Windsor et al. III-C): the columns of ``artifacts.parquet``.

Artifacts of one PnP-RANSAC run (columns of ``artifacts.parquet``):

- ``n_inliers``: n_i, inliers of the returned pose (recounted, see :mod:`pnp`); 0 on failure
- ``n_inliers_reported``: OpenCV's own inlier count
- ``n_keypoints``, ``n_matches``: SIFT keypoints in the frame, ratio-test matches to M_t
- ``inlier_ratio``: n_i / n_matches (0 without matches)
- ``reproj_error_px``: mean reprojection error of the inliers
- ``inlier_spread_px``: RMS distance of the inlier keypoints from their centroid (image-space spread)
- ``inlier_hull_area_px2``: area of the convex hull of the inlier keypoints (coverage; Windsor et al. [4]
  studied keypoint distribution artifacts)
- ``model_coverage``: n_i / |M_t|, the fraction of the target model seen
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np
from poseintegrity.localization.pnp import PnPResult, reprojection_errors

ARTIFACT_COLUMNS = [
    "n_inliers", "n_inliers_reported", "n_keypoints", "n_matches", "inlier_ratio", "reproj_error_px",
    "inlier_spread_px", "inlier_hull_area_px2", "model_coverage",
]


def frame_artifacts(
    result: PnPResult, object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, n_keypoints: int, model_size: int
) -> dict[str, Any]:
    """Artifact values of one PnP result.

    object_points : (n, 3) mm and image_points : (n, 2) px are the n ratio-test matches given to PnP.
    A failed result has n_i = 0 and NaN for the inlier geometry.
    """
    n_matches = len(image_points)
    row = dict(
        n_inliers=result.n_inliers, n_inliers_reported=result.n_inliers_reported, n_keypoints=n_keypoints,
        n_matches=n_matches, inlier_ratio=result.n_inliers / n_matches if n_matches else 0.0,
        reproj_error_px=np.nan, inlier_spread_px=np.nan, inlier_hull_area_px2=np.nan,
        model_coverage=result.n_inliers / model_size if model_size else 0.0,
    )
    if result.status != "ok":
        return row
    x = image_points[result.inliers].astype(np.float64)
    errors = reprojection_errors(object_points[result.inliers], x, K, result.T_cam_model)
    row["reproj_error_px"] = float(errors.mean())
    row["inlier_spread_px"] = float(np.sqrt(np.mean(np.sum((x - x.mean(axis=0)) ** 2, axis=1))))
    row["inlier_hull_area_px2"] = float(cv2.contourArea(cv2.convexHull(x.astype(np.float32))))
    return row
