"""Board-based ground truth (IV-C): ArUco GridBoard detection -> board.matchImagePoints -> cv2.solvePnP.

OpenCV 5 API (docs/references.md, "OpenCV 5"): ``cv2.aruco.ArucoDetector(...).detectMarkers`` replaces the removed free functions.
The estimated pose maps board coordinates (the frame of ``board.getObjPoints()``, mm) into the camera frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np
from pydantic import ValidationError

from poseintegrity.errors import ArgumentError
from poseintegrity.grayscale import as_gray8
from poseintegrity.lens import Camera
from poseintegrity.localization.dataset import BoardMeta, aruco_dictionary
from poseintegrity.poses import NAN_POSE, pose_from_rvec_tvec


@dataclass(frozen=True)
class BoardPose:
    """T_cam_board : (4, 4) float, mm (NaN unless status == "ok"); n_markers : detected board markers;
    status : "ok", "board_not_detected" or "board_pnp_failed"."""

    T_cam_board: np.ndarray
    n_markers: int
    status: str


def make_board(board: dict[str, Any]) -> cv2.aruco.GridBoard:
    """The GridBoard described by a dataset's ``meta.json["board"]`` or a board.yaml (lengths in mm), checked as a
    dataset's board is (:class:`~poseintegrity.localization.dataset.BoardMeta`): a missing key, a value of the wrong
    type or range, an unknown dictionary or marker ids outside it raise :class:`~poseintegrity.errors.ArgumentError`
    naming ``board`` and each key."""
    try:
        board = BoardMeta.model_validate(board).model_dump()
    except ValidationError as error:
        problems = "; ".join(f"{'.'.join(map(str, item['loc'])) or 'the board'}: {item['msg']}"
                             for item in error.errors())
        raise ArgumentError(f"board: {problems} (expected the keys {', '.join(BoardMeta.model_fields)})") from None
    dictionary = cv2.aruco.getPredefinedDictionary(aruco_dictionary(board["dictionary"]))
    n_markers = board["markers_x"] * board["markers_y"]
    ids = np.arange(board["first_id"], board["first_id"] + n_markers)
    return cv2.aruco.GridBoard(
        (board["markers_x"], board["markers_y"]), board["marker_length_mm"], board["separation_mm"], dictionary, ids
    )


def board_pose(image: np.ndarray, board: cv2.aruco.GridBoard, camera: Camera) -> BoardPose:
    """Pose of the board in an 8-bit grayscale image (h, w) of ``camera`` (its corners undistorted by the calibrated
    lens, then solvePnP with its K).

    Needs at least one board marker (4 coplanar corners); otherwise a NaN pose with a status, never an error.
    image : (h, w) uint8; colour or 16-bit images are converted, anything else refused
    (:func:`~poseintegrity.grayscale.as_gray8`). ``camera`` is a checked
    :class:`~poseintegrity.lens.Camera` (finite K, positive focal lengths, finite distortion).
    """
    if not isinstance(camera, Camera):
        raise ArgumentError(f"camera: expected a poseintegrity.lens.Camera, got {type(camera).__name__}")
    if not isinstance(board, cv2.aruco.Board):
        raise ArgumentError(f"board: expected a cv2.aruco board (make_board), got {type(board).__name__}")
    image = as_gray8("image", image)
    detector_params = cv2.aruco.DetectorParameters()
    detector_params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX  # sub-pixel corners for pose
    detector = cv2.aruco.ArucoDetector(board.getDictionary(), detector_params)
    corners, ids, _ = detector.detectMarkers(image)
    if ids is None or len(ids) == 0:
        return BoardPose(NAN_POSE.copy(), 0, "board_not_detected")
    object_points, image_points = board.matchImagePoints(corners, ids)
    if object_points is None or len(object_points) < 4:
        return BoardPose(NAN_POSE.copy(), 0, "board_not_detected")
    n_markers = len(object_points) // 4
    try:
        ideal = camera.undistort(image_points.reshape(-1, 2))
        found, rvec, tvec = cv2.solvePnP(object_points, ideal, np.asarray(camera.K, np.float64), None)
    except cv2.error:
        found = False
    if not found or not (np.all(np.isfinite(rvec)) and np.all(np.isfinite(tvec))):
        return BoardPose(NAN_POSE.copy(), n_markers, "board_pnp_failed")
    return BoardPose(pose_from_rvec_tvec(rvec, tvec), n_markers, "ok")
