"""Stage 01: write the robot datasets of Windsor et al. IV-D to disk.

Layout of ``<root>/<dataset>/``: ``meta.json`` (scene, targets, trajectory, intrinsics, board, model pair),
``frames.parquet`` (one row per image: stop, image, theta_deg, x_mm, file, T_cam_board, T_cam_target as
row-major 16-float lists), ``model/`` (the two model images and their target masks) and ``images/``.
A dataset is written into a hidden temporary folder and renamed when complete, so an interrupted run leaves
nothing that looks finished; ``<root>/index.parquet`` is written last.
"""

from __future__ import annotations

import json
import shutil
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from tqdm.auto import tqdm

from poseintegrity.protocol import ProtocolParams
from poseintegrity.scenes import catalog, renderer, trajectories
from poseintegrity.scenes.camera import Intrinsics, defocus_sigma_px, inverse
from poseintegrity.scenes.params import GenerateParams
from poseintegrity.scenes.textures import build_atlas

PNG_FLAGS = [cv2.IMWRITE_PNG_COMPRESSION, 3]


@dataclass(frozen=True)
class DatasetPlan:
    """One dataset to render: ``trajectory`` is "arc" (``azimuth_deg``) or "line" (``offset_deg``)."""

    dataset: str
    scene_index: int
    trajectory: str
    azimuth_deg: float
    offset_deg: float


def plan_datasets(params: GenerateParams) -> list[DatasetPlan]:
    """Arcs: every scene x every azimuth; lines: every offset on ``lines.scene`` (IV-D)."""
    plans = [DatasetPlan(f"{spec.name}_arc{az:03.0f}", i, "arc", az, 0.0)
             for i, spec in enumerate(params.scenes) for az in params.arcs.azimuths_deg]
    if params.lines is not None:
        i = [s.name for s in params.scenes].index(params.lines.scene)
        plans += [DatasetPlan(f"{params.lines.scene}_line{off:02.0f}", i, "line", 0.0, off)
                  for off in params.lines.offsets_deg]
    return plans


@dataclass(frozen=True)
class _World:
    scene: catalog.Scene
    geometry: renderer.SceneGeometry
    target_ids: np.ndarray


_WORLDS: dict[tuple[str, int], _World] = {}


MIN_TARGET_IN_VIEW = 0.5  # share of a target's vertices that must project inside the model images
MIN_TARGET_AREA = 0.005  # share of the image its projected bounding box must cover (not a speck)


class WorldError(ValueError):
    """A scene cannot give the datasets: its target would leave (or vanish from) the model view."""


def check_world(params: GenerateParams) -> None:
    """Stop before any rendering, naming the key, when a scene cannot be rendered as the protocol needs: every
    scene is built (an unreadable mesh or a hole outside the bone raises :class:`~.scapula.MeshError` here) and each
    target must lie mostly inside both model views of its arcs and, for the lines' scene, of the lines' model pair
    (a mesh scaled far too large or too small, or a distance that puts the target out of the picture)."""
    cam = Intrinsics.from_params(params.camera)
    for index, spec in enumerate(params.scenes):
        scene = catalog.build_scene(spec, index, params)
        distances = [spec.distance_mm]
        if params.lines is not None and params.lines.scene == spec.name:
            distances.append(params.lines.distance_mm)
        for distance in distances:
            for T_world_cam in trajectories.model_pair(scene.aim, scene.view_dir, distance, params.model_baseline_mm):
                T_cam_world = inverse(T_world_cam)
                for name, mesh in scene.placed:
                    if name in scene.target_objects:
                        _check_in_view(mesh.vertices @ T_cam_world[:3, :3].T + T_cam_world[:3, 3], cam, index, name,
                                       distance)


