"""Stage 01: write the robot datasets of Windsor et al. IV-D to disk.

Layout of ``<root>/<dataset>/``: ``meta.json`` (scene, targets, trajectory, intrinsics, board, model pair),
``frames.parquet`` (one row per image: stop, image, theta_deg, x_mm, file, T_cam_board, T_cam_target as
row-major 16-float lists), ``model/`` (the two model images and their target masks) and ``images/``.
A dataset is written into a hidden temporary folder and renamed when complete, so an interrupted run leaves
nothing that looks finished; ``<root>/index.parquet`` is written last.

The work is split into :class:`Shot` tasks, one per distinct camera pose of a scene, run by
:class:`poseintegrity.parallel.Workers`: a shot renders its pose once and writes every image taken there. Poses
that several datasets share are rendered once: a scene's model pair serves all its arcs (and the lines theirs),
and an arc's first stop is its model view (IV-D: the robot returns to it). Every image draws its noise from its
own generator, keyed by ``generate.seed`` and what the image is, so the files do not depend on the backend, the
worker count or the order the shots run in.
"""

from __future__ import annotations

import json
import shutil
from collections import OrderedDict
from dataclasses import dataclass
from functools import lru_cache, partial
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from poseintegrity.parallel import Workers
from poseintegrity.protocol import ProtocolParams
from poseintegrity.scenes import catalog, renderer, trajectories
from poseintegrity.poses import inverse
from poseintegrity.scenes.camera import Intrinsics, defocus_sigma_px
from poseintegrity.scenes.foam import ReliefVolume
from poseintegrity.scenes.params import BoneFoamParams, GenerateParams
from poseintegrity.scenes.textures import build_atlas

# Camera images are noisy: deflate's string matching finds almost nothing in them, so they are Huffman-coded only,
# after PNG's "average" filter (the prediction residuals are what is compressible): ~3 x faster to encode and ~12 %
# smaller than zlib level 3 with adaptive filters. Masks are flat: there string matching is what compresses.
IMAGE_PNG_FLAGS = [cv2.IMWRITE_PNG_STRATEGY, cv2.IMWRITE_PNG_STRATEGY_HUFFMAN_ONLY,
                   cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_AVG]
MASK_PNG_FLAGS = [cv2.IMWRITE_PNG_COMPRESSION, 3]
MIN_TARGET_IN_VIEW = 0.5  # share of a target's vertices that must project inside the model images
MIN_TARGET_AREA = 0.005  # share of the image its projected bounding box must cover (not a speck)


@dataclass(frozen=True)
class DatasetPlan:
    """One dataset to render: ``trajectory`` is "arc" (``azimuth_deg``) or "line" (``offset_deg``)."""

    dataset: str
    scene_index: int
    trajectory: str
    azimuth_deg: float
    offset_deg: float


def plan_datasets(params: GenerateParams) -> list[DatasetPlan]:
    """Arcs: every scene x every azimuth; lines: every offset on ``lines.scene`` (IV-D). The ids are
    :meth:`GenerateParams.dataset_ids` (validated distinct)."""
    plans = [DatasetPlan(dataset, i, "arc", az, 0.0) for i, spec in enumerate(params.scenes)
             for dataset, az in zip(params.arcs.dataset_ids(spec.name), params.arcs.azimuths_deg)]
    if params.lines is not None:
        i = [s.name for s in params.scenes].index(params.lines.scene)
        plans += [DatasetPlan(dataset, i, "line", 0.0, off)
                  for dataset, off in zip(params.lines.dataset_ids(), params.lines.offsets_deg)]
    return plans


@dataclass(frozen=True)
class Trip:
    """Where the camera of one dataset goes: its model pair (T_world_cam, the first is where the trajectory
    starts) at ``distance_mm`` from the aim point, and the stops of its trajectory."""

    distance_mm: float
    model_views: list[np.ndarray]
    stops: list[trajectories.Stop]


