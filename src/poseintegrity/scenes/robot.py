"""The robot that carries the eye-in-hand camera (Windsor et al. IV-D): a UR5e whose kinematics and hand-eye
calibration are slightly wrong, placed on the table of a scene.

A commanded camera pose T_world_cam becomes an actual one the way it does on a real arm (docs/references.md
"Robot"): camera -> flange with the hand-eye calibration's *estimate* of the camera mount, inverse kinematics on
the *nominal* (published) kinematics -> joint angles, plus a repeatability draw per visit -> forward kinematics on
the *actual* kinematics (DH parameters off by small errors drawn once per world) -> flange -> camera with the
*true* mount. The same commanded pose thus always carries the same systematic error and a new repeatability
draw each visit. Lengths in mm, angles in rad unless a name says deg.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity import kinematics
from poseintegrity.denavit_hartenberg import DH, UR5E
from poseintegrity.errors import PoseIntegrityError
from poseintegrity.poses import inverse as inverse_pose
from poseintegrity.poses import pose_errors, pose_matrix, rotation_angle_deg
from poseintegrity.scenes.trajectories import Stop

if TYPE_CHECKING:
    from poseintegrity.params.robot import PlacementParams, RobotParams

ISO_9283_CYCLES = 30  # visits per pose of the ISO 9283 repeatability test


class ReachError(PoseIntegrityError):
    """The robot cannot reach a commanded pose (or no base placement reaches all of a scene's poses)."""


def _seeds(p_base: np.ndarray) -> np.ndarray:
    """(32, 6) starting points of the first IK solution of a path: the arm turned towards the flange position
    p_base (3,) or away from it, shoulder raised or lowered, elbow and both wrist joints either way (joint 6 at 0).
    At q = 0 a UR arm stretches along the base's -x axis, hence q1 = atan2(y, x) - pi faces the target."""
    facing = np.arctan2(p_base[1], p_base[0]) - np.pi
    grid = np.meshgrid([facing, facing + np.pi], [-np.pi / 4, -3 * np.pi / 4], [np.pi / 2, -np.pi / 2],
                       [-np.pi / 2, np.pi / 2], [np.pi / 2, -np.pi / 2], [0.0], indexing="ij")
    return np.stack([g.ravel() for g in grid], axis=-1)


def elbow_up(dh: DH, q: np.ndarray) -> bool:
    """Whether the elbow (frame 2's origin) lies above the straight line from the shoulder (frame 1) to the wrist
    (frame 3), in the base frame (z up)."""
    shoulder, elbow, wrist = kinematics.joint_frames(dh, q)[1:4, :3, 3]
    line = (wrist - shoulder) / np.linalg.norm(wrist - shoulder)
    closest = shoulder + line * np.dot(elbow - shoulder, line)
    return bool(elbow[2] > closest[2])


@dataclass(frozen=True)
class Robot:
    """One physical UR5e with its camera.

    nominal, actual : the published and the true kinematics; T_flange_cam, T_flange_cam_estimate : (4, 4) the true
    camera mount and the hand-eye calibration's estimate of it; joint_std_rad : per-joint repeatability (std) of a
    visit; placement : how the base is put on a scene's table.
    """

    nominal: DH
    actual: DH
    T_flange_cam: np.ndarray
    T_flange_cam_estimate: np.ndarray
    joint_std_rad: float
    placement: "PlacementParams"

    @classmethod
    def from_params(cls, robot: "RobotParams", rng: np.random.Generator) -> "Robot":
        """Draw one arm's DH deviations (N(0, std) per joint and parameter) and one hand-eye calibration result
        (the true mount times a small pose error, N(0, std) per axis of its translation and rotation vector)."""
        errors = robot.dh_errors
        deviations = [rng.normal(0.0, errors.length_std_mm, kinematics.N_JOINTS),
                      rng.normal(0.0, errors.length_std_mm, kinematics.N_JOINTS),
                      np.radians(rng.normal(0.0, errors.twist_std_deg, kinematics.N_JOINTS)),
                      np.radians(rng.normal(0.0, errors.joint_offset_std_deg, kinematics.N_JOINTS))]
        mount = pose_matrix(Rotation.from_rotvec(robot.mount.rotation_deg, degrees=True).as_matrix(),
                            robot.mount.translation_mm)
        hand_eye = robot.hand_eye_errors
        calibration_error = pose_matrix(
            Rotation.from_rotvec(rng.normal(0.0, hand_eye.rotation_std_deg, 3), degrees=True).as_matrix(),
            rng.normal(0.0, hand_eye.translation_std_mm, 3))
        return cls(UR5E, UR5E.perturbed(*deviations), mount, mount @ calibration_error,
                   float(np.radians(robot.joint_repeatability_std_deg)), robot.placement)

    def placed(self, paths: Sequence[Sequence[np.ndarray]], aim: np.ndarray, scene: str) -> "PlacedRobot":
        """The robot with its base on the table (z = 0) where it reaches every pose of ``paths``, each a sequence
        of commanded T_world_cam (4, 4) visited in order (a model pair, an arc, a line), around the point ``aim``
        (3,) the camera looks at. Candidates at ``placement.base_distances_mm`` from the aim point (horizontally),
        in the directions ``placement.base_azimuths_deg`` from the direction towards the cameras, are tried in
        that order (azimuth first): the first where every path has IK solutions within the margins wins. Its -x
        axis faces the aim point (a UR arm's q = 0 stretches along -x). ReachError naming ``scene`` if none does."""
        poses = [np.asarray(T, dtype=np.float64) for path in paths for T in path]
        if not poses or any(T.shape != (4, 4) or not np.isfinite(T).all() for T in poses) or min(map(len, paths)) == 0:
            raise ValueError(f"paths must be non-empty sequences of finite (4, 4) poses (scene {scene})")
        cameras = np.mean([T[:3, 3] for T in poses], axis=0)
        toward = np.arctan2(cameras[1] - aim[1], cameras[0] - aim[0])
        n_candidates = len(self.placement.base_azimuths_deg) * len(self.placement.base_distances_mm)
        closest = (-1, "")  # the candidate that reached the most paths, and why it failed then
        for azimuth in np.radians(self.placement.base_azimuths_deg):
            for distance in self.placement.base_distances_mm:
                direction = toward + azimuth
                xy = aim[:2] + distance * np.array([np.cos(direction), np.sin(direction)])
                candidate = PlacedRobot(self, pose_matrix(Rotation.from_euler("z", direction).as_matrix(), [*xy, 0]))
                solved = 0
                try:
                    for path in paths:
                        candidate.solve(path)
                        solved += 1
                except ReachError as error:
                    if solved > closest[0]:
                        closest = (solved, f"the base {distance:g} mm away at {np.degrees(azimuth):g} deg reached "
                                           f"{solved} of {len(paths)} paths, then: {error}")
                    continue
                return candidate
        raise ReachError(f"scene {scene}: none of generate.robot.placement's {n_candidates} base placements reaches "
                         f"every commanded camera pose ({closest[1]}); check the scene's distance_mm and "
                         f"elevation_deg (a UR5e reaches 850 mm; the camera must stay above the table)")


@dataclass(frozen=True)
class PlacedRobot:
    """A robot whose base stands at T_world_base (4, 4) on a scene's table (the first IK solution of each pose
    asked for is kept: a path's start is often the model view of another)."""

    robot: Robot
    T_world_base: np.ndarray
    _first_solutions: dict[bytes, np.ndarray] = field(default_factory=dict, init=False, repr=False, compare=False)

    def _flange_target(self, T_world_cam: np.ndarray) -> np.ndarray:
        """T_base_flange the controller aims for: the commanded camera pose through the hand-eye *estimate*."""
        return inverse_pose(self.T_world_base) @ T_world_cam @ inverse_pose(self.robot.T_flange_cam_estimate)

    def _check(self, q: np.ndarray) -> str | None:
        """Why joint angles q (6,) are unusable (None if usable): too close to a singularity, or a joint or the
        camera below the table top plus its clearance (nominal kinematics)."""
        robot, placement = self.robot, self.robot.placement
        frames = self.T_world_base @ kinematics.joint_frames(robot.nominal, q)
        heights = np.append(frames[2:, 2, 3], (frames[-1] @ robot.T_flange_cam)[2, 3])
        if heights.min() < placement.table_clearance_mm:
            return (f"a joint or the camera {heights.min():.0f} mm above the table, below "
                    f"placement.table_clearance_mm ({placement.table_clearance_mm:g})")
        w = kinematics.manipulability(robot.nominal, q)
        if w < placement.min_manipulability:
            return f"manipulability {w:.3f} < placement.min_manipulability ({placement.min_manipulability:g})"
        return None

    def joints(self, T_world_cam: np.ndarray, q_seed: np.ndarray | None = None) -> np.ndarray:
        """Joint angles (6,) rad the controller commands for camera pose T_world_cam (4, 4): the IK solution of
        q_seed's branch (6,) if given (a move from there), else the first solution chosen as an operator would:
        elbow up if any, then the largest manipulability (wrist and elbow away from singularities). ReachError
        when there is none within the margins."""
        where = f"at {np.round(T_world_cam[:3, 3], 1)} mm"
        if q_seed is None:
            key = T_world_cam.tobytes()
            if key not in self._first_solutions:
                self._first_solutions[key] = self._first_solution(self._flange_target(T_world_cam), where)
            return self._first_solutions[key]
        q = kinematics.inverse(self.robot.nominal, self._flange_target(T_world_cam), q_seed)
        if q is None:
            raise ReachError(f"no IK solution {where} from the previous pose")
        if kinematics.branch(self.robot.nominal, q) != kinematics.branch(self.robot.nominal, q_seed):
            raise ReachError(f"the IK solution {where} is on another branch than the previous pose's: the arm "
                             f"would pass a singularity between them")
        reason = self._check(q)
        if reason is not None:
            raise ReachError(f"{where}: {reason}")
        return q

    def _first_solution(self, T_base_flange: np.ndarray, where: str) -> np.ndarray:
        """The operator's choice among the distinct IK solutions found from :func:`_seeds` (see :meth:`joints`)."""
        nominal = self.robot.nominal
        solutions, reasons = [], []
        for seed in _seeds(T_base_flange[:3, 3]):
            q = kinematics.inverse(nominal, T_base_flange, seed)
            if q is None or any(np.allclose(q, other, atol=1e-6) for other in solutions):
                continue
            reason = self._check(q)
            (reasons if reason else solutions).append(reason or q)
        if not solutions:
            raise ReachError(f"no IK solution {where}"
                             + (f" within the margins ({reasons[0]})" if reasons else " (out of reach)"))
        return max(solutions, key=lambda q: (elbow_up(nominal, q), kinematics.manipulability(nominal, q)))

    def solve(self, path: Sequence[np.ndarray]) -> np.ndarray:
        """Joint angles (n, 6) of a path of commanded T_world_cam (n, 4, 4) visited in order: the first chosen by
        :meth:`joints`, each next one on the branch of the one before. ReachError if a pose has none."""
        q = [self.joints(path[0])]
        for T in path[1:]:
            q.append(self.joints(T, q[-1]))
        return np.stack(q)

    def reach(self, q: np.ndarray, rng: np.random.Generator | None) -> np.ndarray:
        """Actual T_world_cam (4, 4) when the controller commands joint angles q (6,): the joints land within their
        repeatability (a N(0, joint_std) draw from ``rng``; None: exactly, the systematic pose), the *actual*
        kinematics carry the flange there and the *true* mount the camera."""
        robot = self.robot
        if rng is not None:
            q = q + rng.normal(0.0, robot.joint_std_rad, kinematics.N_JOINTS)
        return self.T_world_base @ kinematics.forward(robot.actual, q) @ robot.T_flange_cam

    def move(self, T_world_cam: np.ndarray, rng: np.random.Generator | None,
             q_seed: np.ndarray | None = None) -> np.ndarray:
        """Actual T_world_cam (4, 4) of one visit to the commanded T_world_cam (4, 4) (from q_seed's branch if
        given, see :meth:`joints`)."""
        return self.reach(self.joints(T_world_cam, q_seed), rng)

    def moves(self, path: Sequence[np.ndarray], rng: np.random.Generator | None) -> np.ndarray:
        """Actual T_world_cam (n, 4, 4) of one visit to each commanded pose of a path (n, 4, 4), in order."""
        return np.stack([self.reach(q, rng) for q in self.solve(path)])


class Trip(Protocol):
    """What the robot does for one dataset (:class:`.trips.Trip` is one): visits its model pair, then its
    stops."""

    model_views: Sequence[np.ndarray]
    stops: Sequence[Stop]


def trip_path(trip: Trip) -> list[np.ndarray]:
    """The commanded T_world_cam (4, 4) of a trip in the order the robot visits them: model pair, then stops."""
    return [*trip.model_views, *(stop.T_world_cam for stop in trip.stops)]


def repeatability_mm(placed: PlacedRobot, T_world_cam: np.ndarray, rng: np.random.Generator) -> float:
    """ISO 9283 pose repeatability RP = mean(l) + 3 std(l) of the camera positions' distances l from their mean
    over ISO_9283_CYCLES visits to T_world_cam (4, 4), mm (the data sheet's figure, at the camera)."""
    q = placed.joints(T_world_cam)
    positions = np.stack([placed.reach(q, rng)[:3, 3] for _ in range(ISO_9283_CYCLES)])
    distances = np.linalg.norm(positions - positions.mean(axis=0), axis=1)
    return float(distances.mean() + 3 * distances.std(ddof=1))


def accuracy(placed: PlacedRobot, arc_trips: Sequence[Trip], line_trips: Sequence[Trip],
             rng: np.random.Generator) -> dict[str, float]:
    """How far one visit of every trip lands from what was commanded, in the terms that matter to the protocol:
    the absolute error of every pose (E_t mm, E_r deg as IV-C), the model pair's baseline (the relative move
    the target model is triangulated from, III-B: its length, direction and vector error in the first model
    camera's frame), the viewing angle theta of every stop from the model view (III-D) and the line stops'
    distance x from the line start (V-A), and the repeatability at the first model view. Returns mean and p95
    (max for the baselines, one per trip) of the absolute values, flat, for a stage's metrics."""
    if not (arc_trips or line_trips):
        raise ValueError("accuracy: arc_trips and line_trips are both empty; it needs at least one trip")
    E_t, E_r, base_length, base_direction, base_vector, theta, x = ([] for _ in range(7))
    for kind, trips in (("arc", arc_trips), ("line", line_trips)):
        for trip in trips:
            commanded = np.stack(trip_path(trip))
            actual = placed.moves(commanded, rng)
            errors = pose_errors(actual, commanded)
            E_t += list(errors[0])
            E_r += list(errors[1])
            n_views = len(trip.model_views)
            b_actual = (inverse_pose(actual[0]) @ actual[1])[:3, 3]
            b_commanded = (inverse_pose(commanded[0]) @ commanded[1])[:3, 3]
            base_length.append(np.linalg.norm(b_actual) - np.linalg.norm(b_commanded))
            base_direction.append(np.degrees(np.arctan2(np.linalg.norm(np.cross(b_actual, b_commanded)),
                                                        np.dot(b_actual, b_commanded))))
            base_vector.append(np.linalg.norm(b_actual - b_commanded))
            stops = actual[n_views:]
            theta += [rotation_angle_deg(actual[0, :3, :3], T[:3, :3]) - stop.theta_deg
                      for T, stop in zip(stops, trip.stops)]
            if kind == "line":
                x += [np.linalg.norm(T[:3, 3] - stops[0, :3, 3]) - stop.x_mm for T, stop in zip(stops, trip.stops)]
    first_view = (arc_trips or line_trips)[0].model_views[0]
    summary = {"repeatability_mm": repeatability_mm(placed, first_view, rng)}
    for name, values, spread in (("abs_position_mm", E_t, "p95"), ("abs_orientation_deg", E_r, "p95"),
                                 ("baseline_length_error_mm", base_length, "max"),
                                 ("baseline_direction_error_deg", base_direction, "max"),
                                 ("baseline_error_mm", base_vector, "max"),
                                 ("theta_error_deg", theta, "p95"), ("line_x_error_mm", x, "p95")):
        if values:
            values = np.abs(values)
            summary[f"{name}_mean"] = float(values.mean())
            summary[f"{name}_{spread}"] = float(values.max() if spread == "max" else np.percentile(values, 95))
    return summary