def _check_in_view(points_cam: np.ndarray, cam: Intrinsics, index: int, name: str, distance: float) -> None:
    """WorldError unless most of points_cam (n, 3, mm) project inside the image and their extent is not a speck."""
    z = points_cam[:, 2]
    safe = np.where(z > renderer.NEAR_MM, z, np.nan)
    u = cam.K[0, 0] * points_cam[:, 0] / safe + cam.K[0, 2]
    v = cam.K[1, 1] * points_cam[:, 1] / safe + cam.K[1, 2]
    inside = (u >= 0) & (u <= cam.width - 1) & (v >= 0) & (v <= cam.height - 1)
    hint = (f"check generate.scenes.{index}.distance_mm ({distance:g} mm)"
            + (" and generate.scapula.length_mm" if name.startswith("scapula") else ""))
    if inside.mean() < MIN_TARGET_IN_VIEW:
        raise WorldError(f"generate.scenes.{index}: only {inside.mean():.0%} of target {name} lies inside the "
                         f"{cam.width} x {cam.height} model image: it leaves the view; {hint}")
    area = np.ptp(u[inside]) * np.ptp(v[inside]) / (cam.width * cam.height)
    if area < MIN_TARGET_AREA:
        raise WorldError(f"generate.scenes.{index}: target {name} covers {area:.2%} of the model image: too small "
                         f"to be seen; {hint}")


def _world(params: GenerateParams, scene_index: int) -> _World:
    """The scene and its renderable geometry, built once per process and scene."""
    key = (params.model_dump_json(), scene_index)
    if key not in _WORLDS:
        _WORLDS.clear()
        _WORLDS[key] = _build_world(params, scene_index)
    return _WORLDS[key]


def _build_world(params: GenerateParams, scene_index: int) -> _World:
    scene = catalog.build_scene(params.scenes[scene_index], scene_index, params)
    geometry = renderer.SceneGeometry.from_meshes(scene.placed, build_atlas(scene.textures), scene.light_dir,
                                                  params.lights.intensities(), params.bone_foam.relief(params.seed))
    target_ids = np.array([i for i, name in enumerate(geometry.object_names) if name in scene.target_objects])
    return _World(scene, geometry, target_ids)


def _flat(T: np.ndarray) -> list[float]:
    return [float(v) for v in T.ravel()]


