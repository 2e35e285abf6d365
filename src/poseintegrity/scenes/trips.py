"""Where the camera of each dataset of a world is commanded to go (Windsor et al. IV-D): the datasets a world renders
(:func:`plan_datasets`: each scene's arcs, the lines' scene's lines) and each one's trip (:func:`plan_trip`: its model
pair and the stops of its trajectory, T_world_cam (4, 4), mm, and where the lens is focused).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from poseintegrity.params.generate import GenerateParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.scenes import catalog, trajectories


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
