"""Whether a world can give its datasets, checked before any rendering: every scene's sessions laid out, their boards
planned (:func:`check_world`, :func:`laid_out`), each target mostly inside the model views, and, from its targets'
arrangement alone, whether a scene can give its arcs (:func:`arc_problem`). A scene that cannot raises
:class:`WorldError` naming its key.
"""

from __future__ import annotations

from functools import partial
from operator import call

import numpy as np

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.params.generate import GenerateParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.poses import inverse
from poseintegrity.scenes import catalog, renderer, trajectories
from poseintegrity.scenes.board_stand import PlacementError
from poseintegrity.scenes.camera import Intrinsics
from poseintegrity.scenes.robot import ReachError, Robot, trip_path
from poseintegrity.scenes.trips import plan_datasets, plan_trip
from poseintegrity.seeding import keyed_rng
from poseintegrity.workers import Workers

MIN_TARGET_IN_VIEW = 0.5  # share of a target's vertices that must project inside the model images
MIN_TARGET_AREA = 0.005  # share of the image its projected bounding box must cover (not a speck)


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
    the bone raises :class:`~poseintegrity.mesh_file.MeshError` here, a board with no place a :class:`WorldError`), on ``workers`` when
    given (planning a scene's boards takes seconds); each target must lie mostly inside both model views of its
    session (a mesh scaled far too large or too small, or a distance that puts the target out of the picture). The
    robot's reach is checked by :func:`~.world_plan.drive_scene`."""
    cam = Intrinsics.from_params(params.camera)
    layouts = [partial(laid_out, params, protocol, world, index, session) for index, session in sessions(params)]
    built = (workers.map(call, layouts, desc=f"layouts and boards of {len(layouts)} sessions ({world} world)",
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
    no base placement from which it serves every arc (:func:`~.world_plan.drive_scene`'s placement). None: it
    can."""
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