def write_dataset(params: GenerateParams, protocol: ProtocolParams, plan: DatasetPlan, root: Path) -> dict:
    """Render one dataset into ``root / plan.dataset`` (its trajectory spans ``protocol``'s range); returns its row
    of the index."""
    world = _world(params, plan.scene_index)
    spec = params.scenes[plan.scene_index]
    cam = Intrinsics.from_params(params.camera)
    scene = world.scene
    # the straight lines have their own model pair (IV-D), closer to the target: the robot backs away from it
    distance_mm = spec.distance_mm if plan.trajectory == "arc" else params.lines.distance_mm
    model_views = trajectories.model_pair(scene.aim, scene.view_dir, distance_mm, params.model_baseline_mm)
    if plan.trajectory == "arc":
        stops = trajectories.arc(model_views[0], scene.aim, plan.azimuth_deg, protocol.arc_span_deg,
                                 params.arcs.n_stops)
    else:
        stops = trajectories.line(model_views[0], scene.aim, plan.offset_deg, protocol.line_length_mm,
                                  params.lines.n_stops)

    final = root / plan.dataset
    tmp = root / f".{plan.dataset}.partial"
    shutil.rmtree(tmp, ignore_errors=True)
    (tmp / "model").mkdir(parents=True)
    (tmp / "images").mkdir()

    def shoot(T_world_cam: np.ndarray, rng_key: tuple[int, ...], n: int) -> tuple[renderer.Render, list[np.ndarray]]:
        T_cam_world = inverse(T_world_cam)
        frame = renderer.render(world.geometry, cam.K, cam.width, cam.height, T_cam_world)
        depth_mm = (T_cam_world[:3, :3] @ scene.aim + T_cam_world[:3, 3])[2]
        defocus = defocus_sigma_px(depth_mm, distance_mm, params.camera)  # focused at the model view
        irradiance = renderer.optics(frame.radiance, params.sensor, defocus)  # the robot is still: one image
        images = [renderer.expose(irradiance, params.sensor, np.random.default_rng([params.seed, *rng_key, i]))
                  for i in range(n)]
        return frame, images

    model = {"images": [], "masks": [], "T_cam_board": [], "T_cam_target": []}
    for k, T_world_cam in enumerate(model_views):
        # model images depend on the scene and trajectory kind only: datasets sharing them share them byte for byte
        frame, (image,) = shoot(T_world_cam, (plan.scene_index, 1000 + k + 10 * (plan.trajectory == "line")), 1)
        mask = np.isin(frame.object_index, world.target_ids).astype(np.uint8) * 255
        cv2.imwrite(str(tmp / f"model/model_{k}.png"), image, PNG_FLAGS)
        cv2.imwrite(str(tmp / f"model/mask_{k}.png"), mask, PNG_FLAGS)
        T_cam_world = inverse(T_world_cam)
        model["images"].append(f"model/model_{k}.png")
        model["masks"].append(f"model/mask_{k}.png")
        model["T_cam_board"].append((T_cam_world @ scene.T_world_board).tolist())
        model["T_cam_target"].append((T_cam_world @ scene.T_world_target).tolist())

    dataset_index = [p.dataset for p in plan_datasets(params)].index(plan.dataset)
    rows = []
    for s, stop in enumerate(stops):
        _, images = shoot(stop.T_world_cam, (dataset_index, s), params.images_per_stop)
        T_cam_world = inverse(stop.T_world_cam)
        for i, image in enumerate(images):
            file = f"images/s{s:02d}_i{i:02d}.png"
            cv2.imwrite(str(tmp / file), image, PNG_FLAGS)
            rows.append({"dataset": plan.dataset, "stop": s, "image": i, "theta_deg": stop.theta_deg,
                         "x_mm": stop.x_mm, "file": file, "T_cam_board": _flat(T_cam_world @ scene.T_world_board),
                         "T_cam_target": _flat(T_cam_world @ scene.T_world_target)})
    pd.DataFrame(rows).to_parquet(tmp / "frames.parquet", index=False)
    meta = {
        "dataset": plan.dataset, "scene": spec.name, "targets": list(spec.targets), "trajectory": plan.trajectory,
        "azimuth_deg": plan.azimuth_deg, "offset_deg": plan.offset_deg, "n_stops": len(stops),
        "images_per_stop": params.images_per_stop, "image_size": [cam.width, cam.height], "K": cam.K.tolist(),
        "dist": [0.0] * 5, "board": scene.board.as_dict(), "model": model,
        "model_baseline_mm": params.model_baseline_mm, "distance_mm": distance_mm,
    }
    (tmp / "meta.json").write_text(json.dumps(meta, indent=1))
    shutil.rmtree(final, ignore_errors=True)
    tmp.rename(final)
    return {"dataset": plan.dataset, "scene": spec.name, "trajectory": plan.trajectory,
            "azimuth_deg": plan.azimuth_deg, "offset_deg": plan.offset_deg, "n_frames": len(rows),
            "path": f"datasets/{plan.dataset}"}


def generate(params: GenerateParams, protocol: ProtocolParams, root: Path, progress: bool = True) -> pd.DataFrame:
    """Render every planned dataset under ``root`` (in parallel, ``params.n_jobs``) after :func:`check_world`;
    returns and writes the index."""
    check_world(params)
    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    (root / "index.parquet").unlink(missing_ok=True)
    plans = plan_datasets(params)
    # datasets of one scene go to the same worker in sequence, so it builds each scene once
    plans_sorted = sorted(plans, key=lambda p: p.scene_index)
    jobs = Parallel(n_jobs=params.n_jobs, return_as="generator")(
        delayed(write_dataset)(params, protocol, plan, root) for plan in plans_sorted)
    rows = list(tqdm(jobs, total=len(plans), desc="datasets", disable=not progress))
    index = pd.DataFrame(rows).set_index("dataset").loc[[p.dataset for p in plans]].reset_index()
    index.to_parquet(root / "index.parquet", index=False)
    return index
