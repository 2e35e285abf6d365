"""Camera poses of the data-collection protocol (Windsor et al., IV-D): the model pair, arcs about the target,
straight lines away from it. All poses are T_world_cam (4x4, mm); the eye-in-hand camera moves, the scene is still.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.poses import pose_matrix
from poseintegrity.scenes.camera import look_at


@dataclass(frozen=True)
class Stop:
    """One robot stop: the camera pose, the viewing-angle change theta from the model view (deg) and the camera
    translation x from the trajectory start (mm)."""

    T_world_cam: np.ndarray
    theta_deg: float
    x_mm: float


def model_pair(aim: np.ndarray, view_dir: np.ndarray, distance_mm: float, baseline_mm: float) -> list[np.ndarray]:
    """The two model-generation views: the camera looking at ``aim`` from ``view_dir``, then translated by
    ``baseline_mm`` along its own x axis (same orientation)."""
    T0 = look_at(aim + distance_mm * view_dir, aim)
    T1 = T0.copy()
    T1[:3, 3] += baseline_mm * T0[:3, 0]
    return [T0, T1]


def _rotate_about(T_world_cam: np.ndarray, centre: np.ndarray, rotation: Rotation) -> np.ndarray:
    """The camera pose rotated rigidly about the point ``centre`` (world frame)."""
    R = rotation.as_matrix()
    return pose_matrix(R @ T_world_cam[:3, :3], centre + R @ (T_world_cam[:3, 3] - centre))


def arc_axis(T_world_cam: np.ndarray, azimuth_deg: float) -> np.ndarray:
    """Rotation axis of an arc whose camera starts moving along the image direction at ``azimuth_deg``
    (0 = camera +x, 90 = camera +y, i.e. down in the image); unit (3,) in the world frame.

    The camera centre moves along u = cos(az) x_cam + sin(az) y_cam, so the axis is u x z_cam.
    """
    a = np.deg2rad(azimuth_deg)
    x_cam, y_cam, z_cam = T_world_cam[:3, 0], T_world_cam[:3, 1], T_world_cam[:3, 2]
    u = np.cos(a) * x_cam + np.sin(a) * y_cam
    axis = np.cross(u, z_cam)
    return axis / np.linalg.norm(axis)


def arc(T_start: np.ndarray, aim: np.ndarray, azimuth_deg: float, span_deg: float, n_stops: int) -> list[Stop]:
    """Stops k = 0..n_stops-1 at theta = k * span / n_stops along a circle about ``aim``, camera pointed at ``aim``.

    IV-D: the robot is "re-positioned to its initial pose" (the first model view, ``T_start``) and stops every
    2.25 deg of a 45 deg arc, so the first stop is the model view itself (theta = 0) and the last is 42.75 deg;
    theta_i is measured "between the pose where M_t was created and robot pose at position i" (III-D).
    Rotating the camera rigidly about the aim point keeps it pointed at the target, and the change of camera
    orientation from the model view is exactly theta.
    """
    axis = arc_axis(T_start, azimuth_deg)
    thetas = span_deg * np.arange(n_stops) / n_stops
    return [Stop(_rotate_about(T_start, aim, Rotation.from_rotvec(np.deg2rad(t) * axis)), float(t), 0.0)
            for t in thetas]


def line(T_model: np.ndarray, aim: np.ndarray, offset_deg: float, length_mm: float, n_stops: int) -> list[Stop]:
    """Straight line along the camera's -z axis from a start view ``offset_deg`` away from the model view
    (about the aim point, horizontally); stops at x = k * length / n_stops, k = 0..n_stops-1 (IV-D: every 10 mm
    of 150 mm): x_i is "the absolute magnitude of the 3D camera translation between the first position of the
    trajectory and position i" (V-A), so the first stop is the start view (x = 0)."""
    start = _rotate_about(T_model, aim, Rotation.from_rotvec(np.deg2rad(offset_deg) * arc_axis(T_model, 0.0)))
    stops = []
    for x_mm in length_mm * np.arange(n_stops) / n_stops:
        T = start.copy()
        T[:3, 3] -= x_mm * start[:3, 2]
        stops.append(Stop(T, float(offset_deg), float(x_mm)))
    return stops


def arc_trajectories(aim: np.ndarray, view_dir: np.ndarray, distance_mm: float, baseline_mm: float,
                     azimuths_deg: list[float], span_deg: float, n_stops: int
                     ) -> tuple[list[np.ndarray], list[list[np.ndarray]]]:
    """A scene's arcs session: its model pair (T_world_cam (4, 4) each) and per arc (one per azimuth) the commanded
    T_world_cam of its stops (the first is model image 0's)."""
    pair = model_pair(aim, view_dir, distance_mm, baseline_mm)
    return pair, [[stop.T_world_cam for stop in arc(pair[0], aim, az, span_deg, n_stops)]
                  for az in azimuths_deg]


def line_trajectories(aim: np.ndarray, view_dir: np.ndarray, distance_mm: float, baseline_mm: float,
                      offsets_deg: list[float], length_mm: float, n_stops: int
                      ) -> tuple[list[np.ndarray], list[list[np.ndarray]]]:
    """The lines session: its model pair and per line (one per offset) the commanded T_world_cam of its stops."""
    pair = model_pair(aim, view_dir, distance_mm, baseline_mm)
    return pair, [[stop.T_world_cam for stop in line(pair[0], aim, offset, length_mm, n_stops)]
                  for offset in offsets_deg]
