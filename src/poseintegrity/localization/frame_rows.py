"""One frame's rows of the artifacts table (Windsor et al. III-C, IV-C): its evidence, PnP-RANSAC per method, the
artifacts, the consensus columns, and E_t / E_r against its ground truth; runs in a worker
(:mod:`~poseintegrity.localization.extract` describes every column and drives the frames).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from poseintegrity.dataset_meta import pose_problem
from poseintegrity.lens import Camera
from poseintegrity.localization.consensus import CONSENSUS_COLUMNS, frame_consensus
from poseintegrity.localization.evidence import FrameEvidence, frame_evidence
from poseintegrity.localization.frame_artifacts import frame_artifacts
from poseintegrity.localization.frame_pnp import frame_pnp
from poseintegrity.localization.ground_truth import BoardPose, truth_error, truth_scale
from poseintegrity.localization.kinematic_consistency import kinematic_errors, reported_pose
from poseintegrity.localization.model_store import StoredModel, load_model
from poseintegrity.localization.pnp import PnPResult, failed, solve_checked
from poseintegrity.params.extract import ExtractParams
from poseintegrity.poses import NAN_POSE, pose_errors
from poseintegrity.ransac import minimal_sample_size, ransac_iterations
from poseintegrity.seeding import keyed_rng


FRAME_COLUMNS = ["world", "dataset", "trajectory", "stop", "image", "theta_deg", "x_mm"]


DATA_FLAGS = ("bad_image", "bad_pose")  # statuses of rows whose frame (not its localization) is at fault


NO_CONSENSUS = dict.fromkeys(CONSENSUS_COLUMNS, np.nan)  # the consensus columns of a row without a pose


def usable(table: pd.DataFrame) -> pd.DataFrame:
    """The rows of an artifacts table whose frame was usable: without the ``DATA_FLAGS`` statuses."""
    return table[~table["status"].isin(DATA_FLAGS)]


def frame_seed(seed: int, dataset: str, stop: int, image: int) -> int:
    """RANSAC seed of one frame, drawn from a Generator seeded by (params seed, dataset, stop, image)."""
    rng = keyed_rng(seed, dataset, stop, image)
    return int(rng.integers(0, 2**31 - 1))


def localize(
    object_points: np.ndarray, image_points: np.ndarray, point_covariances: np.ndarray, n_keypoints: int,
    model_size: int, K: np.ndarray, method: str, params: ExtractParams, seed: int,
) -> tuple[np.ndarray, dict[str, Any], str, str]:
    """PnP-RANSAC of one frame's correspondences with one method: (T_cam_board estimate (4, 4), artifacts, status,
    reason).

    Status "no_keypoints" when SIFT found nothing, else the PnP status ("too_few_matches", ...); the reason says why
    a frame has no pose ("" when it has one). The classic methods' iteration cap is sized for
    ``params.ransac_budget_inlier_ratio`` at ``params.ransac_confidence`` (ransac.py).
    """
    result = solve_checked(  # K of a checked Camera, points of checked features: no per-frame checks
        object_points, image_points, K, method, params.reprojection_threshold_px, params.ransac_confidence,
        iteration_cap(method, params), seed, params.usac_refine_lm,
    )
    return located(result, object_points, image_points, point_covariances, n_keypoints, model_size, K,
                   params.reprojection_threshold_px)


def located(
    result: PnPResult, object_points: np.ndarray, image_points: np.ndarray, point_covariances: np.ndarray,
    n_keypoints: int, model_size: int, K: np.ndarray, threshold_px: float,
) -> tuple[np.ndarray, dict[str, Any], str, str]:
    """What :func:`localize` returns for a PnP result of its correspondences (point_covariances : (m, 3, 3) mm^2,
    the matched model points' covariances; threshold_px: RANSAC's inlier threshold)."""
    artifacts = frame_artifacts(result, object_points, image_points, K, n_keypoints, model_size, point_covariances,
                                threshold_px)
    if n_keypoints == 0:
        return result.T_cam_model, artifacts, "no_keypoints", "SIFT found no keypoints in the frame"
    return result.T_cam_model, artifacts, result.status, result.reason


def iteration_cap(method: str, params: ExtractParams) -> int:
    """RANSAC iterations ``method`` may draw at most: usac_max_iterations for USAC; for classic RANSAC the count that
    reaches ransac_confidence at ransac_budget_inlier_ratio with the method's samples (ransac.py)."""
    if method == "usac_magsac":
        return params.usac_max_iterations
    return ransac_iterations(params.ransac_confidence, params.ransac_budget_inlier_ratio, minimal_sample_size(method))