def plan_trip(params: GenerateParams, protocol: ProtocolParams, plan: DatasetPlan, scene: catalog.Scene) -> Trip:
    """The model pair and stops of ``plan`` in ``scene``; the trajectory spans ``protocol``'s range."""
    # the straight lines have their own model pair (IV-D), closer to the target: the robot backs away from it
    distance_mm = params.scenes[plan.scene_index].distance_mm if plan.trajectory == "arc" else params.lines.distance_mm
    model_views = trajectories.model_pair(scene.aim, scene.view_dir, distance_mm, params.model_baseline_mm)
    if plan.trajectory == "arc":
        stops = trajectories.arc(model_views[0], scene.aim, plan.azimuth_deg, protocol.arc_span_deg,
                                 params.arcs.n_stops)
    else:
        stops = trajectories.line(model_views[0], scene.aim, plan.offset_deg, protocol.line_length_mm,
                                  params.lines.n_stops)
    return Trip(distance_mm, model_views, stops)


class WorldError(ValueError):
    """A scene cannot give the datasets: its target would leave (or vanish from) the model view."""


def check_world(params: GenerateParams, protocol: ProtocolParams) -> list[catalog.Scene]:
    """Lay out every scene and stop before any rendering, naming the key, when one cannot be rendered as the
    protocol needs; returns the scenes. Every scene is built (an unreadable mesh or a hole outside the bone raises
    :class:`~.scapula.MeshError` here); each target must lie mostly inside both model views of its arcs and, for
    the lines' scene, of the lines' model pair (a mesh scaled far too large or too small, or a distance that puts
    the target out of the picture)."""
    cam = Intrinsics.from_params(params.camera)
    scenes = [catalog.build_scene(spec, index, params) for index, spec in enumerate(params.scenes)]
    for index, scene in enumerate(scenes):
        distances = [params.scenes[index].distance_mm]
        if params.lines is not None and params.lines.scene == scene.name:
            distances.append(params.lines.distance_mm)
        for distance in distances:
            for T_world_cam in trajectories.model_pair(scene.aim, scene.view_dir, distance, params.model_baseline_mm):
                T_cam_world = inverse(T_world_cam)
                for name, mesh in scene.placed:
                    if name in scene.target_objects:
                        _check_in_view(mesh.vertices @ T_cam_world[:3, :3].T + T_cam_world[:3, 3], cam, index, name,
                                       distance)
    return scenes


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


@dataclass(frozen=True)
class World:
    """A scene and its renderable geometry; ``target_ids`` index its targets in ``geometry.object_names``."""

    scene: catalog.Scene
    geometry: renderer.SceneGeometry
    target_ids: np.ndarray


_WORLDS: OrderedDict[tuple[str, int], World] = OrderedDict()
WORLDS_KEPT = 2  # per process: the shots of one scene run together, a worker seldom goes back to an earlier one


def world(params: GenerateParams, scene_index: int) -> World:
    """The scene and its renderable geometry, built once per process and scene (the last WORLDS_KEPT kept)."""
    key = (params.model_dump_json(), scene_index)
    if key not in _WORLDS:
        _WORLDS[key] = _build_world(params, scene_index)
        while len(_WORLDS) > WORLDS_KEPT:
            _WORLDS.popitem(last=False)
    _WORLDS.move_to_end(key)
    return _WORLDS[key]


@lru_cache(maxsize=1)
def _relief(bone_foam: BoneFoamParams, seed: int) -> ReliefVolume:
    """The foam's relief: one material, the same in every scene, drawn once per process."""
    return bone_foam.relief(seed)


def _build_world(params: GenerateParams, scene_index: int) -> World:
    scene = catalog.build_scene(params.scenes[scene_index], scene_index, params)
    atlas = build_atlas(catalog.scene_textures(scene, params))
    geometry = renderer.SceneGeometry.from_meshes(scene.placed, atlas, scene.light_dir, params.lights.intensities(),
                                                  _relief(params.bone_foam, params.seed))
    target_ids = np.array([i for i, name in enumerate(geometry.object_names) if name in scene.target_objects])
    return World(scene, geometry, target_ids)


@dataclass(frozen=True)
class Exposure:
    """Images taken at a shot: image i is drawn from ``default_rng([generate.seed, *rng_key, i])`` and written
    as ``files[i]`` into the folder of every dataset in ``datasets`` (several when they share these images byte
    for byte: a scene's model pair); ``mask``: the file of the target mask, written beside them."""

    datasets: tuple[str, ...]
    files: tuple[str, ...]
    rng_key: tuple[int, ...]
    mask: str | None = None


