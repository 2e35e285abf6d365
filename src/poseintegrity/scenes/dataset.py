"""Stage 01: write the robot datasets of Windsor et al. IV-D to disk, for every world of ``generate``.

Layout of ``<root>/<dataset>/``: ``meta.json`` (world, scene, targets, trajectory, board, model pair),
``camera.yaml`` (the camera as the world's calibration estimated it: the pipeline's only intrinsics),
``frames.parquet`` (one row per image: stop, image, theta_deg and x_mm as the robot recorded them, file, and the
exact T_cam_board / T_cam_target of the image as row-major 16-float lists, a diagnostic), ``model/`` (the two model
images and their target masks) and ``images/``. A dataset is written into a hidden temporary folder and renamed when
complete, so an interrupted run leaves nothing that looks finished; ``<root>/index.parquet`` is written last.

How an image comes about:

1. The robot (:mod:`.robot`) is commanded to the protocol's poses (:mod:`.trajectories`) and lands slightly off them:
   each visit of a pose has its own actual pose. The model pair is visited once per scene and trajectory kind and
   serves all its datasets; the robot returns to the first model view to start each arc (a new visit).
2. Once the robot reports a stop, the camera takes a burst of ``images_per_stop`` exposures (``capture``) while
   the arm rings down (:mod:`.ringdown`): each image sees the stop's view turned by a small rotation, and blurred
   along its path during the exposure. A model image is taken once the arm has settled (``model_settle_ms``).
3. The view is rendered once per visit on the lens' ideal canvas (:mod:`.renderer`), blurred by the lens and the
   depth of field (:mod:`.optics`), warped per image by its ring-down rotation and distorted by the lens onto the
   sensor, then exposed (sensor noise).

The work is split into :class:`Shot` tasks, one per visit, run by :class:`poseintegrity.parallel.Workers`. Every
random draw comes from a generator keyed by the world's seed and what it is for, so the files do not depend on the
backend, the worker count or the order the shots run in.
"""

from __future__ import annotations

import ctypes
import json
import shutil
from collections import OrderedDict
from dataclasses import dataclass, replace
from functools import lru_cache, partial
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
from pydantic import ValidationError

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.localization.dataset import DatasetError, Meta
from poseintegrity.lens import Camera, write_camera_yaml
from poseintegrity.parallel import Workers
from poseintegrity.poses import inverse
from poseintegrity.protocol import ProtocolParams
from poseintegrity.staging import full_disk_named, partial_folder
from poseintegrity.scenes import catalog, optics, renderer, trajectories
from poseintegrity.scenes.acquisition import Route, image_motion, image_pose, model_motion, rotation_maps, visits
from poseintegrity.scenes.board_placement import PlacementError
from poseintegrity.scenes.board_plan import BoardPlan
from poseintegrity.scenes.calibration_views import CalibrationSession, calibration_session, write_calibration
from poseintegrity.scenes.camera import Intrinsics, true_camera
from poseintegrity.scenes.foam import ReliefVolume, bone_foam_relief
from poseintegrity.params.generate import BoneFoamParams, GenerateParams
from poseintegrity.scenes.robot import ReachError, Robot, accuracy, trip_path
from poseintegrity.scenes.textures import build_atlas
from poseintegrity.seeding import keyed_rng

# Camera images are noisy: deflate's string matching finds almost nothing in them, so they are Huffman-coded only,
# after PNG's "average" filter (the prediction residuals are what is compressible): ~3 x faster to encode and ~12 %
# smaller than zlib level 3 with adaptive filters. Masks are flat: there string matching is what compresses.
IMAGE_PNG_FLAGS = [cv2.IMWRITE_PNG_STRATEGY, cv2.IMWRITE_PNG_STRATEGY_HUFFMAN_ONLY,
                   cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_AVG]
MASK_PNG_FLAGS = [cv2.IMWRITE_PNG_COMPRESSION, 3]
MIN_TARGET_IN_VIEW = 0.5  # share of a target's vertices that must project inside the model images
MIN_TARGET_AREA = 0.005  # share of the image its projected bounding box must cover (not a speck)
CAMERA_NAME = "ids_u3_3060cp"  # camera.yaml's camera_name


