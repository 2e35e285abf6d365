"""What a dataset holds besides its images, written once they are (:func:`finish_dataset`): ``frames.parquet``,
``meta.json`` (checked against what stage 02 reads, :func:`check_meta`) and ``camera.yaml``; then its partial folder
is renamed to the dataset's.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
from pydantic import ValidationError

from poseintegrity.dataset_meta import DatasetError, Meta
from poseintegrity.lens import Camera, write_camera_yaml
from poseintegrity.params.generate import GenerateParams
from poseintegrity.poses import inverse
from poseintegrity.scenes import catalog
from poseintegrity.scenes.acquisition import Route, image_motion, image_pose, model_motion
from poseintegrity.scenes.camera import true_camera
from poseintegrity.scenes.shots import image_files, partial_dataset
from poseintegrity.scenes.trips import DatasetPlan, Trip

CAMERA_NAME = "ids_u3_3060cp"  # camera.yaml's camera_name


def _flat(T: np.ndarray) -> list[float]:
    """A pose (4, 4) as 16 row-major floats (a frames.parquet cell)."""
    return [float(v) for v in T.ravel()]


def check_meta(meta: dict, dataset: str) -> None:
    """:class:`~poseintegrity.dataset_meta.DatasetError` naming the dataset and the field unless ``meta``
    holds what stage 02 reads from meta.json (:class:`~poseintegrity.dataset_meta.Meta`: an ArUco dictionary
    OpenCV knows, a rigid model baseline, ...): stage 01 never writes a dataset stage 02 would refuse."""
    try:
        Meta.model_validate(meta)
    except ValidationError as error:
        lines = [f"  {'.'.join(map(str, item['loc']))}: {item['msg']}" for item in error.errors()]
        raise DatasetError(f"dataset {dataset}: its meta.json would have invalid values:\n" + "\n".join(lines)) from None


def trajectory_index(params: GenerateParams, plan: DatasetPlan) -> int:
    """The index of a dataset's trajectory in its session (``arcs.azimuths_deg`` or ``lines.offsets_deg``), which
    names its board (:meth:`~.catalog.Scene.board_for`)."""
    if plan.trajectory == "arc":
        return params.arcs.azimuths_deg.index(plan.azimuth_deg)
    return params.lines.offsets_deg.index(plan.offset_deg)


def finish_dataset(params: GenerateParams, root: Path, plan: DatasetPlan, trip: Trip, route: Route,
                   scene: catalog.Scene, camera: Camera) -> dict:
    """Once its images are written: the dataset's frames.parquet, meta.json and camera.yaml (``camera``: the world's
    calibration estimate), then its partial folder renamed to ``root / plan.dataset``; returns its row of the index.
    The dataset's ground truth is its trajectory's board (:meth:`~.catalog.Scene.board_for`); the scene's other
    boards are its handover boards."""
    spec = params.scenes[plan.scene_index]
    board = scene.board_for(trajectory_index(params, plan))
    # the scene's other boards judge the frames this board cannot (a handover; stage 02 takes one only where it is
    # trusted in model image 0)
    others = [b.board.as_dict() for b in scene.boards if b is not board]
    truth = true_camera(params.camera)
    f_px = truth.K[0, 0]
    tmp, final = partial_dataset(root, plan.dataset), root / plan.dataset
    model_poses = [image_pose(visit, model_motion(visit, params.capture, f_px)) for visit in route.model]
    T_cam1_cam0 = inverse(trip.model_views[1]) @ trip.model_views[0]  # what the robot says it did (III-B)
    model = {
        "images": [f"model/model_{k}.png" for k in range(len(route.model))],
        "masks": [f"model/mask_{k}.png" for k in range(len(route.model))],
        "T_cam1_cam0": T_cam1_cam0.tolist(),
        "exact_T_cam_board": [(inverse(T) @ board.T_world_board).tolist() for T in model_poses],
        # the robot's log: the commanded poses its controller reports (its encoders would add the joints'
        # repeatability, ~0.01 mm here; the world frame stands for its base frame: only relative poses are used)
        "T_base_cam_robot": [T.tolist() for T in trip.model_views],
    }
    rows = []
    for s, (stop, visit) in enumerate(zip(trip.stops, route.stops)):
        for i, file in enumerate(image_files(s, params.images_per_stop)):
            T_cam_world = inverse(image_pose(visit, image_motion(visit, params.capture, i, f_px)))
            rows.append({"dataset": plan.dataset, "stop": s, "image": i, "theta_deg": stop.theta_deg,
                         "x_mm": stop.x_mm, "file": file, "T_cam_board": _flat(T_cam_world @ board.T_world_board),
                         "T_base_cam_robot": _flat(stop.T_world_cam),
                         "T_cam_target": _flat(T_cam_world @ scene.T_world_target)})
    pd.DataFrame(rows).to_parquet(tmp / "frames.parquet", index=False)
    meta = {
        "dataset": plan.dataset, "world": plan.world, "scene": spec.name, "targets": list(spec.targets),
        "trajectory": plan.trajectory, "azimuth_deg": plan.azimuth_deg, "offset_deg": plan.offset_deg,
        "n_stops": len(trip.stops), "images_per_stop": params.images_per_stop,
        "board": board.board.as_dict(), "handover_boards": others, "model": model, "model_baseline_mm": params.model_baseline_mm,
        "distance_mm": trip.distance_mm,
        "true_camera": {"K": truth.K.tolist(), "dist": truth.dist.tolist()},  # a diagnostic: stage 02 never reads it
    }
    check_meta(meta, plan.dataset)
    (tmp / "meta.json").write_text(json.dumps(meta, indent=1))
    write_camera_yaml(tmp / "camera.yaml", camera, CAMERA_NAME)
    shutil.rmtree(final, ignore_errors=True)
    tmp.rename(final)
    return {"dataset": plan.dataset, "world": plan.world, "scene": spec.name, "trajectory": plan.trajectory,
            "azimuth_deg": plan.azimuth_deg, "offset_deg": plan.offset_deg, "n_frames": len(rows),
            "path": f"datasets/{plan.dataset}"}