@dataclass(frozen=True)
class Shot:
    """One camera pose (T_world_cam) of scene ``scene_index``, the lens focused at ``focus_mm``: rendered once,
    then exposed for every image taken there."""

    scene_index: int
    T_world_cam: np.ndarray
    focus_mm: float
    exposures: tuple[Exposure, ...]


def plan_shots(params: GenerateParams, plans: list[DatasetPlan], trips: list[Trip]) -> list[Shot]:
    """Every image of every dataset, grouped by the pose it is taken from (bit-identical poses of one scene and
    focus share one render), the shots of a scene together (a worker then builds each scene once)."""
    exposures: dict[tuple, dict[tuple, list[str]]] = {}  # shot key -> (files, rng_key, mask) -> datasets
    poses: dict[tuple, np.ndarray] = {}

    def add(plan: DatasetPlan, T_world_cam: np.ndarray, focus_mm: float, files: tuple[str, ...],
            rng_key: tuple[int, ...], mask: str | None = None) -> None:
        key = (plan.scene_index, T_world_cam.tobytes(), focus_mm)
        poses.setdefault(key, T_world_cam)
        exposures.setdefault(key, {}).setdefault((files, rng_key, mask), []).append(plan.dataset)

    for dataset_index, (plan, trip) in enumerate(zip(plans, trips)):
        for k, T_world_cam in enumerate(trip.model_views):
            # model images depend on the scene and trajectory kind only: datasets sharing them share them byte for byte
            add(plan, T_world_cam, trip.distance_mm, (f"model/model_{k}.png",),
                (plan.scene_index, 1000 + k + 10 * (plan.trajectory == "line")), f"model/mask_{k}.png")
        for s, stop in enumerate(trip.stops):
            add(plan, stop.T_world_cam, trip.distance_mm, _image_files(s, params.images_per_stop), (dataset_index, s))
    shots = [Shot(key[0], poses[key], key[2], tuple(Exposure(tuple(datasets), *what)
                                                    for what, datasets in taken.items()))
             for key, taken in exposures.items()]
    return sorted(shots, key=lambda shot: shot.scene_index)  # stable: the datasets' order within a scene


def _image_files(stop: int, images_per_stop: int) -> tuple[str, ...]:
    return tuple(f"images/s{stop:02d}_i{i:02d}.png" for i in range(images_per_stop))


def _partial(root: Path, dataset: str) -> Path:
    """The hidden folder a dataset is written into, renamed to ``root / dataset`` when complete."""
    return root / f".{dataset}.partial"


def take_shot(params: GenerateParams, root: Path, shot: Shot) -> None:
    """Render ``shot`` and write its images (and masks) into the datasets' partial folders under ``root``."""
    scene_world = world(params, shot.scene_index)
    cam = Intrinsics.from_params(params.camera)
    T_cam_world = inverse(shot.T_world_cam)
    frame = renderer.render(scene_world.geometry, cam.K, cam.width, cam.height, T_cam_world)
    depth_mm = (T_cam_world[:3, :3] @ scene_world.scene.aim + T_cam_world[:3, 3])[2]
    defocus = defocus_sigma_px(depth_mm, shot.focus_mm, params.camera)  # focused at the model view
    irradiance = renderer.optics(frame.radiance, params.sensor, defocus)  # the robot is still: one image
    for exposure in shot.exposures:
        for i, file in enumerate(exposure.files):
            image = renderer.expose(irradiance, params.sensor, np.random.default_rng([params.seed, *exposure.rng_key, i]))
            _write_png(root, exposure.datasets, file, image, IMAGE_PNG_FLAGS)
        if exposure.mask is not None:
            mask = np.isin(frame.object_index, scene_world.target_ids).astype(np.uint8) * 255
            _write_png(root, exposure.datasets, exposure.mask, mask, MASK_PNG_FLAGS)