@dataclass(frozen=True)
class FrameTask:
    """One frame of a dataset: everything a worker needs, M_t by reference."""

    frame: dict[str, Any]  # FRAME_COLUMNS, file and T_cam_board of frames.parquet
    image_path: Path
    features_path: Path
    evidence_path: Path
    model: StoredModel
    board: dict[str, Any] | None
    camera: Camera
    methods: tuple[str, ...]
    params: ExtractParams
    ground_truth: str = "board"  # meta.json's ground_truth: "board" (IV-C) or "poses" (frames.parquet's)
    T_cam0_board_exact: np.ndarray | None = None  # model image 0's exact board pose (rendered data: R11)
    T_base_board_robot: np.ndarray | None = None  # where the model view placed the board, in the robot's base frame
    handover_boards: tuple[dict[str, Any], ...] = ()  # meta.json's: boards that judge a frame its own board cannot
    consensus: bool = True  # compute the consensus columns (else NaN): see extract_datasets

    @property
    def pnp_path(self) -> Path:
        """The cache of the frame's PnP results (:mod:`frame_pnp`), beside its evidence."""
        return beside_evidence(self.evidence_path, ".pnp.npz")

    @property
    def consensus_path(self) -> Path:
        """The cache of the frame's consensus columns (:mod:`consensus`), beside its evidence."""
        return beside_evidence(self.evidence_path, ".consensus.npz")


def beside_evidence(evidence_path: Path, suffix: str) -> Path:
    """A per-frame cache file beside the frame's evidence: ``<image>.evidence.npz`` -> ``<image><suffix>``."""
    return evidence_path.with_name(evidence_path.name.removesuffix(".evidence.npz") + suffix)


def frame_rows(task: FrameTask) -> tuple[list[dict[str, Any]], tuple[BoardPose, ...]]:
    """All rows (one per method) of one frame, judged by the dataset's own board, and the frame's checked board
    poses (its own, then its handover boards'); runs in a worker."""
    frame, model = task.frame, task.model
    M_t = load_model(model.path, model.digest)
    evidence: FrameEvidence = frame_evidence(
        task.image_path, task.features_path, task.evidence_path, M_t, model.digest, task.board, task.camera,
        task.params, frame["file"], task.handover_boards,
    )
    point_covariances = M_t.covariances[evidence.model_index]
    known = frame["T_cam_board"] is not None  # None: a recorded frame without a pose (board ground truth)
    truth_problem = pose_problem(frame["T_cam_board"]) if known else None
    T_cam_board = exact_pose(frame)
    if evidence.image_problem:
        status, reason = "bad_image", evidence.image_problem
    elif truth_problem:
        status, reason = "bad_pose", f"ground truth T_cam_board of frames.parquet {truth_problem}"
    else:
        status, reason = None, ""
    seed = frame_seed(task.params.seed, frame["dataset"], int(frame["stop"]), int(frame["image"]))
    T_base_cam = reported_pose(frame.get("T_base_cam_robot"))
    T_base_board = NAN_POSE if task.T_base_board_robot is None else task.T_base_board_robot
    caps = {method: iteration_cap(method, task.params) for method in task.methods}
    results = {} if evidence.image_problem else frame_pnp(  # cached per frame; the classic RANSAC shared
        task.pnp_path, evidence.object_points, evidence.image_points, task.camera.K, model.digest, task.methods, caps,
        task.params, seed)
    consensus = {} if evidence.image_problem or not task.consensus else frame_consensus(  # cached per frame
        task.consensus_path, evidence.object_points, evidence.image_points, task.camera.K, model.digest, results, caps,
        task.params, seed)
    rows = []
    for method in task.methods:
        if evidence.image_problem:
            T_est, artifacts = NAN_POSE.copy(), frame_artifacts(failed("bad_image", reason), evidence.object_points,
                                                                evidence.image_points, task.camera.K, 0,
                                                                model.size, point_covariances,
                                                                task.params.reprojection_threshold_px)
        else:
            T_est, artifacts, pnp_status, pnp_reason = located(
                results[method], evidence.object_points, evidence.image_points, point_covariances,
                evidence.n_keypoints, model.size, task.camera.K, task.params.reprojection_threshold_px,
            )
        E_t_exact_mm, E_r_exact_deg = map(float, pose_errors(T_est, T_cam_board))
        E_t_kinematic_mm, E_r_kinematic_deg = map(float, kinematic_errors(T_base_cam, T_est, T_base_board))
        row = ({key: frame[key] for key in FRAME_COLUMNS}
               | dict(method=method, status=status or pnp_status, reason=reason or pnp_reason, model_size=model.size,
                      model_pixel_noise_px=model.pixel_noise_px)
               | artifacts
               | consensus.get(method, NO_CONSENSUS)
               | dict(E_t_exact_mm=E_t_exact_mm, E_r_exact_deg=E_r_exact_deg, E_t_kinematic_mm=E_t_kinematic_mm,
                      E_r_kinematic_deg=E_r_kinematic_deg, T_cam_board_est=T_est.ravel().tolist()))
        rows.append(row | judged(row, evidence.board, task))
    return rows, (evidence.board, *evidence.handover)


