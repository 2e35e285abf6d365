"""Stage 02/05 driver: every frame of a dataset through the localization pipeline, one row per PnP method.

Per dataset: M_t from the two model images (III-B); per frame (in parallel with joblib, cached features):
CLAHE + SIFT -> ratio-test matches to M_t -> PnP-RANSAC per method -> artifacts, E_t/E_r against the exact
renderer pose and against the ArUco board pose (IV-C).
"""

from __future__ import annotations

import zlib
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from tqdm.auto import tqdm

from poseintegrity.localization.frame_artifacts import frame_artifacts
from poseintegrity.localization.dataset import Dataset, load_dataset, load_index
from poseintegrity.localization.errors import pose_errors
from poseintegrity.localization.features import Features, cached_features, read_gray
from poseintegrity.localization.ground_truth import board_pose, make_board
from poseintegrity.localization.matching import match_ratio_test
from poseintegrity.localization.params import ExtractParams
from poseintegrity.localization.pnp import solve_pnp_ransac
from poseintegrity.localization.target_model import TargetModel, build_target_model

FRAME_COLUMNS = ["dataset", "trajectory", "stop", "image", "theta_deg", "x_mm"]


def frame_seed(seed: int, dataset: str, stop: int, image: int) -> int:
    """RANSAC seed of one frame, drawn from a Generator seeded by (params seed, dataset, stop, image)."""
    rng = np.random.default_rng([seed, zlib.crc32(dataset.encode()), stop, image])
    return int(rng.integers(0, 2**31 - 1))


def correspondences(features: Features, model: TargetModel, ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """2D-3D correspondences of a frame: ratio-test matches of its descriptors to M_t (III-B).

    Returns object points (k, 3, board frame, mm) and image points (k, 2, px).
    """
    pairs = match_ratio_test(features.descriptors, model.descriptors, ratio)
    return model.points[pairs[:, 1]], features.points[pairs[:, 0]].astype(np.float64)


def localize(
    object_points: np.ndarray, image_points: np.ndarray, n_keypoints: int, model_size: int, K: np.ndarray,
    method: str, params: ExtractParams, seed: int,
) -> tuple[np.ndarray, dict[str, Any], str]:
    """PnP-RANSAC of one frame's correspondences with one method: (T_cam_board estimate (4, 4), artifacts, status).

    Status "no_keypoints" when SIFT found nothing, else the PnP status ("too_few_matches", ...).
    """
    max_iterations = params.usac_max_iterations if method == "usac_magsac" else params.ransac_max_iterations
    result = solve_pnp_ransac(
        object_points, image_points, K, method, params.reprojection_threshold_px, params.ransac_confidence,
        max_iterations, seed, params.usac_refine_lm,
    )
    status = "no_keypoints" if n_keypoints == 0 else result.status
    artifacts = frame_artifacts(result, object_points, image_points, K, n_keypoints, model_size)
    return result.T_cam_model, artifacts, status


def _frame_rows(
    frame: dict[str, Any], image_path: Path, cache_path: Path, model: TargetModel, board: dict[str, Any],
    K: np.ndarray, methods: list[str], params: ExtractParams,
) -> list[dict[str, Any]]:
    """All rows (one per method) of one frame; runs in a joblib worker."""
    features = cached_features(image_path, cache_path, params.clahe, params.sift)
    T_cam_board = np.asarray(frame["T_cam_board"], dtype=np.float64).reshape(4, 4)
    aruco = board_pose(read_gray(image_path), make_board(board), K)
    E_t_board_exact_mm, E_r_board_exact_deg = pose_errors(aruco.T_cam_board, T_cam_board)
    seed = frame_seed(params.seed, frame["dataset"], int(frame["stop"]), int(frame["image"]))
    object_points, image_points = correspondences(features, model, params.ratio_test)
    rows = []
    for method in methods:
        T_est, artifacts, status = localize(
            object_points, image_points, features.n_keypoints, model.size, K, method, params, seed
        )
        E_t_mm, E_r_deg = pose_errors(T_est, T_cam_board)
        E_t_board_mm, E_r_board_deg = pose_errors(T_est, aruco.T_cam_board)
        rows.append(
            {key: frame[key] for key in FRAME_COLUMNS}
            | dict(method=method, status=status, model_size=model.size)
            | artifacts
            | dict(
                E_t_mm=E_t_mm, E_r_deg=E_r_deg, E_t_board_mm=E_t_board_mm, E_r_board_deg=E_r_board_deg,
                board_status=aruco.status, board_n_markers=aruco.n_markers,
                E_t_board_exact_mm=E_t_board_exact_mm, E_r_board_exact_deg=E_r_board_exact_deg,
                T_cam_board_est=T_est.ravel().tolist(),
            )
        )
    return rows


def dataset_model(dataset: Dataset, params: ExtractParams, cache_dir: Path) -> TargetModel:
    """M_t of a dataset from its two model images (features cached like frames)."""
    model = dataset.meta["model"]
    features = tuple(
        cached_features(dataset.path(image), cache_dir / "model" / f"{index}.npz", params.clahe, params.sift)
        for index, image in enumerate(model["images"])
    )
    masks = tuple(read_gray(dataset.path(mask)) for mask in model["masks"])
    return build_target_model(
        features, masks, dataset.model_T_cam_board(), dataset.K, params.ratio_test, params.model_max_reprojection_px
    )


def extract_dataset(
    data_dir: str | Path, folder: str | Path, params: ExtractParams, methods: list[str], progress: bool = True
) -> pd.DataFrame:
    """Artifact rows (one per frame and method) of the dataset in ``data_dir/folder``.

    Raises :class:`~poseintegrity.localization.features.ImageReadError` naming the file when an image is
    missing or unreadable; every other failure is a row status.
    """
    dataset = load_dataset(data_dir, folder)
    dataset.check_images()
    cache_dir = Path(data_dir) / params.features_dir / dataset.name
    model = dataset_model(dataset, params, cache_dir)
    frames = dataset.frames.assign(trajectory=dataset.meta["trajectory"]).to_dict("records")
    tasks = (
        delayed(_frame_rows)(
            frame, dataset.path(frame["file"]), cache_dir / Path(frame["file"]).with_suffix(".npz"), model,
            dataset.meta["board"], dataset.K, methods, params,
        )
        for frame in frames
    )
    results = Parallel(n_jobs=params.n_jobs, return_as="generator")(tasks)
    rows = [row for frame_rows in tqdm(results, total=len(frames), desc=dataset.name, disable=not progress) for row in frame_rows]
    return pd.DataFrame(rows)


def extract_all(data_dir: str | Path, params: ExtractParams, methods: list[str], progress: bool = True) -> pd.DataFrame:
    """Artifact rows of every dataset in ``data_dir/datasets/index.parquet`` (or of ``params.datasets``)."""
    index = load_index(data_dir)
    if params.datasets is not None:
        unknown = sorted(set(params.datasets) - set(index["dataset"]))
        if unknown:
            raise ValueError(f"extract.datasets names unknown datasets {unknown}; known: {sorted(index['dataset'])}")
        index = index[index["dataset"].isin(params.datasets)]
    tables = [extract_dataset(data_dir, row.path, params, methods, progress) for row in index.itertuples()]
    return pd.concat(tables, ignore_index=True)