@dataclass(frozen=True)
class DatasetPlan:
    """One dataset to render: ``trajectory`` is "arc" (``azimuth_deg``) or "line" (``offset_deg``)."""

    world: str
    dataset: str
    scene_index: int
    trajectory: str
    azimuth_deg: float
    offset_deg: float


def plan_datasets(params: GenerateParams, world: str = "main") -> list[DatasetPlan]:
    """Arcs: every scene x every azimuth; lines: every offset on ``lines.scene`` (IV-D), of one world's params.
    The ids are :meth:`GenerateParams.dataset_ids` (validated distinct)."""
    plans = [DatasetPlan(world, dataset, i, "arc", az, 0.0) for i, spec in enumerate(params.scenes)
             for dataset, az in zip(params.arcs.dataset_ids(spec.name), params.arcs.azimuths_deg)]
    if params.lines is not None:
        i = [s.name for s in params.scenes].index(params.lines.scene)
        plans += [DatasetPlan(world, dataset, i, "line", 0.0, off)
                  for dataset, off in zip(params.lines.dataset_ids(), params.lines.offsets_deg)]
    return plans


@dataclass(frozen=True)
class Trip:
    """Where the camera of one dataset is commanded to go: its model pair (T_world_cam, the first is where the
    trajectory starts) at ``distance_mm`` from the aim point, and the stops of its trajectory; the lens is focused at
    ``focus_mm`` for the whole session (arcs: the model view; lines: ``generate.lines.focus``)."""

    distance_mm: float
    focus_mm: float
    model_views: list[np.ndarray]
    stops: list[trajectories.Stop]


def plan_trip(params: GenerateParams, protocol: ProtocolParams, plan: DatasetPlan,
              scene: catalog.Scene | catalog.Arrangement) -> Trip:
    """The commanded model pair and stops of ``plan`` in ``scene`` (its aim and view direction: a scene laid out, or
    its targets arranged); the trajectory spans ``protocol``'s range."""
    # the straight lines have their own model pair (IV-D), closer to the target: the robot backs away from it
    distance_mm = params.scenes[plan.scene_index].distance_mm if plan.trajectory == "arc" else params.lines.distance_mm
    model_views = trajectories.model_pair(scene.aim, scene.view_dir, distance_mm, params.model_baseline_mm)
    if plan.trajectory == "arc":
        stops = trajectories.arc(model_views[0], scene.aim, plan.azimuth_deg, protocol.arc_span_deg,
                                 params.arcs.n_stops)
    else:
        stops = trajectories.line(model_views[0], scene.aim, plan.offset_deg, protocol.line_length_mm,
                                  params.lines.n_stops)
    focus_mm = distance_mm if plan.trajectory == "arc" else params.lines.focus_mm(protocol.line_length_mm)
    return Trip(distance_mm, focus_mm, model_views, stops)


class WorldError(PoseIntegrityError):
    """A scene cannot give the datasets: its target would leave (or vanish from) the model view, or the robot
    cannot reach its poses."""


def scenes_key(world: str) -> str:
    """The params key of a world's scenes, as an error names it."""
    return "generate.scenes" if world == "main" else f"generate.{world}.scenes"


def sessions(params: GenerateParams) -> list[tuple[int, str]]:
    """(scene index, session) of every layout a world renders: each scene's arcs, and the lines' scene's lines
    (:func:`~.catalog.build_scene`)."""
    names = [spec.name for spec in params.scenes]
    lines = [] if params.lines is None else [(names.index(params.lines.scene), "line")]
    return [(index, "arc") for index in range(len(names))] + lines


def laid_out(params: GenerateParams, protocol: ProtocolParams, world: str, index: int, session: str) -> catalog.Scene:
    """Scene ``index``'s ``session`` laid out (:func:`~.catalog.build_scene`, its boards planned); a board with no
    place raises :class:`WorldError` naming the scene's key."""
    try:
        return catalog.build_scene(params.scenes[index], index, params, protocol, session)
    except PlacementError as error:
        raise WorldError(f"{scenes_key(world)}.{index} ({session}s): {error}") from None