def _write_png(root: Path, datasets: tuple[str, ...], file: str, image: np.ndarray, flags: list[int]) -> None:
    """Encode once (OpenCV ``flags``), write into every dataset's partial folder."""
    ok, encoded = cv2.imencode(".png", image, flags)
    if not ok:
        raise OSError(f"cannot encode {file} as PNG")
    for dataset in datasets:
        (_partial(root, dataset) / file).write_bytes(encoded.tobytes())


def _flat(T: np.ndarray) -> list[float]:
    return [float(v) for v in T.ravel()]


def finish_dataset(params: GenerateParams, root: Path, plan: DatasetPlan, trip: Trip, scene: catalog.Scene) -> dict:
    """Once its images are written: the dataset's frames.parquet and meta.json, then its partial folder renamed
    to ``root / plan.dataset``; returns its row of the index."""
    spec = params.scenes[plan.scene_index]
    cam = Intrinsics.from_params(params.camera)
    tmp, final = _partial(root, plan.dataset), root / plan.dataset
    model = {"images": [], "masks": [], "T_cam_board": [], "T_cam_target": []}
    for k, T_world_cam in enumerate(trip.model_views):
        T_cam_world = inverse(T_world_cam)
        model["images"].append(f"model/model_{k}.png")
        model["masks"].append(f"model/mask_{k}.png")
        model["T_cam_board"].append((T_cam_world @ scene.T_world_board).tolist())
        model["T_cam_target"].append((T_cam_world @ scene.T_world_target).tolist())
    rows = []
    for s, stop in enumerate(trip.stops):
        T_cam_world = inverse(stop.T_world_cam)
        for i, file in enumerate(_image_files(s, params.images_per_stop)):
            rows.append({"dataset": plan.dataset, "stop": s, "image": i, "theta_deg": stop.theta_deg,
                         "x_mm": stop.x_mm, "file": file, "T_cam_board": _flat(T_cam_world @ scene.T_world_board),
                         "T_cam_target": _flat(T_cam_world @ scene.T_world_target)})
    pd.DataFrame(rows).to_parquet(tmp / "frames.parquet", index=False)
    meta = {
        "dataset": plan.dataset, "scene": spec.name, "targets": list(spec.targets), "trajectory": plan.trajectory,
        "azimuth_deg": plan.azimuth_deg, "offset_deg": plan.offset_deg, "n_stops": len(trip.stops),
        "images_per_stop": params.images_per_stop, "image_size": [cam.width, cam.height], "K": cam.K.tolist(),
        "dist": [0.0] * 5, "board": scene.board.as_dict(), "model": model,
        "model_baseline_mm": params.model_baseline_mm, "distance_mm": trip.distance_mm,
    }
    (tmp / "meta.json").write_text(json.dumps(meta, indent=1))
    shutil.rmtree(final, ignore_errors=True)
    tmp.rename(final)
    return {"dataset": plan.dataset, "scene": spec.name, "trajectory": plan.trajectory,
            "azimuth_deg": plan.azimuth_deg, "offset_deg": plan.offset_deg, "n_frames": len(rows),
            "path": f"datasets/{plan.dataset}"}


def generate(params: GenerateParams, protocol: ProtocolParams, root: Path, workers: Workers,
             progress: bool = True) -> pd.DataFrame:
    """Render every planned dataset under ``root`` after :func:`check_world`, the shots on ``workers``; returns
    and writes the index."""
    scenes = check_world(params, protocol)
    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    (root / "index.parquet").unlink(missing_ok=True)
    plans = plan_datasets(params)
    trips = [plan_trip(params, protocol, plan, scenes[plan.scene_index]) for plan in plans]
    for plan in plans:
        tmp = _partial(root, plan.dataset)
        shutil.rmtree(tmp, ignore_errors=True)
        (tmp / "model").mkdir(parents=True)
        (tmp / "images").mkdir()
    shots = plan_shots(params, plans, trips)
    workers.map(partial(take_shot, params, root), shots, desc=f"camera poses of {len(plans)} datasets",
                progress=progress)
    index = pd.DataFrame([finish_dataset(params, root, plan, trip, scenes[plan.scene_index])
                          for plan, trip in zip(plans, trips)])
    index.to_parquet(root / "index.parquet", index=False)
    return index
