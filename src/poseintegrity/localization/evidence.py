"""What one frame gives before any PnP method runs, computed once and cached beside its SIFT features.

Per frame, stages 02 and 05 need the same method-independent evidence: the image checked against its dataset's
camera (8-bit gray, camera.yaml's size), its CLAHE + SIFT features (IV-C), the ratio-test 2D-3D correspondences
to M_t (III-B), their image points undistorted by the calibrated lens, and the board's checked pose (the ground truth
of IV-C, :mod:`~poseintegrity.localization.ground_truth`; none for a recorded dataset without a board, status
``no_board``). Stage 02 computes them and stores them in one
small ``.npz`` per frame (``<features_dir>/<dataset>/images/<image>.evidence.npz``); stage 05, which runs the other
PnP methods on the same frames, reads them back instead of decoding the image, loading its descriptors,
matching them and detecting the board again. The entry's key hashes everything the evidence depends on (image
bytes, CLAHE/SIFT settings, the ratio, M_t itself, the board, the camera), so an entry is used only when
recomputing it would give the same arrays, and only when whole (:mod:`poseintegrity.cache_entry`); a frame image
that fails its check is never cached (it is checked, and flagged, again). The frame's SIFT cache file is checked
too when its evidence is read back, and computed again if it is not whole: no damaged cache file is left behind.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from poseintegrity.cache_entry import Miss, read_entry, write_entry
from poseintegrity.lens import Camera
from poseintegrity.localization.features import (
    ImageReadError, cached_features, decode_gray, features_key, read_image_bytes, stored_features,
)
from poseintegrity.localization.ground_truth import BoardPose, ImageMarkers, board_from_dict, board_pose, no_pose
from poseintegrity.localization.matching import match_ratio_test
from poseintegrity.localization.target_model import TargetModel
from poseintegrity.params.extract import ExtractParams

EVIDENCE_VERSION = 6  # bump when the cached content or its layout changes (3: the checked board pose, issue 30;
# 4: the matched model points' indices, whose covariances the predicted error needs, issue 38; 5: the board poses'
# covariances and the handover boards' poses, issue 39; 6: whether a board pose passed checks 1-2, issue 39)


@dataclass(frozen=True)
class FrameEvidence:
    """The method-independent evidence of one frame.

    image_problem : why the image is unusable ("" if it is fine; then nothing else was computed)
    object_points : (m, 3) float64, M_t points of the m ratio-test matches, board frame, mm
    model_index : (m,) int, their indices in M_t (whose covariances they carry)
    image_points : (m, 2) float64, the frame's keypoints of those matches, undistorted (ideal pinhole px of K)
    n_keypoints : SIFT keypoints in the frame
    board : the board's checked pose (the ground truth, :mod:`~poseintegrity.localization.ground_truth`)
    handover : the checked poses of the dataset's handover boards, in meta.json's order (their ``board`` 1, 2, ...)
    """

    image_problem: str
    object_points: np.ndarray
    model_index: np.ndarray
    image_points: np.ndarray
    n_keypoints: int
    board: BoardPose
    handover: tuple[BoardPose, ...] = ()


def bad_image(problem: str) -> FrameEvidence:
    """The evidence of a frame whose image failed its check: no correspondences, no board."""
    return FrameEvidence(problem, np.empty((0, 3)), np.empty(0, np.intp), np.empty((0, 2)), 0,
                         no_pose("bad_image", problem))


def model_digest(model: TargetModel) -> str:
    """SHA-1 of M_t's points and descriptors: the part of an evidence key that stands for the target model."""
    return hashlib.sha1(model.points.tobytes() + model.descriptors.tobytes()).hexdigest()


def evidence_key(features_key_: str, digest: str, params: ExtractParams, board: dict[str, Any], camera: Camera,
                 handover_boards: list[dict[str, Any]] = ()) -> str:
    """Hash of what a frame's evidence depends on beyond its features: M_t, the ratio, the boards and their checks,
    the camera."""
    settings = json.dumps([EVIDENCE_VERSION, features_key_, digest, params.ratio_test, board, list(handover_boards),
                           params.ground_truth.model_dump(),
                           np.asarray(camera.K, np.float64).tolist(), np.asarray(camera.dist, np.float64).tolist(),
                           [camera.width, camera.height]], sort_keys=True)
    return hashlib.sha1(settings.encode()).hexdigest()