def check_world(params: GenerateParams, protocol: ProtocolParams, world: str = "main",
                workers: Workers | None = None, progress: bool = True) -> dict[tuple[int, str], catalog.Scene]:
    """Lay out every scene's sessions before any rendering, naming the key, when one cannot be rendered as the
    protocol needs; returns the scenes by (index, session). Every scene is built (an unreadable mesh or a hole outside
    the bone raises :class:`~.mesh.MeshError` here, a board with no place a :class:`WorldError`), on ``workers`` when
    given (planning a scene's boards takes seconds); each target must lie mostly inside both model views of its
    session (a mesh scaled far too large or too small, or a distance that puts the target out of the picture). The
    robot's reach is checked by :func:`drive`."""
    cam = Intrinsics.from_params(params.camera)
    layouts = [partial(laid_out, params, protocol, world, index, session) for index, session in sessions(params)]
    built = (workers.map(_call, layouts, desc=f"layouts and boards of {len(layouts)} sessions ({world} world)",
                         progress=progress) if workers is not None else [layout() for layout in layouts])
    scenes = dict(zip(sessions(params), built))
    for (index, session), scene in scenes.items():
        distance = params.scenes[index].distance_mm if session == "arc" else params.lines.distance_mm
        _check_targets_in_view(scene, scene.target_objects, distance, params.model_baseline_mm, cam,
                               f"{scenes_key(world)}.{index}")
    return scenes


def arc_problem(params: GenerateParams, protocol: ProtocolParams, index: int) -> str | None:
    """Why scene ``index`` of a world cannot give its arcs, found from its targets' arrangement before any board is
    planned (seconds less than :func:`check_world`; a world of the population is drawn again where this says so,
    population/draw.py): a target out of either model view (:func:`_check_in_view`), or the world's robot reaching
    no base placement from which it serves every arc (:func:`drive_scene`'s placement). None: it can."""
    spec, cam = params.scenes[index], Intrinsics.from_params(params.camera)
    arranged = catalog.arrange(spec, index, params)
    try:
        _check_targets_in_view(arranged, spec.targets, spec.distance_mm, params.model_baseline_mm, cam,
                               f"{scenes_key('main')}.{index}")
        trips = [plan_trip(params, protocol, plan, arranged) for plan in plan_datasets(params)
                 if plan.scene_index == index and plan.trajectory == "arc"]
        Robot.from_params(params.robot, keyed_rng(params.seed, "robot")).placed(
            [trip_path(trip) for trip in trips], arranged.aim, spec.name)
    except (WorldError, ReachError) as error:
        return str(error)
    return None


def _check_targets_in_view(scene: catalog.Scene | catalog.Arrangement, targets: tuple[str, ...] | list[str],
                           distance: float, baseline_mm: float, cam: Intrinsics, key: str) -> None:
    """WorldError naming ``key`` unless each of ``targets`` among the scene's placed meshes lies mostly inside both
    images of the model pair at ``distance`` (mm) from its aim point (:func:`_check_in_view`)."""
    for T_world_cam in trajectories.model_pair(scene.aim, scene.view_dir, distance, baseline_mm):
        T_cam_world = inverse(T_world_cam)
        for name, mesh in scene.placed:
            if name in targets:
                _check_in_view(mesh.vertices @ T_cam_world[:3, :3].T + T_cam_world[:3, 3], cam, key, name, distance)


