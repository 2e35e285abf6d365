"""Which part of the target model makes an arc's poses wrong (issue 38: the deciding arcs of the error predictors)?

A wrong pose with many inliers (val_2_arc270 fails at 11.7 deg with 34 inliers, its measured E_t 3-4.5 x the predicted
sigma_t) can come from a coherent error of M_t, which the per-point triangulation covariances do not carry: the
baseline the robot reports for the model pair (its error: a 20 mm move errs by ~0.05 mm, docs/references.md "Robot"),
the board pose that places M_t in the board frame (IV-C), or the calibrated camera. Or it comes from the points' own
triangulation noise, which the covariances carry. This study rebuilds M_t of one dataset with each coherent source
replaced by its exact value (rendered data only: meta.json's ``model.exact_T_cam_board``, the world's true camera),
localizes the same frames again as stage 02 does (same features, matching, USAC seed and iteration cap), and prints,
per stop and variant, the mean inlier count, the mean E_t (mm) and E_r (deg) against the exact pose, and the predicted
sigma_t (conditioned on the inlier test, and not). If E_t does not fall when a source is exact, that source is not the
cause.

    .venv/bin/python studies/model_error_sources.py val_2_arc270 [--stops 0-10] [--world validation]
        [--params params.yaml] [--data data]

``--world`` names the world whose true camera (``generate``'s camera section) is the exact camera; without it the
exact-camera variant is left out.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import poseintegrity  # noqa: F401  (first: it pins the CPU dispatch before numpy loads)
import numpy as np
import pandas as pd

from poseintegrity.config import load_params
from poseintegrity.errors import ArgumentError
from poseintegrity.lens import Camera
from poseintegrity.localization.dataset import Dataset, load_dataset, load_index
from poseintegrity.localization.evidence import correspondences
from poseintegrity.localization.extract import _cache_root
from poseintegrity.localization.features import cached_features, read_gray
from poseintegrity.localization.frame_rows import frame_seed, iteration_cap
from poseintegrity.localization.model_store import dataset_model
from poseintegrity.localization.pnp import solve_checked
from poseintegrity.localization.pose_covariance import propagated_covariance
from poseintegrity.localization.target_model import TargetModel, build_target_model
from poseintegrity.params.extract import ExtractParams
from poseintegrity.poses import pose_errors
from poseintegrity.scenes.camera import true_camera

METHOD = "usac_magsac"  # the paper's path (protocol.pnp_method)


def variants(dataset: Dataset, params: ExtractParams, exact_camera: Camera | None
             ) -> dict[str, tuple[TargetModel, Camera]]:
    """M_t of ``dataset`` as stage 02 builds it, and with the baseline, then also the anchor, then also the camera
    exact (the last only with ``exact_camera``); each with the camera the frames' keypoints are undistorted by."""
    model = dataset.meta["model"]
    exact = model.get("exact_T_cam_board")
    if not exact:
        raise ArgumentError(f"dataset {dataset.name}: meta.json has no model.exact_T_cam_board (rendered data only)")
    T_cam0_board, T_cam1_board = (np.asarray(T, dtype=np.float64) for T in exact[:2])
    cache = _cache_root(dataset.data_dir, params) / dataset.name / "model"
    images = [read_gray(dataset.path(name), dataset.image_size) for name in model["images"]]
    masks = tuple(read_gray(dataset.path(name), dataset.image_size) for name in model["masks"])
    features = tuple(cached_features(dataset.path(name), cache / f"{k}.npz", params.clahe, params.sift, image=image)
                     for k, (name, image) in enumerate(zip(model["images"], images)))
    stage_02, anchor = dataset_model(dataset, params, cache.parent)
    exact_baseline = T_cam1_board @ np.linalg.inv(T_cam0_board)

    def built(T_cam1_cam0: np.ndarray, T_cam0_b: np.ndarray, camera: Camera) -> tuple[TargetModel, Camera]:
        return build_target_model(features, masks, T_cam1_cam0, T_cam0_b, camera, params.ratio_test,
                                  params.model_max_reprojection_px), camera

    out = {
        "stage 02": (stage_02, dataset.camera),
        "exact baseline": built(exact_baseline, anchor.T_cam_board, dataset.camera),
        "exact baseline, anchor": built(exact_baseline, T_cam0_board, dataset.camera),
    }
    if exact_camera is not None:
        out["exact baseline, anchor, camera"] = built(exact_baseline, T_cam0_board, exact_camera)
    return out


