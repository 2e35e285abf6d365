"""Static sparse feature model of the target, M_t (paper III-B).

Two model images taken with a relative camera pose the robot reports (IV-D: 20 mm apart along the camera x axis;
the robot really moved slightly otherwise) -> CLAHE + SIFT -> ratio-test matches -> ``cv2.triangulatePoints`` ->
keep points on the target (the paper trims by hand; we keep keypoints inside the renderer's target mask in both
images) -> coordinates in the board frame, through the ArUco board's pose in the first model image (IV-C: "the
origin of the model reference frame was transformed to be coincident with the origin of the ArUco board"), so that
a PnP pose of the model is directly an estimate of T_cam_board.

Beyond the paper, every point carries its triangulation covariance (:mod:`pose_covariance`, (b)), from the pixel noise
the model pair's own residuals measure: what the predicted localization error of every later frame is built on.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from poseintegrity.errors import ArgumentError, check_array, check_image, check_intrinsics, check_pose, check_scalar
from poseintegrity.lens import Camera
from poseintegrity.localization.features import Features
from poseintegrity.localization.matching import match_ratio_test
from poseintegrity.localization.pnp import reprojection_errors
from poseintegrity.localization.pose_covariance import triangulation_covariances, triangulation_sigma


@dataclass(frozen=True)
class TargetModel:
    """M_t = [f_0, ..., f_n]: each feature a descriptor and a 3D point.

    points : (n, 3) float64, board frame, mm
    descriptors : (n, 128) float32, SIFT descriptors from the first model image
    covariances : (n, 3, 3) float64, each point's triangulation covariance, board frame, mm^2
    pixel_noise_px : the keypoint noise of the model pair, measured from its triangulation residuals (NaN when
        empty)
    """

    points: np.ndarray
    descriptors: np.ndarray
    covariances: np.ndarray
    pixel_noise_px: float

    @property
    def size(self) -> int:
        return len(self.points)


def triangulate(K: np.ndarray, T_cam1_cam0: np.ndarray, x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """Linear (DLT) triangulation: (n, 3) points in camera-0 coordinates from pixels x0, x1 (n, 2).

    Projection matrices P0 = K [I | 0] and P1 = K [R | t] with (R, t) of T_cam1_cam0 (camera 0 -> camera 1).
    Checked once (ArgumentError naming the argument): K a pinhole matrix, T_cam1_cam0 a rigid transform, x0 and x1
    finite (n, 2) of the same n.
    """
    K, T_cam1_cam0 = check_intrinsics("K", K), check_pose("T_cam1_cam0", T_cam1_cam0)
    x0, x1 = check_array("x0", x0, shape=(None, 2)), check_array("x1", x1, shape=(None, 2))
    if len(x0) != len(x1):
        raise ArgumentError(f"x0 and x1: lengths must agree, got {len(x0)} and {len(x1)}")
    P0 = K @ np.hstack([np.eye(3), np.zeros((3, 1))])
    P1 = K @ T_cam1_cam0[:3, :]
    X_h = cv2.triangulatePoints(P0, P1, x0.T.astype(np.float64), x1.T.astype(np.float64))
    with np.errstate(divide="ignore", invalid="ignore"):
        return (X_h[:3] / X_h[3]).T


def _residuals(X_cam: np.ndarray, x: np.ndarray, K: np.ndarray) -> np.ndarray:
    """(n, 2) px: pixels x minus the projections of camera points X_cam (n, 3) by the pinhole K."""
    projected = X_cam @ K.T
    return x - projected[:, :2] / projected[:, 2:3]


def _inside(mask: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(n,) bool: pixel x (n, 2) lies on a nonzero mask pixel (h, w)."""
    h, w = mask.shape
    col = np.clip(np.round(x[:, 0]).astype(int), 0, w - 1)
    row = np.clip(np.round(x[:, 1]).astype(int), 0, h - 1)
    in_image = (x[:, 0] >= 0) & (x[:, 0] <= w - 1) & (x[:, 1] >= 0) & (x[:, 1] <= h - 1)
    return in_image & (mask[row, col] > 0)


def build_target_model(
    features: tuple[Features, Features],
    masks: tuple[np.ndarray, np.ndarray],
    T_cam1_cam0: np.ndarray,
    T_cam0_board: np.ndarray,
    camera: Camera,
    ratio: float,
    max_reprojection_px: float,
) -> TargetModel:
    """M_t from the two model views.

    features : CLAHE + SIFT features of model image 0 and 1
    masks : (h, w) uint8 target masks of both images (nonzero = target)
    T_cam1_cam0 : (4, 4) camera 0 -> camera 1, mm: the model baseline as the robot reports it
    T_cam0_board : (4, 4) board -> camera 0, mm: the ArUco board's pose in model image 0
    camera : the calibrated camera: keypoints are undistorted before any geometry (masks are looked up raw)
    A point is kept when it lies in front of both cameras, reprojects within ``max_reprojection_px`` in both
    images and its keypoints lie inside both masks. An empty model (no texture, no overlap) is returned
    as such; every frame then fails with ``too_few_matches``. The kept points' residuals measure the pixel noise
    (:func:`~poseintegrity.localization.pose_covariance.triangulation_sigma`), and each point's covariance follows
    from it, the baseline and its depth.
    """
    if not isinstance(camera, Camera):
        raise ArgumentError(f"camera: expected a poseintegrity.lens.Camera, got {type(camera).__name__}")
    check_pose("T_cam1_cam0", T_cam1_cam0)
    check_pose("T_cam0_board", T_cam0_board)
    for index, mask in enumerate(masks):
        check_image(f"masks[{index}]", mask)
    check_scalar("ratio", ratio, low=0.0, high=1.0, low_open=True)
    check_scalar("max_reprojection_px", max_reprojection_px, low=0.0, low_open=True)
    K = np.asarray(camera.K, dtype=np.float64)
    pairs = match_ratio_test(features[0].descriptors, features[1].descriptors, ratio)
    raw0 = features[0].points[pairs[:, 0]].astype(np.float64)
    raw1 = features[1].points[pairs[:, 1]].astype(np.float64)
    x0, x1 = camera.undistort(raw0), camera.undistort(raw1)
    X_cam0 = triangulate(K, T_cam1_cam0, x0, x1)
    finite = np.all(np.isfinite(X_cam0), axis=1)
    X_cam0 = np.where(finite[:, None], X_cam0, 0.0)
    error0 = reprojection_errors(X_cam0, x0, K, np.eye(4))
    error1 = reprojection_errors(X_cam0, x1, K, T_cam1_cam0)
    keep = (
        finite
        & (error0 <= max_reprojection_px)
        & (error1 <= max_reprojection_px)
        & _inside(masks[0], raw0)
        & _inside(masks[1], raw1)
    )
    X_cam0 = X_cam0[keep].reshape(-1, 3)
    sigma_px = triangulation_sigma(_residuals(X_cam0, x0[keep], K),
                                   _residuals(X_cam0 @ T_cam1_cam0[:3, :3].T + T_cam1_cam0[:3, 3], x1[keep], K))
    covariances = (triangulation_covariances(X_cam0, T_cam1_cam0, K, sigma_px) if len(X_cam0)
                   else np.empty((0, 3, 3)))
    T_board_cam0 = np.linalg.inv(T_cam0_board)
    R = T_board_cam0[:3, :3]
    points = X_cam0 @ R.T + T_board_cam0[:3, 3]
    descriptors = features[0].descriptors[pairs[keep, 0]]
    return TargetModel(points, descriptors.reshape(-1, 128).astype(np.float32), R @ covariances @ R.T, sigma_px)
