"""Camera calibration from ChArUco board images (Zhang's method as ``cv2.calibrateCamera`` implements it).

The robot's camera is calibrated before any data is taken (stage 01 renders the calibration session; a user's own
calibration arrives as ``camera.yaml``). Every ChArUco corner found (``cv2.aruco.CharucoDetector``, OpenCV 5 API:
docs/references.md "OpenCV 5") is matched to its board point and the intrinsics and the 5-coefficient plumb_bob
distortion are estimated; k3 is held at 0, the usual practice for a lens of moderate distortion (its sixth-order
term is then not fitted to noise). The result is what every later stage uses as the camera.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from poseintegrity.boards import Charuco, scaled
from poseintegrity.errors import PoseIntegrityError
from poseintegrity.lens import Camera

MIN_CORNERS = 8  # ChArUco corners a view needs to add a constraint worth its 6 pose unknowns
MIN_VIEWS = 5  # views a calibration needs: the intrinsics and distortion are 8 unknowns beside 6 per view


class CalibrationError(PoseIntegrityError):
    """A calibration session that cannot give an estimate, or gives one worse than the bound asked for."""


@dataclass(frozen=True)
class Calibration:
    """The estimated camera and how well it fits: rms_px (OpenCV's overall reprojection RMS), per_view_rms_px (one per
    view used), views_used (indices of the views with >= MIN_CORNERS corners), n_corners (per view used)."""

    camera: Camera
    rms_px: float
    per_view_rms_px: tuple[float, ...]
    views_used: tuple[int, ...]
    n_corners: tuple[int, ...]


def detect_corners(image: np.ndarray, board: Charuco) -> tuple[np.ndarray, np.ndarray]:
    """ChArUco corners of an 8-bit gray image (h, w): printed board points (k, 3) mm (the drawing's, scaled by the
    board's measured ``scale``) and image points (k, 2) px; (0, 3), (0, 2) when none are found."""
    cv_board = board.cv_board()
    corners, ids, _, _ = cv2.aruco.CharucoDetector(cv_board).detectBoard(image)
    if ids is None or len(ids) == 0:
        return np.empty((0, 3)), np.empty((0, 2))
    object_points, image_points = cv_board.matchImagePoints(corners, ids)
    return scaled(object_points.reshape(-1, 3), board), image_points.reshape(-1, 2).astype(np.float64)


def calibrate(images: list[np.ndarray], board: Charuco, max_rms_px: float, key: str) -> Calibration:
    """Estimate the camera from calibration images (each (h, w) uint8, one size); ``key``: the params section of the
    ``max_rms_px`` came from, named by :class:`CalibrationError` (too few usable views, no convergence, an RMS above
    the bound)."""
    height, width = images[0].shape
    found = [(i, *detect_corners(image, board)) for i, image in enumerate(images)]
    used = [(i, obj, img) for i, obj, img in found if len(obj) >= MIN_CORNERS]
    if len(used) < MIN_VIEWS:
        raise CalibrationError(f"{key}.n_views: only {len(used)} of {len(images)} calibration views show >= "
                               f"{MIN_CORNERS} ChArUco corners; a calibration needs {MIN_VIEWS} (more views, or "
                               f"{key}.distance_mm / max_tilt_deg: views too far or tilted?)")
    objects = [obj.astype(np.float32) for _, obj, _ in used]
    points = [img.astype(np.float32) for _, _, img in used]
    threads = cv2.getNumThreads()
    cv2.setNumThreads(1)  # OpenCV's parallel sums differ in the last bits from run to run: stage 01 must repeat exactly
    try:
        rms, K, dist, rvecs, tvecs = cv2.calibrateCamera(objects, points, (width, height), None, None,
                                                         flags=cv2.CALIB_FIX_K3)
    except cv2.error as error:
        raise CalibrationError(f"{key}: cv2.calibrateCamera failed: {str(error).strip().splitlines()[-1]}") from None
    finally:
        cv2.setNumThreads(threads)
    dist = np.asarray(dist, dtype=np.float64).ravel()[:5]
    if not (np.isfinite(rms) and np.all(np.isfinite(K)) and np.all(np.isfinite(dist)) and K[0, 0] > 0 and K[1, 1] > 0):
        raise CalibrationError(f"{key}: the calibration did not converge (RMS {rms}, K {np.round(K, 3).tolist()})")
    if rms > max_rms_px:
        raise CalibrationError(f"{key}.max_rms_px: the calibration's reprojection RMS {rms:.3f} px exceeds the bound "
                               f"{max_rms_px:g} px")
    per_view = []
    for obj, img, rvec, tvec in zip(objects, points, rvecs, tvecs):
        projected, _ = cv2.projectPoints(obj, rvec, tvec, K, dist)
        per_view.append(float(np.sqrt(np.mean(np.sum((projected.reshape(-1, 2) - img) ** 2, axis=1)))))
    return Calibration(Camera(np.asarray(K, dtype=np.float64), dist, width, height), float(rms), tuple(per_view),
                       tuple(i for i, _, _ in used), tuple(len(obj) for _, obj, _ in used))
