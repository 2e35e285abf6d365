"""Stage 02/05 driver: every frame of the datasets through the localization pipeline, one row per PnP method.

Before any work: the index, each dataset's meta.json and frames.parquet are checked (:mod:`dataset`), a
:class:`~poseintegrity.localization.dataset.DatasetError` naming the dataset and file otherwise. Then, on the
workers of the ``parallel`` section (:class:`~poseintegrity.parallel.Workers`):

1. per dataset, M_t from the two model images (III-B); a model image or mask that is not the 8-bit gray image of
   camera.yaml's image size stops the stage naming it. M_t is stored beside the SIFT cache, and every frame task
   loads it from there once per worker process (a task carries its path, not its 1-2 MB of descriptors);
2. per frame (one task, results in frame order): its evidence (:mod:`evidence`: image check, CLAHE + SIFT, ratio-test
   matches to M_t, the board's checked pose; cached, so stage 05 reuses stage 02's), then PnP-RANSAC per method
   (:mod:`frame_pnp`: cached per frame, the classic RANSAC shared by EPnP, SQPnP and iterative) ->
   artifacts (III-C), the evidence that needs no ground truth (:mod:`consensus`: the inliers' bootstrap and RANSAC
   re-runs per frame and method, cached per frame; per stop the spread of its images' poses, once a dataset's rows
   are gathered) and E_t/E_r against the ground truth, the board pose of the frame (IV-C): ``E_t_mm``,
   ``E_r_deg`` (NaN without a pose, and without a trusted board pose: ``board_status`` other than "ok", e.g.
   ``bad_ground_truth`` with its ``board_reason``; such a frame keeps its localization status and n_i, it is only
   not judged); the same against a board pose refused by the trust rule's limits alone, which judges looser
   tolerances (``E_t_loose_mm``, ``E_r_loose_deg``, NaN where the board gave no consistent fit; ``truth_scale_t``,
   ``truth_scale_r``: its predicted uncertainty over the limits, :func:`.ground_truth.truth_scale`); against the
   exact renderer pose as a diagnostic: ``E_t_exact_mm``, ``E_r_exact_deg``. The board
   pose's own errors: ``E_*_board_exact`` (against the exact pose, absolute) and ``E_*_truth`` (what it adds to E_t
   and E_r: relative to model image 0's, :func:`~poseintegrity.localization.ground_truth.truth_error`; R11); the
   model placement's (``E_*_placement``: model image 0's board pose against its exact pose, ``anchor_status`` its
   check). A recorded dataset whose meta.json says ``ground_truth: poses``
   (:mod:`poseintegrity.recorded`) has no board: M_t is placed by model image 0's pose ``model.T_cam0_ref``, the
   frames' poses of frames.parquet are the ground truth of E_t/E_r (as well as of the ``_exact`` columns), and the
   board columns say ``no_board``.

Every cache file (SIFT features, evidence, PnP results, consensus columns, M_t) is used only when it proves it is
whole and current (:mod:`poseintegrity.cache_entry`), and computed again otherwise; the unfinished writes of a killed
run are removed first. The stage prints one line per dataset where it computed a file (how many, and why) and a total.

A frame whose image is unusable gives rows with status ``bad_image``, one whose exact pose in frames.parquet is not a
finite rigid transform rows with status ``bad_pose`` (a damaged file: no error is reported); a frame without a pose
gives its PnP status; a recorded frame whose pose is not known (None in frames.parquet, board ground truth) is not
flagged and its ``_exact`` errors are NaN. The ``reason`` column says why for every row whose status is not "ok"
(empty otherwise). Neither is evidence about localization: :func:`usable` drops them before
envelopes and summaries.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, replace
from functools import lru_cache, partial
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from poseintegrity.cache_entry import Miss, describe, read_entry, read_whole, tallied, write_entry
from poseintegrity.lens import Camera
from poseintegrity.seeding import keyed_rng
from poseintegrity.localization.dataset import Dataset, DatasetError, load_dataset, load_index, pose_problem
from poseintegrity.localization.evidence import FrameEvidence, frame_evidence, model_digest
from poseintegrity.localization.features import cached_features, read_gray
from poseintegrity.localization.frame_artifacts import frame_artifacts
from poseintegrity.localization.consensus import CONSENSUS_COLUMNS, frame_consensus, stop_spread
from poseintegrity.localization.frame_pnp import frame_pnp
from poseintegrity.localization.kinematic_consistency import kinematic_errors, reported_pose
from poseintegrity.localization.ground_truth import (
    BoardPose, board_from_dict, board_pose, handed_over, handover, no_pose, truth_error, truth_scale,
)
from poseintegrity.params.extract import ExtractParams
from poseintegrity.localization.pnp import PnPResult, failed, solve_checked
from poseintegrity.ransac import minimal_sample_size, ransac_iterations
from poseintegrity.poses import NAN_POSE, pose_errors
from poseintegrity.localization.target_model import TargetModel, build_target_model
from poseintegrity.parallel import Workers
from poseintegrity.staging import remove_staging_files

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
    """What :func:`localize` returns for a PnP result of its correspondences (point_covariances : (k, 3, 3) mm^2,
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
class ModelTask:
    """Build M_t of one dataset and store it at ``path``."""

    dataset: Dataset
    cache_dir: Path
    params: ExtractParams

    @property
    def path(self) -> Path:
        return self.cache_dir / "model" / "M_t.npz"


@dataclass(frozen=True)
class StoredModel:
    """Where a dataset's M_t is stored, its digest (part of every evidence key), size and the model pair's measured
    pixel noise; ``anchor``: the board's checked pose in model image 0 that placed M_t in the board frame (status
    ``no_board`` with recorded poses); ``handover_anchors``: the handover boards' checked poses there."""

    path: Path
    digest: str
    size: int
    anchor: BoardPose
    pixel_noise_px: float
    handover_anchors: tuple[BoardPose, ...] = ()

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


def dataset_model(dataset: Dataset, params: ExtractParams, cache_dir: Path) -> tuple[TargetModel, BoardPose]:
    """M_t of a dataset from its two model images (features cached like frames), and the board pose in model image
    0 that placed it. Each image and mask must be the 8-bit gray image of camera.yaml's size:
    :class:`~poseintegrity.localization.features.ImageReadError` naming the dataset and the file otherwise. A board
    that gives no pose in model image 0 stops the stage naming the dataset; one whose pose fails its checks
    (``bad_ground_truth``) still places M_t, and the anchor's status says so (artifacts.json)."""
    model = dataset.meta["model"]
    try:
        images = [read_gray(dataset.path(image), dataset.image_size) for image in model["images"]]
        masks = tuple(read_gray(dataset.path(mask), dataset.image_size) for mask in model["masks"])
    except DatasetError as error:
        raise type(error)(f"dataset {dataset.name}, model pair: {error}") from None
    features = tuple(
        cached_features(dataset.path(name), cache_dir / "model" / f"{index}.npz", params.clahe, params.sift, image=image)
        for index, (name, image) in enumerate(zip(model["images"], images))
    )
    if dataset.meta.get("ground_truth", "board") == "poses":  # recorded: M_t in the external system's frame
        T_cam0_ref = np.asarray(dataset.meta["model"]["T_cam0_ref"], dtype=np.float64)
        return build_target_model(features, masks, dataset.model_baseline(), T_cam0_ref, dataset.camera,
                                  params.ratio_test, params.model_max_reprojection_px), no_pose("no_board", "")
    anchor = board_pose(images[0], board_from_dict(dataset.meta["board"], f"dataset {dataset.name}: meta.json board"),
                        dataset.camera, params.ground_truth)  # IV-C: M_t in the board frame
    if anchor.status not in ("ok", "bad_ground_truth"):
        raise DatasetError(f"dataset {dataset.name}: the ArUco board is not found in model image "
                           f"{model['images'][0]} ({anchor.status}: {anchor.reason}), so the target model cannot be "
                           f"placed in the board frame (IV-C)")
    return build_target_model(features, masks, dataset.model_baseline(), anchor.T_cam_board, dataset.camera,
                              params.ratio_test, params.model_max_reprojection_px), anchor


def handover_anchors(dataset: Dataset, params: ExtractParams) -> tuple[BoardPose, ...]:
    """The checked poses of meta.json's handover boards in model image 0 (``board`` 1, 2, ...; ground_truth.py)."""
    others = dataset.meta.get("handover_boards") or []
    if not others:
        return ()
    image = read_gray(dataset.path(dataset.meta["model"]["images"][0]), dataset.image_size)
    return tuple(replace(board_pose(image, board_from_dict(other, f"dataset {dataset.name}: meta.json handover_boards["
                                                                  f"{k}]"), dataset.camera, params.ground_truth),
                         board=k + 1) for k, other in enumerate(others))


def store_model(task: ModelTask) -> StoredModel:
    """Build M_t of a dataset (a worker task) and store it for the frame tasks (unless stored already)."""
    model, anchor = dataset_model(task.dataset, task.params, task.cache_dir)
    digest = model_digest(model)
    stored = read_entry(task.path, digest)  # the covariances do not enter the digest (no evidence depends on them)
    if isinstance(stored, Miss) or not np.array_equal(stored["covariances"], model.covariances):
        write_entry(task.path, digest, dict(points=model.points, descriptors=model.descriptors,
                                            covariances=model.covariances, pixel_noise_px=model.pixel_noise_px))
    return StoredModel(task.path, digest, model.size, anchor, model.pixel_noise_px,
                       handover_anchors(task.dataset, task.params))


@lru_cache(maxsize=4)
def load_model(path: Path, digest: str) -> TargetModel:
    """M_t stored by :func:`store_model`, loaded once per worker process (``digest``: the one expected)."""
    stored = read_whole(path, digest)  # checked (and counted) by store_model
    if isinstance(stored, Miss):
        raise DatasetError(f"target model {path} is {stored.reason} since this stage stored it (another run on the "
                           f"same data?): re-run the stage")
    return TargetModel(stored["points"], stored["descriptors"], stored["covariances"], float(stored["pixel_noise_px"]))


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


def handed_over_rows(tasks: list[FrameTask], results: list[tuple[list[dict[str, Any]], tuple[BoardPose, ...]]],
                     params: ExtractParams) -> list[dict[str, Any]]:
    """The rows of one dataset's frames (``tasks`` and their :func:`frame_rows` results, in order), each frame whose
    own board pose is not trusted judged by the first handover board that is (ground_truth.py, "Handover boards")."""
    rows = [list(frame_result[0]) for frame_result in results]
    if not tasks or not tasks[0].handover_boards:
        return [row for frame in rows for row in frame]
    model = tasks[0].model
    links = [handover(model.anchor, other) for other in model.handover_anchors]
    for task, frame, (_, boards) in zip(tasks, rows, results):
        if boards[0].trusted or not frame or frame[0]["status"] in DATA_FLAGS:
            continue
        for k, link in enumerate(links, start=1):
            if link is None or not boards[k].trusted:
                continue
            carried = handed_over(boards[k], link, params.ground_truth, k)
            if carried.trusted:
                frame[:] = [row | judged(row, carried, task) for row in frame]
                break
    return [row for frame in rows for row in frame]


def extract_datasets(
    datasets: list[Dataset], params: ExtractParams, methods: list[str], workers: Workers, progress: bool = True,
    consensus: bool = True,
) -> pd.DataFrame:
    """Artifact rows (one per frame and method, datasets in the given order, frames by stop and image) of checked
    datasets: M_t per dataset, then every frame, on ``workers``; then each stop's spread of poses
    (:func:`~poseintegrity.localization.consensus.stop_spread`).

    consensus : compute the consensus columns of every method (:mod:`consensus`; NaN otherwise). Stage 02 does, for
    ``protocol.pnp_method``, at ~2 ms (bootstrap) + ~15 ms (3 USAC re-runs) per frame; stage 05 does not: its five
    classic methods would cost ~50 ms more per frame, about three times its PnP, for columns no figure of it reads."""
    cache_dirs = [_cache_root(dataset.data_dir, params) / dataset.name for dataset in datasets]
    unfinished = {dataset.name: remove_staging_files(cache_dir) for dataset, cache_dir in zip(datasets, cache_dirs)}
    stored = workers.map(partial(tallied, store_model), [ModelTask(d, c, params) for d, c in zip(datasets, cache_dirs)],
                         desc="target models M_t", progress=progress)
    models = [model for model, _ in stored]
    tasks = [
        FrameTask(
            frame, dataset.path(frame["file"]), cache_dir / Path(frame["file"]).with_suffix(".npz"),
            cache_dir / Path(frame["file"]).with_suffix(".evidence.npz"), model, dataset.meta.get("board"),
            dataset.camera, tuple(methods), params, dataset.meta.get("ground_truth", "board"), exact_model_pose(dataset),
            robot_board_pose(dataset, model), tuple(dataset.meta.get("handover_boards") or ()), consensus,
        )
        for dataset, cache_dir, model in zip(datasets, cache_dirs, models)
        for frame in dataset.frames.assign(world=dataset.meta["world"], trajectory=dataset.meta["trajectory"])
            .to_dict("records")
    ]
    counted = workers.map(partial(tallied, frame_rows), tasks, desc=f"frames of {len(datasets)} dataset(s)",
                          progress=progress)
    results = [result for result, _ in counted]
    tallies = {dataset.name: tally for dataset, (_, tally) in zip(datasets, stored)}
    for task, (_, tally) in zip(tasks, counted):
        tallies[task.frame["dataset"]] += tally
    if progress:
        print(cache_report(tallies, unfinished), flush=True)
    rows = []
    for dataset in datasets:
        mine = [k for k, task in enumerate(tasks) if task.frame["dataset"] == dataset.name]
        rows += handed_over_rows([tasks[k] for k in mine], [results[k] for k in mine], params)
    table = pd.DataFrame(rows)
    return table.join(stop_spread(table)) if rows else table


def cache_report(tallies: dict[str, Counter], unfinished: dict[str, int]) -> str:
    """The lines a stage prints about its cache files (:mod:`poseintegrity.cache_entry`): one per dataset where any
    file was computed (or a killed run's unfinished write removed), then the total."""
    lines = [f"cache of {name}: {describe(tally)}" + (f"; {unfinished[name]} unfinished write(s) of a stopped run "
                                                      f"removed" if unfinished[name] else "")
             for name, tally in tallies.items()
             if unfinished[name] or set(tally) - {"checked"}]
    return "\n".join([*lines, f"cache of {len(tallies)} dataset(s): {describe(sum(tallies.values(), Counter()))}"])


def robot_board_pose(dataset: Dataset, model: StoredModel) -> np.ndarray | None:
    """T_base_board (4, 4, mm) of :mod:`kinematic_consistency`: the pose that placed M_t (the board's in model image
    0, or meta.json's T_cam0_ref with recorded poses) carried into the robot's base frame by the model view's robot
    pose; None when the dataset holds no robot poses."""
    robot = dataset.meta["model"].get("T_base_cam_robot")
    if robot is None:
        return None
    placed = (dataset.meta["model"]["T_cam0_ref"] if dataset.meta.get("ground_truth", "board") == "poses"
              else model.anchor.T_cam_board)
    return np.asarray(robot[0], dtype=np.float64) @ np.asarray(placed, dtype=np.float64)


def exact_model_pose(dataset: Dataset) -> np.ndarray | None:
    """Model image 0's exact board pose (4, 4, mm) when the dataset has one (rendered data), else None."""
    exact = dataset.meta["model"].get("exact_T_cam_board")
    return None if exact is None else np.asarray(exact[0], dtype=np.float64).reshape(4, 4)


def _cache_root(data_dir: Path, params: ExtractParams) -> Path:
    return Path(data_dir) / params.features_dir  # an absolute features_dir stays as it is


def extract_dataset(
    data_dir: str | Path, folder: str | Path, params: ExtractParams, methods: list[str], workers: Workers,
    progress: bool = True, consensus: bool = True,
) -> pd.DataFrame:
    """Artifact rows (one per frame and method) of the dataset in ``data_dir/folder`` (checked on read)."""
    return extract_datasets([load_dataset(data_dir, folder)], params, methods, workers, progress, consensus)


def extract_all(
    data_dir: str | Path, params: ExtractParams, methods: list[str], workers: Workers, progress: bool = True,
    consensus: bool = True,
) -> pd.DataFrame:
    """Artifact rows of every dataset of ``data_dir/datasets/index.parquet`` (or of ``params.datasets``), in index
    order. Every dataset is checked before any work (:mod:`~poseintegrity.localization.dataset`)."""
    index = load_index(data_dir)
    if params.datasets is not None:
        unknown = sorted(set(params.datasets) - set(index["dataset"]))
        if unknown:
            raise DatasetError(f"extract.datasets names datasets {unknown} that are not in the index; "
                               f"known: {sorted(index['dataset'])}")
        index = index[index["dataset"].isin(params.datasets)]
    datasets = [load_dataset(data_dir, row.path, row.dataset) for row in index.itertuples()]
    return extract_datasets(datasets, params, methods, workers, progress, consensus)