def _check_in_view(points_cam: np.ndarray, cam: Intrinsics, key: str, name: str, distance: float) -> None:
    """WorldError unless most of points_cam (n, 3, mm) project inside the image and their extent is not a speck."""
    z = points_cam[:, 2]
    safe = np.where(z > renderer.NEAR_MM, z, np.nan)
    u = cam.K[0, 0] * points_cam[:, 0] / safe + cam.K[0, 2]
    v = cam.K[1, 1] * points_cam[:, 1] / safe + cam.K[1, 2]
    inside = (u >= 0) & (u <= cam.width - 1) & (v >= 0) & (v <= cam.height - 1)
    hint = (f"check {key}.distance_mm ({distance:g} mm)"
            + (" and generate.scapula.length_mm" if name.startswith("scapula") else ""))
    if inside.mean() < MIN_TARGET_IN_VIEW:
        raise WorldError(f"{key}: only {inside.mean():.0%} of target {name} lies inside the "
                         f"{cam.width} x {cam.height} model image: it leaves the view; {hint}")
    area = np.ptp(u[inside]) * np.ptp(v[inside]) / (cam.width * cam.height)
    if area < MIN_TARGET_AREA:
        raise WorldError(f"{key}: target {name} covers {area:.2%} of the model image: too small "
                         f"to be seen; {hint}")


def drive_scene(params: GenerateParams, mine: list[tuple[DatasetPlan, Trip]], scene: catalog.Scene,
                scene_index: int, world: str = "main") -> tuple[dict[str, Route], dict[str, float]]:
    """The world's robot (drawn from its seed) placed in one scene where it reaches every commanded pose of the
    scene's datasets ``mine`` (their plans and trips), then driven: each dataset's route, and how far it lands from
    what was commanded (:func:`.robot.accuracy`). A scene the robot cannot serve raises :class:`WorldError` naming
    it. Every draw is keyed by the world's seed and the scene or dataset: scenes can be driven in any order, apart."""
    robot = Robot.from_params(params.robot, keyed_rng(params.seed, "robot"))
    try:
        placed = robot.placed([trip_path(trip) for _, trip in mine], scene.aim, scene.name)
    except ValueError as error:
        raise WorldError(f"{scenes_key(world)}.{scene_index}: {error}") from None
    first_trip = {plan.trajectory: trip for plan, trip in reversed(mine)}  # arcs share one model pair, lines one
    model = {kind: visits(placed, trip.model_views, params, "model", scene_index, kind)
             for kind, trip in first_trip.items()}
    routes = {}
    for plan, trip in mine:
        stops = visits(placed, trip_path(trip), params, plan.dataset)[len(trip.model_views):]
        routes[plan.dataset] = Route(model[plan.trajectory], stops)
    return routes, accuracy(placed, [t for p, t in mine if p.trajectory == "arc"],
                            [t for p, t in mine if p.trajectory == "line"],
                            keyed_rng(params.seed, "accuracy", scene_index))


@dataclass(frozen=True)
class World:
    """A scene and its renderable geometry; ``target_ids`` index its targets in ``geometry.object_names``."""

    scene: catalog.Scene
    geometry: renderer.SceneGeometry
    target_ids: np.ndarray


_WORLDS: OrderedDict[tuple[str, int], World] = OrderedDict()
WORLDS_KEPT = 2  # per process: the shots of one session run together, a worker seldom goes back to an earlier one


def world(params: GenerateParams, protocol: ProtocolParams, scene_index: int, session: str,
          plan: BoardPlan | None = None) -> World:
    """The scene of one session and its renderable geometry, built once per process (the last WORLDS_KEPT kept);
    ``plan``: its boards' plan, found when the world was planned (:func:`~.catalog.build_scene`)."""
    key = (params.model_dump_json(), protocol.model_dump_json(), scene_index, session,
           None if plan is None else tuple(b.placement.T_world_board.tobytes() for b in plan.boards))
    if key not in _WORLDS:
        _WORLDS[key] = _build_world(params, protocol, scene_index, session, plan)
        while len(_WORLDS) > WORLDS_KEPT:
            _WORLDS.popitem(last=False)
        give_back_freed_memory()
    _WORLDS.move_to_end(key)
    return _WORLDS[key]


