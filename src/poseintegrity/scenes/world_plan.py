"""Everything a world renders, planned before any rendering (:func:`plan_worlds`): its scenes checked
(:mod:`.world_checks`), its datasets and their trips (:mod:`.trips`), its robot placed and driven in each scene
(:func:`drive_scene`: the actual routes) and its camera calibrated (:mod:`.calibration_views`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from operator import call

from poseintegrity.params.generate import GenerateParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.scenes import catalog
from poseintegrity.scenes.acquisition import Route, visits
from poseintegrity.scenes.calibration_views import CalibrationSession, calibration_session
from poseintegrity.scenes.robot import Robot, accuracy, trip_path
from poseintegrity.scenes.trips import DatasetPlan, Trip, plan_datasets, plan_trip
from poseintegrity.scenes.world_checks import WorldError, check_world, scenes_key
from poseintegrity.seeding import keyed_rng
from poseintegrity.workers import Workers

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
    results = workers.map(call, tasks, desc=f"robot drives of {len(drives)} scenes and {len(worlds)} camera "
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