def localized(dataset: Dataset, stops: range, M_t: TargetModel, camera: Camera, params: ExtractParams) -> pd.DataFrame:
    """One row per frame of ``stops``: stop, theta_deg, n_inliers, E_t_mm, E_r_deg (against the exact pose),
    sigma_t_pred_mm and sigma_t_unconditioned_mm, localized with M_t as stage 02 does (NaN without a pose)."""
    cache = _cache_root(dataset.data_dir, params) / dataset.name / "images"
    rows = []
    for frame in dataset.frames[dataset.frames.stop.isin(list(stops))].itertuples():
        features = cached_features(dataset.path(frame.file), cache / f"{Path(frame.file).stem}.npz", params.clahe,
                                   params.sift)
        index, image_points = correspondences(features, M_t, params.ratio_test, camera)
        seed = frame_seed(params.seed, dataset.name, int(frame.stop), int(frame.image))
        result = solve_checked(M_t.points[index], image_points, camera.K, METHOD, params.reprojection_threshold_px,
                               params.ransac_confidence, iteration_cap(METHOD, params), seed, params.usac_refine_lm)
        row = dict(stop=frame.stop, theta_deg=frame.theta_deg, n_inliers=0, E_t_mm=np.nan, E_r_deg=np.nan,
                   sigma_t_pred_mm=np.nan, sigma_t_unconditioned_mm=np.nan)
        if result.status == "ok":
            inliers = index[result.inliers]
            E_t, E_r = pose_errors(result.T_cam_model, np.asarray(frame.T_cam_board, dtype=np.float64).reshape(4, 4))
            covariance = propagated_covariance(M_t.points[inliers], image_points[result.inliers], result.T_cam_model,
                                               camera.K, M_t.covariances[inliers], None,
                                               params.reprojection_threshold_px)
            row |= dict(n_inliers=len(inliers), E_t_mm=float(E_t), E_r_deg=float(E_r),
                        sigma_t_pred_mm=covariance.sigma_t_mm(),
                        sigma_t_unconditioned_mm=covariance.sigma_t_mm("unconditioned"))
        rows.append(row)
    return pd.DataFrame(rows)


def study(data_dir: Path, name: str, stops: range, params: ExtractParams, exact_camera: Camera | None) -> pd.DataFrame:
    """Per variant and stop: the means of :func:`localized`'s columns over the stop's frames."""
    index = load_index(data_dir)
    if name not in set(index.dataset):
        raise ArgumentError(f"dataset: {name!r} is not in {data_dir}/datasets/index.parquet")
    dataset = load_dataset(data_dir, index.set_index("dataset").loc[name, "path"], name)
    return pd.concat({variant: localized(dataset, stops, M_t, camera, params).groupby("stop").mean()
                      for variant, (M_t, camera) in variants(dataset, params, exact_camera).items()}, names=["variant"])


def _stops(text: str) -> range:
    first, _, last = text.partition("-")
    return range(int(first), int(last or first) + 1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dataset")
    parser.add_argument("--stops", type=_stops, default=_stops("0-10"), help="first-last stop, e.g. 0-10")
    parser.add_argument("--world", help="the world whose true camera is the exact one (main, validation, ...)")
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument("--data", type=Path, default=Path("data"))
    args = parser.parse_args()
    params = load_params(args.params)
    camera = None
    if args.world is not None:
        worlds = params.generate.worlds()
        if args.world not in worlds:
            raise SystemExit(f"--world: {args.world!r} is not one of {sorted(worlds)}")
        camera = true_camera(worlds[args.world].camera)
    table = study(args.data, args.dataset, args.stops, params.extract, camera)
    print(table.unstack("variant")[["n_inliers", "E_t_mm", "E_r_deg", "sigma_t_pred_mm"]].round(2).to_string())


if __name__ == "__main__":
    main()