def give_back_freed_memory() -> None:
    """Return the heap memory freed so far to the kernel (glibc's ``malloc_trim``; nothing where there is none).

    The Makefile keeps freed memory for reuse (``MALLOC_TRIM_THRESHOLD_`` 1 GB: SIFT's per-frame buffers), so the
    temporaries of building a world stayed resident in the render worker: at paper scale 130 MB for a world whose foam
    relief is drawn (its 128^3 FFTs), 66 MB for one that reuses it. loky restarts a worker whose memory grew by
    300 MB past what it held after its first task (a robot drive, ~350 MB); by the validation world's first shot a
    render worker held 310-330 MB more and was restarted, in every stage-01 run, with "A worker stopped while some
    jobs were given to the executor" (and built its worlds again). Given back, they peak ~210 MB above it."""
    trim = getattr(ctypes.CDLL(None), "malloc_trim", None)  # the C library this process runs on
    if trim is not None:
        trim(0)


@lru_cache(maxsize=2)
def _relief(bone_foam: BoneFoamParams, seed: int) -> ReliefVolume:
    """The foam's relief: one material, the same in every scene of a world, drawn once per process."""
    return bone_foam_relief(bone_foam, seed)


def _build_world(params: GenerateParams, protocol: ProtocolParams, scene_index: int, session: str,
                 plan: BoardPlan | None) -> World:
    scene = catalog.build_scene(params.scenes[scene_index], scene_index, params, protocol, session, plan)
    atlas = build_atlas(catalog.scene_textures(scene, params))
    geometry = renderer.SceneGeometry.from_meshes(scene.placed, atlas, scene.light_dir, params.lights.intensities(),
                                                  _relief(params.bone_foam, params.seed))
    target_ids = np.array([i for i, name in enumerate(geometry.object_names) if name in scene.target_objects])
    return World(scene, geometry, target_ids)


@dataclass(frozen=True)
class Exposure:
    """An image taken at a shot: its noise drawn from ``keyed_rng(generate.seed, "image", *rng_key)`` after turning the view by the
    ring-down path ``rotations`` (k, 3), written as ``file`` into the folder of every dataset in ``datasets``;
    ``mask``: the file of the target mask, written beside it (model images)."""

    datasets: tuple[str, ...]
    file: str
    rng_key: tuple
    rotations: np.ndarray
    mask: str | None = None


@dataclass(frozen=True)
class Shot:
    """One visit of the camera (T_world_cam at the reported stop) in scene ``scene_index``'s ``session`` ("arc" or
    "line"), the lens focused at ``focus_mm``: rendered once, then exposed for every image taken there."""

    scene_index: int
    session: str
    T_world_cam: np.ndarray
    focus_mm: float
    exposures: tuple[Exposure, ...]
    plan: BoardPlan | None = None  # the session's boards (found when the world was planned)


def plan_shots(params: GenerateParams, plans: list[DatasetPlan], trips: list[Trip], routes: list[Route],
               boards: dict[tuple[int, str], BoardPlan | None]) -> list[Shot]:
    """Every image of every dataset, one shot per visit (a scene's model pair once for all datasets sharing it), the
    shots of a scene together (a worker then builds each scene once); ``boards``: each session's boards' plan."""
    f_px = Intrinsics.from_params(params.camera).K[0, 0]
    shots: dict[tuple, Shot] = {}
    for plan, trip, route in zip(plans, trips, routes):
        for k, visit in enumerate(route.model):
            key = (plan.scene_index, "model", plan.trajectory, k)
            if key in shots:  # the scene's other datasets of this kind share the images
                shot = shots[key]
                shots[key] = replace(shot, exposures=tuple(
                    Exposure((*e.datasets, plan.dataset), e.file, e.rng_key, e.rotations, e.mask)
                    for e in shot.exposures))
                continue
            motion = model_motion(visit, params.capture, f_px)
            shots[key] = Shot(plan.scene_index, plan.trajectory, visit.T_world_cam, trip.focus_mm, (Exposure(
                (plan.dataset,), f"model/model_{k}.png", ("model", plan.scene_index, plan.trajectory, k),
                motion.path, f"model/mask_{k}.png"),), boards[plan.scene_index, plan.trajectory])
        for s, visit in enumerate(route.stops):
            exposures = tuple(Exposure((plan.dataset,), file, (plan.dataset, s, i),
                                       image_motion(visit, params.capture, i, f_px).path)
                              for i, file in enumerate(_image_files(s, params.images_per_stop)))
            shots[(plan.dataset, s)] = Shot(plan.scene_index, plan.trajectory, visit.T_world_cam, trip.focus_mm,
                                            exposures, boards[plan.scene_index, plan.trajectory])
    # stable: the datasets' order within a session; a worker then builds each session's scene once
    return sorted(shots.values(), key=lambda shot: (shot.scene_index, shot.session))