def exact_pose(frame: dict[str, Any]) -> np.ndarray:
    """(4, 4) mm: the frame's pose of frames.parquet (exact when rendered, the external system's when recorded);
    NaN when it is None or not a finite rigid transform."""
    pose = frame["T_cam_board"]
    if pose is None or pose_problem(pose):
        return NAN_POSE
    return np.asarray(pose, dtype=np.float64).reshape(4, 4)


def judged(row: dict[str, Any], board: BoardPose, task: FrameTask) -> dict[str, Any]:
    """The columns of a row that its ground truth decides, the checked board pose ``board`` (IV-C; the frame's poses
    of frames.parquet with ``ground_truth: poses``): E_t and E_r (NaN without a trusted pose, and on a flagged row),
    the board's columns, and what the board pose adds to E_t and E_r (R11)."""
    T_cam_board = exact_pose(task.frame)
    poses = task.ground_truth == "poses"
    truth = T_cam_board if poses else (board.T_cam_board if board.trusted else NAN_POSE)
    loose = T_cam_board if poses else (board.T_cam_board if board.consistent else NAN_POSE)
    T_est = np.asarray(row["T_cam_board_est"], dtype=np.float64).reshape(4, 4)
    E_t_mm, E_r_deg = map(float, pose_errors(T_est, truth))  # IV-C: the board is the truth (or the poses)
    E_t_loose_mm, E_r_loose_deg = map(float, pose_errors(T_est, loose))  # judges the looser tolerances
    scale_t, scale_r = truth_scale(board, task.params.ground_truth)
    if row["status"] in DATA_FLAGS:  # a flagged frame is no evidence: no error is reported for it
        E_t_mm = E_r_deg = E_t_loose_mm = E_r_loose_deg = np.nan
    E_t_board_exact_mm, E_r_board_exact_deg = map(float, pose_errors(board.T_cam_board, T_cam_board))
    exact_0 = NAN_POSE if task.T_cam0_board_exact is None else task.T_cam0_board_exact
    anchor = task.model.anchor
    E_t_truth_mm, E_r_truth_deg = truth_error(board.T_cam_board, T_cam_board, anchor.T_cam_board, exact_0)
    E_t_placement_mm, E_r_placement_deg = map(float, pose_errors(anchor.T_cam_board, exact_0))
    return dict(E_t_mm=E_t_mm, E_r_deg=E_r_deg, E_t_loose_mm=E_t_loose_mm, E_r_loose_deg=E_r_loose_deg,
                truth_scale_t=scale_t, truth_scale_r=scale_r,
                board_status=board.status, board_reason=board.reason,
                board_n_points=board.n_points, board_n_dropped=board.n_dropped, board_rms_px=board.rms_px,
                board_sigma_t_mm=board.sigma_t_mm, board_sigma_r_deg=board.sigma_r_deg, truth_board=board.board,
                E_t_board_exact_mm=E_t_board_exact_mm, E_r_board_exact_deg=E_r_board_exact_deg,
                E_t_truth_mm=E_t_truth_mm, E_r_truth_deg=E_r_truth_deg, anchor_status=anchor.status,
                E_t_placement_mm=E_t_placement_mm, E_r_placement_deg=E_r_placement_deg)
