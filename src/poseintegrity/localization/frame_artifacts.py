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

Beyond the paper, the error the pose is expected to have (issue 38, :mod:`pose_covariance`), propagated to first
order from the inliers' residual and their model points' triangulation covariances, conditioned on the inlier test
of RANSAC's threshold ((c) there):

- ``sigma_px``: the pixel noise the inliers' residual gives, sqrt(RSS / (2 n_i - 6))
- ``sigma_t_pred_mm``, ``sigma_r_pred_deg``: predicted RMS E_t (at the board origin) and E_r
- ``sigma_t_model_mm``, ``sigma_r_model_deg``: the model points' share of them (the rest is the residual's, in
  quadrature)
- ``sigma_t_unconditioned_mm``, ``sigma_r_unconditioned_deg``: the same without the inlier test's conditioning (the
  plain first-order propagation), reported beside it
- ``covariance_status``: "ok", or why there is no prediction ("no_pose", "too_few_points", "degenerate_points")

Evidence about the pose that needs no ground truth (issue 50), beside these in stage 02's rows: ``consensus_*`` and
``stop_spread_*``, :mod:`consensus`.
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np
from poseintegrity.localization.pnp import PnPResult, reprojection_errors
from poseintegrity.localization.pose_covariance import propagated_covariance

ARTIFACT_COLUMNS = [
    "n_inliers", "n_inliers_reported", "n_keypoints", "n_matches", "inlier_ratio", "reproj_error_px",
    "inlier_spread_px", "inlier_hull_area_px2", "model_coverage", "sigma_px", "sigma_t_pred_mm", "sigma_r_pred_deg",
    "sigma_t_model_mm", "sigma_r_model_deg", "sigma_t_unconditioned_mm", "sigma_r_unconditioned_deg",
    "covariance_status",
]


def frame_artifacts(
    result: PnPResult, object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, n_keypoints: int,
    model_size: int, point_covariances: np.ndarray, inlier_threshold_px: float,
) -> dict[str, Any]:
    """Artifact values of one PnP result.

    object_points : (n, 3) mm and image_points : (n, 2) px are the n ratio-test matches given to PnP;
    point_covariances : (n, 3, 3) mm^2 their model points' covariances (M_t's, board frame);
    inlier_threshold_px : RANSAC's threshold, on which the inliers' model errors are conditioned.
    A failed result has n_i = 0 and NaN for the inlier geometry and the predicted error.
    """
    n_matches = len(image_points)
    row = dict(
        n_inliers=result.n_inliers, n_inliers_reported=result.n_inliers_reported, n_keypoints=n_keypoints,
        n_matches=n_matches, inlier_ratio=result.n_inliers / n_matches if n_matches else 0.0,
        reproj_error_px=np.nan, inlier_spread_px=np.nan, inlier_hull_area_px2=np.nan,
        model_coverage=result.n_inliers / model_size if model_size else 0.0,
        sigma_px=np.nan, sigma_t_pred_mm=np.nan, sigma_r_pred_deg=np.nan, sigma_t_model_mm=np.nan,
        sigma_r_model_deg=np.nan, sigma_t_unconditioned_mm=np.nan, sigma_r_unconditioned_deg=np.nan,
        covariance_status="no_pose",
    )
    if result.status != "ok":
        return row
    x = image_points[result.inliers].astype(np.float64)
    errors = reprojection_errors(object_points[result.inliers], x, K, result.T_cam_model)
    row["reproj_error_px"] = float(errors.mean())
    row["inlier_spread_px"] = float(np.sqrt(np.mean(np.sum((x - x.mean(axis=0)) ** 2, axis=1))))
    row["inlier_hull_area_px2"] = float(cv2.contourArea(cv2.convexHull(x.astype(np.float32))))
    covariance = propagated_covariance(object_points[result.inliers], x, result.T_cam_model, K,
                                       point_covariances[result.inliers], None, inlier_threshold_px)
    row.update(sigma_px=covariance.sigma_px, sigma_t_pred_mm=covariance.sigma_t_mm(),
               sigma_r_pred_deg=covariance.sigma_r_deg(), sigma_t_model_mm=covariance.sigma_t_mm("model"),
               sigma_r_model_deg=covariance.sigma_r_deg("model"),
               sigma_t_unconditioned_mm=covariance.sigma_t_mm("total_unconditioned"),
               sigma_r_unconditioned_deg=covariance.sigma_r_deg("total_unconditioned"),
               covariance_status=covariance.status)
    return row