def correspondences(features, model: TargetModel, ratio: float, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """2D-3D correspondences of a frame: ratio-test matches of its descriptors to M_t (III-B).

    Returns the matched points' indices in M_t (m,) and image points (m, 2), undistorted by ``camera`` (ideal
    pinhole px of its K); the object points are ``model.points[index]`` (m, 3, board frame, mm).
    """
    pairs = match_ratio_test(features.descriptors, model.descriptors, ratio)
    return pairs[:, 1].astype(np.intp), camera.undistort(features.points[pairs[:, 0]])


def _load(path: Path, key: str) -> FrameEvidence | None:
    """The evidence stored at ``path`` when the file is whole and its key is ``key``, else None (recomputed)."""
    stored = read_entry(path, key)
    if isinstance(stored, Miss):
        return None
    return FrameEvidence("", stored["object_points"], stored["model_index"].astype(np.intp), stored["image_points"],
                         int(stored["n_keypoints"]), _stored_pose(stored, "board"),
                         tuple(_stored_pose(stored, f"handover{n}", n + 1) for n in range(int(stored["n_handover"]))))


def _pose_arrays(prefix: str, pose: BoardPose) -> dict[str, Any]:
    """A checked board pose as the arrays of an evidence file (``prefix``_...)."""
    return {f"{prefix}_T_cam_board": pose.T_cam_board, f"{prefix}_status": pose.status,
            f"{prefix}_reason": pose.reason, f"{prefix}_n_points": pose.n_points, f"{prefix}_n_dropped": pose.n_dropped,
            f"{prefix}_rms_px": pose.rms_px, f"{prefix}_sigma_t_mm": pose.sigma_t_mm,
            f"{prefix}_sigma_r_deg": pose.sigma_r_deg, f"{prefix}_covariance": pose.covariance,
            f"{prefix}_consistent": pose.consistent}


def _stored_pose(stored, prefix: str, board: int = 0) -> BoardPose:
    """The board pose :func:`_pose_arrays` stored."""
    return BoardPose(stored[f"{prefix}_T_cam_board"], str(stored[f"{prefix}_status"]), str(stored[f"{prefix}_reason"]),
                     *(int(stored[f"{prefix}_{name}"]) for name in ("n_points", "n_dropped")),
                     *(float(stored[f"{prefix}_{name}"]) for name in ("rms_px", "sigma_t_mm", "sigma_r_deg")),
                     stored[f"{prefix}_covariance"], board, bool(stored[f"{prefix}_consistent"]))


def frame_evidence(
    image_path: Path, features_path: Path, evidence_path: Path, model: TargetModel, digest: str,
    board: dict[str, Any], camera: Camera, params: ExtractParams, name: str,
    handover_boards: list[dict[str, Any]] = (),
) -> FrameEvidence:
    """The evidence of one frame: from ``evidence_path`` when its key matches, else computed (the SIFT features
    from ``features_path``, the SIFT cache) and stored. A missing file raises :class:`ImageReadError`; an image that
    cannot be decoded or is not 8-bit gray of the camera's size gives :func:`bad_image` evidence,
    naming the file by ``name`` (as frames.parquet does: the table is the same whichever folder holds the data).
    ``handover_boards``: meta.json's, each board's pose found and checked too."""
    data = read_image_bytes(image_path)
    features_key_ = features_key(data, params.clahe, params.sift)
    key = evidence_key(features_key_, digest, params, board, camera, handover_boards)
    if (cached := _load(evidence_path, key)) is not None:
        if isinstance(read_entry(features_path, features_key_), Miss):  # not whole: computed again, none left damaged
            stored_features(image_path, features_path, features_key_, params.clahe, params.sift, data)
        return cached
    try:
        image = decode_gray(data, name, (camera.width, camera.height))
    except ImageReadError as error:
        return bad_image(str(error))
    features = cached_features(image_path, features_path, params.clahe, params.sift, data=data, image=image)
    model_index, image_points = correspondences(features, model, params.ratio_test, camera)
    object_points = model.points[model_index]
    markers = ImageMarkers(image)  # one marker detection for the board and its handover boards (same poses)
    truth = (board_pose(image, board_from_dict(board), camera, params.ground_truth, markers) if board is not None
             else no_pose("no_board", "recorded poses are the ground truth"))  # no board: recorded poses instead
    handover = tuple(replace(board_pose(image, board_from_dict(other), camera, params.ground_truth, markers),
                             board=n + 1) for n, other in enumerate(handover_boards))
    write_entry(evidence_path, key, dict(
        object_points=object_points, model_index=model_index, image_points=image_points,
        n_keypoints=features.n_keypoints, n_handover=len(handover), **_pose_arrays("board", truth),
        **{key: value for n, pose in enumerate(handover) for key, value in _pose_arrays(f"handover{n}", pose).items()}))
    return FrameEvidence("", object_points, model_index, image_points, features.n_keypoints, truth, handover)