def _image_files(stop: int, images_per_stop: int) -> tuple[str, ...]:
    return tuple(f"images/s{stop:02d}_i{i:02d}.png" for i in range(images_per_stop))


def _partial(root: Path, dataset: str) -> Path:
    """The hidden folder a dataset is written into (its shots by the workers), renamed to ``root / dataset`` when
    complete (:func:`poseintegrity.staging.partial_folder`)."""
    return partial_folder(root / dataset)


def take_shot(params: GenerateParams, protocol: ProtocolParams, root: Path, shot: Shot) -> None:
    """Render ``shot`` on the lens' ideal canvas, blur it by the lens and the depth of field, and for every image
    turn it by the image's ring-down path, distort it onto the sensor and expose it; write the images (and masks)
    into the datasets' partial folders under ``root``."""
    scene_world = world(params, protocol, shot.scene_index, shot.session, shot.plan)
    lens = true_camera(params.camera)  # its canvas and sensor maps are computed once per process
    K_canvas, width, height = lens.canvas
    frame = renderer.render(scene_world.geometry, K_canvas, width, height, inverse(shot.T_world_cam))
    irradiance = optics.lens(frame.radiance, frame.depth_mm, shot.focus_mm, params.sensor.blur_sigma_px, params.camera)
    map_x, map_y = lens.sensor_maps
    for exposure in shot.exposures:
        sensor = np.zeros(map_x.shape, np.float32)
        for rotation in exposure.rotations:  # the exposure integrates the view along the ring-down's path
            sensor += cv2.remap(irradiance, *rotation_maps(K_canvas, rotation, map_x, map_y), cv2.INTER_LINEAR,
                                borderMode=cv2.BORDER_REPLICATE)
        sensor /= len(exposure.rotations)
        image = renderer.expose(sensor, params.sensor, keyed_rng(params.seed, "image", *exposure.rng_key))
        _write_png(root, exposure.datasets, exposure.file, image, IMAGE_PNG_FLAGS)
        if exposure.mask is not None:
            middle = exposure.rotations[len(exposure.rotations) // 2]
            target = np.isin(frame.object_index, scene_world.target_ids).astype(np.uint8) * 255
            mask = cv2.remap(target, *rotation_maps(K_canvas, middle, map_x, map_y), cv2.INTER_NEAREST)
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


def check_meta(meta: dict, dataset: str) -> None:
    """:class:`~poseintegrity.localization.dataset.DatasetError` naming the dataset and the field unless ``meta``
    holds what stage 02 reads from meta.json (:class:`~poseintegrity.localization.dataset.Meta`: an ArUco dictionary
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
    tmp, final = _partial(root, plan.dataset), root / plan.dataset
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
        for i, file in enumerate(_image_files(s, params.images_per_stop)):
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


@dataclass(frozen=True)
class WorldPlan:
    """Everything one world renders: its params, calibration session, scenes, datasets, their commanded trips and
    actual routes."""

    name: str
    params: GenerateParams
    calibration: CalibrationSession
    scenes: dict[tuple[int, str], catalog.Scene]
    plans: list[DatasetPlan]
    trips: list[Trip]
    routes: list[Route]
    robot_accuracy: dict[str, dict[str, float]]


def _call(task: partial):
    return task()


def plan_worlds(params: GenerateParams, protocol: ProtocolParams, workers: Workers,
                progress: bool = True) -> dict[str, WorldPlan]:
    """Every world of ``params`` checked (:func:`check_world`) and its datasets planned, then, on ``workers``, each
    world's camera calibrated (:func:`calibration_session`; a calibration error names the key) and its robot driven
    in each scene (:func:`drive_scene`): every error comes here, before any dataset is rendered. The results do not
    depend on where the tasks run (keyed draws): the same as one after the other, world by world."""
    worlds = params.worlds()
    scenes = {name: check_world(world_params, protocol, name, workers, progress)
              for name, world_params in worlds.items()}
    plans = {name: plan_datasets(world_params, name) for name, world_params in worlds.items()}
    trips = {name: [plan_trip(worlds[name], protocol, plan, scenes[name][plan.scene_index, plan.trajectory])
                    for plan in plans[name]]
             for name in worlds}
    # a scene's robot and aim are those of its arcs' session (arcs and lines have their own board places)
    drives = [(name, scene_index) for name in worlds for scene_index, session in scenes[name]
              if session == "arc" and any(plan.scene_index == scene_index for plan in plans[name])]
    tasks = [partial(drive_scene, worlds[name], [(plan, trip) for plan, trip in zip(plans[name], trips[name])
                                                 if plan.scene_index == scene_index],
                     scenes[name][scene_index, "arc"], scene_index, name) for name, scene_index in drives]
    tasks += [partial(calibration_session, world_params, "generate.calibration" if name == "main"
                      else f"generate.{name}.calibration") for name, world_params in worlds.items()]
    results = workers.map(_call, tasks, desc=f"robot drives of {len(drives)} scenes and {len(worlds)} camera "
                          f"calibrations", progress=progress)
    driven = dict(zip(drives, results))
    sessions = dict(zip(worlds, results[len(drives):]))
    planned = {}
    for name, world_params in worlds.items():
        routes = {dataset: route for (world, _), (scene_routes, _) in driven.items() if world == name
                  for dataset, route in scene_routes.items()}
        robot_accuracy = {scenes[name][scene_index, "arc"].name: summary for (world, scene_index), (_, summary)
                          in driven.items() if world == name}
        planned[name] = WorldPlan(name, world_params, sessions[name], scenes[name], plans[name], trips[name],
                                  [routes[plan.dataset] for plan in plans[name]], robot_accuracy)
    return planned


def generate(params: GenerateParams, protocol: ProtocolParams, root: Path, workers: Workers, *,
             calibration_dir: Path, progress: bool = True) -> tuple[pd.DataFrame, dict[str, WorldPlan]]:
    """Render every world's datasets under ``root`` and its calibration session under ``calibration_dir / world``
    (every world planned, calibrated and checked first), the shots on ``workers``; returns the index (also written)
    and each world's plan (its calibration and robot accuracy)."""
    worlds = plan_worlds(params, protocol, workers, progress)
    root = Path(root)
    with full_disk_named(root):  # a full disk, in a worker or here: one line naming the datasets' folder
        root.mkdir(parents=True, exist_ok=True)
        (root / "index.parquet").unlink(missing_ok=True)
        rows = []
        for w in worlds.values():
            write_calibration(Path(calibration_dir) / w.name, w.calibration, w.params, CAMERA_NAME, IMAGE_PNG_FLAGS)
            for plan in w.plans:
                tmp = _partial(root, plan.dataset)
                shutil.rmtree(tmp, ignore_errors=True)
                (tmp / "model").mkdir(parents=True)
                (tmp / "images").mkdir()
            shots = plan_shots(w.params, w.plans, w.trips, w.routes, {key: s.plan for key, s in w.scenes.items()})
            workers.map(partial(take_shot, w.params, protocol, root), shots,
                        desc=f"camera poses of {len(w.plans)} datasets ({w.name} world)", progress=progress)
            rows += [finish_dataset(w.params, root, plan, trip, route, w.scenes[plan.scene_index, plan.trajectory],
                                    w.calibration.calibration.camera)
                     for plan, trip, route in zip(w.plans, w.trips, w.routes)]
        index = pd.DataFrame(rows)
        index.to_parquet(root / "index.parquet", index=False)
    return index, worlds
