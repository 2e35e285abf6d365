"""The robot carrying the camera: UR5e kinematics against independent references, its error model's invariants,
placement, the ring-down, and the ``generate.robot`` params' refusals."""

import math

import numpy as np
import pytest

from params_cases import refusal, with_value
from poseintegrity import kinematics
from poseintegrity.config import ParamsError, load_params, parse_params
from poseintegrity.denavit_hartenberg import UR5E
from poseintegrity.poses import pose_errors
from poseintegrity.scenes import ringdown, robot, trajectories
from poseintegrity.seeding import keyed_rng
from repository import ROOT

ROBOT = load_params(ROOT / "params.yaml").generate.robot
AIM = np.array([0.0, 0.0, 150.0])
VIEW_DIR = np.array([0.0, -math.cos(math.radians(50)), math.sin(math.radians(50))])  # 50 deg elevation


def exact(params=ROBOT):
    """params with every error switched off."""
    return params.model_copy(update={
        "dh_errors": params.dh_errors.model_copy(update={"length_std_mm": 0.0, "twist_std_deg": 0.0,
                                                         "joint_offset_std_deg": 0.0}),
        "hand_eye_errors": params.hand_eye_errors.model_copy(update={"translation_std_mm": 0.0,
                                                                     "rotation_std_deg": 0.0}),
        "joint_repeatability_std_deg": 0.0})


class Trip:
    def __init__(self, model_views, stops):
        self.model_views, self.stops = model_views, stops


def trips(n_stops=6):
    """A scene like generate's: a model pair 320 mm from the aim point, arcs at azimuths 0, 90, 270 (45 deg), and
    a line of 150 mm from its own model pair 220 mm away."""
    views = trajectories.model_pair(AIM, VIEW_DIR, 320.0, 20.0)
    arcs = [Trip(views, trajectories.arc(views[0], AIM, az, 45.0, n_stops)) for az in (0.0, 90.0, 270.0)]
    line_views = trajectories.model_pair(AIM, VIEW_DIR, 220.0, 20.0)
    lines = [Trip(line_views, trajectories.line(line_views[0], AIM, 5.0, 150.0, n_stops))]
    return arcs, lines


@pytest.fixture(scope="module")
def placed():
    arcs, lines = trips()
    arm = robot.Robot.from_params(ROBOT, keyed_rng(7, "robot"))
    return arm.placed([robot.trip_path(t) for t in arcs + lines], AIM, "test_scene")


# --- kinematics ---

def test_a_pose_has_eight_ik_solutions_one_per_branch():
    """A UR arm reaches a generic pose in 8 ways (shoulder, elbow, wrist each either way): the seeds of the first
    solution find them all, each on its own branch."""
    T = kinematics.forward(UR5E, np.radians([20.0, -100.0, 95.0, -60.0, 80.0, 30.0]))
    solutions = []
    for seed in robot._seeds(T[:3, 3]):
        q = kinematics.inverse(UR5E, T, seed)
        if q is not None and not any(np.allclose(q, other, atol=1e-6) for other in solutions):
            solutions.append(q)
    assert len(solutions) == 8
    assert len({kinematics.branch(UR5E, q) for q in solutions}) == 8


# --- the error model ---

def test_an_exact_robot_lands_where_commanded():
    arcs, lines = trips()
    arm = robot.Robot.from_params(exact(), keyed_rng(7, "robot"))
    placed = arm.placed([robot.trip_path(t) for t in arcs + lines], AIM, "test_scene")
    for trip in arcs + lines:
        path = np.stack(robot.trip_path(trip))
        np.testing.assert_allclose(placed.moves(path, keyed_rng(1, "visit")), path, atol=1e-9)


def test_robots_are_drawn_from_their_seed():
    a, b, c = (robot.Robot.from_params(ROBOT, keyed_rng(seed, "robot")) for seed in (7, 7, 8))
    np.testing.assert_array_equal(a.actual.a, b.actual.a)
    np.testing.assert_array_equal(a.T_flange_cam_estimate, b.T_flange_cam_estimate)
    assert not np.array_equal(a.actual.a, c.actual.a)


def test_first_solution_is_elbow_up_and_paths_stay_on_its_branch(placed):
    arcs, _ = trips()
    q = placed.solve(robot.trip_path(arcs[0]))
    assert robot.elbow_up(UR5E, q[0])
    assert np.max(np.abs(kinematics.wrap(np.diff(q, axis=0)))) < np.radians(15)
    # the arc's first stop is the model view again: the same joint angles, so the same systematic error
    np.testing.assert_allclose(q[2], q[0], atol=1e-9)


def test_a_revisit_keeps_the_systematic_error_and_draws_new_repeatability(placed):
    T = trips()[0][0].model_views[0]
    systematic = placed.move(T, None)
    np.testing.assert_array_equal(systematic, placed.move(T, None))
    assert pose_errors(systematic, T)[0] > 0.1  # off by the arm's error, mm
    rng = keyed_rng(1, "visits")
    visits = np.stack([placed.move(T, rng) for _ in range(3)])
    assert not np.allclose(visits[0], visits[1], atol=1e-6)
    assert np.all(pose_errors(visits, systematic)[0] < 0.05)  # within the repeatability, mm


def test_repeatability_is_the_joint_noise_through_the_jacobian_and_the_data_sheets(placed):
    """The camera's scatter over visits is J diag(joint std^2) J^T (linear); with params.yaml's joint std the
    ISO 9283 RP is the UR5e data sheet's 0.03 mm, within configuration spread."""
    T = trips()[0][0].model_views[0]
    q = placed.joints(T)
    rng = keyed_rng(2, "visits")
    positions = np.stack([placed.reach(q, rng)[:3, 3] for _ in range(2000)])
    R_world_base = placed.T_world_base[:3, :3]
    J = kinematics.jacobian(placed.robot.actual, q)
    # the camera centre moves with the flange plus omega x (camera - flange), base frame
    offset = kinematics.forward(placed.robot.actual, q)[:3, :3] @ placed.robot.T_flange_cam[:3, 3]
    J_cam = J[:3] + np.cross(J[3:].T, offset).T
    expected = R_world_base @ J_cam @ J_cam.T @ R_world_base.T * placed.robot.joint_std_rad**2
    np.testing.assert_allclose(np.cov(positions.T), expected, atol=0.1 * np.abs(expected).max())
    assert 0.02 <= robot.repeatability_mm(placed, T, rng) <= 0.05


def test_a_20_mm_move_errs_much_less_than_the_absolute_pose(placed):
    """The baseline the target model is triangulated from is off by hundredths of a mm, the poses by ~1 mm
    (measured here: baseline error ~0.05 mm, absolute ~1 mm)."""
    arcs, lines = trips()
    summary = robot.accuracy(placed, arcs, lines, keyed_rng(3, "accuracy"))
    assert summary["abs_position_mm_mean"] > 0.3
    assert summary["baseline_error_mm_max"] < summary["abs_position_mm_mean"] / 5
    assert summary["baseline_length_error_mm_max"] < 0.1
    assert summary["theta_error_deg_p95"] < 0.1 < 2.25  # far below the arcs' stop spacing
    assert summary["line_x_error_mm_p95"] < 0.2


# --- placement ---

def test_placement_is_deterministic_and_on_the_table(placed):
    arcs, lines = trips()
    again = placed.robot.placed([robot.trip_path(t) for t in arcs + lines], AIM, "test_scene")
    np.testing.assert_array_equal(again.T_world_base, placed.T_world_base)
    assert placed.T_world_base[2, 3] == 0.0
    np.testing.assert_allclose(placed.T_world_base[:3, 2], [0, 0, 1])


def test_an_unreachable_scene_is_named():
    views = trajectories.model_pair(AIM, VIEW_DIR, 1500.0, 20.0)  # the camera 1.5 m away: out of reach
    arm = robot.Robot.from_params(ROBOT, keyed_rng(7, "robot"))
    with pytest.raises(robot.ReachError, match="scene far_scene"):
        arm.placed([views], AIM, "far_scene")


def test_a_camera_under_the_table_is_unreachable(placed):
    low = np.array([0.0, -math.cos(math.radians(-5)), math.sin(math.radians(-5))])  # looking up from below
    T_world_cam = trajectories.model_pair(np.array([0.0, 0.0, 20.0]), low, 300.0, 20.0)[0]
    assert T_world_cam[2, 3] < 0
    with pytest.raises(robot.ReachError, match="above the table"):
        placed.joints(T_world_cam)


# --- ring-down ---

def test_ring_down_decays_by_its_logarithmic_decrement():
    vibration = ringdown.ring_down(ROBOT.ring_down, keyed_rng(4, "ring"))
    period = 2 * np.pi / vibration.omega_d
    t = np.linspace(0.0, 1.0, 200_001)
    angle = vibration.angle(t)
    peaks = t[1:-1][(angle[1:-1] > angle[:-2]) & (angle[1:-1] > angle[2:])]
    assert np.diff(peaks) == pytest.approx(period, rel=1e-3)
    zeta = ROBOT.ring_down.damping_ratio
    ratio = vibration.angle(peaks[1:]) / vibration.angle(peaks[:-1])
    np.testing.assert_allclose(ratio, np.exp(-2 * np.pi * zeta / np.sqrt(1 - zeta**2)), rtol=1e-4)
    assert np.abs(angle).max() <= np.radians(ROBOT.ring_down.amplitude_deg) + 1e-15


def test_ring_down_rate_is_the_derivative_and_the_exposure_samples_it():
    vibration = ringdown.ring_down(ROBOT.ring_down, keyed_rng(5, "ring"))
    t, h = np.array([0.05, 0.1, 0.2]), 1e-7
    np.testing.assert_allclose(vibration.angular_rate(t), (vibration.angle(t + h) - vibration.angle(t - h)) / (2 * h),
                               rtol=1e-5)
    exposure = vibration.exposure(0.1, 0.11, 5)
    np.testing.assert_allclose(exposure.mid, vibration.rotation(0.105))
    np.testing.assert_allclose(exposure.path[[0, -1]], vibration.rotation(np.array([0.1, 0.11])))
    np.testing.assert_allclose(np.linalg.norm(exposure.path, axis=1), np.abs(vibration.angle(exposure.times_s)))
    with pytest.raises(ValueError, match="t0_s"):
        vibration.exposure(0.2, 0.1, 5)


# --- params ---

def several(raw, values):
    for key, value in values.items():
        raw = with_value(raw, key, value)
    return raw


BAD_VALUES = [
    ("generate.robot.dh_errors.length_std_mm", 10.0, "generate.robot.dh_errors.length_std_mm"),
    ("generate.robot.joint_repeatability_std_deg", 0.5, "generate.robot.joint_repeatability_std_deg"),
    ("generate.robot.mount.rotation_deg", [200.0, 0.0, 0.0], "generate.robot.mount.rotation_deg"),
    ("generate.robot.mount.translation_mm", [0.0, 0.0, 900.0], "generate.robot.mount.translation_mm.2"),
    ("generate.robot.placement.base_distances_mm", [600, 600], "generate.robot.placement.base_distances_mm"),
    ("generate.robot.placement.min_manipulability", 1.5, "generate.robot.placement.min_manipulability"),
    ("generate.robot.ring_down.damping_ratio", 1.0, "generate.robot.ring_down.damping_ratio"),
    ("generate.robot.ring_down.natural_frequency_hz", 0.0, "generate.robot.ring_down.natural_frequency_hz"),
]


@pytest.mark.parametrize("key, value, expected", BAD_VALUES)
def test_bad_robot_value_names_its_key(tiny_raw, key, value, expected):
    assert f"{expected}:" in refusal(tiny_raw, key, value)


@pytest.mark.parametrize("changes, key", [
    # twist errors of 1 deg turn each stop by ~2.5 deg, more than the 2.25 deg between the arcs' stops
    ({"generate.arcs.n_stops": 20, "generate.robot.dh_errors.twist_std_deg": 1.0}, "robot.dh_errors.twist_std_deg"),
    # encoder zeros off by 1 deg move the camera by up to ~60 mm, more than the 25 mm between the lines' stops
    ({"generate.robot.dh_errors.joint_offset_std_deg": 1.0}, "robot.dh_errors.joint_offset_std_deg"),
    # 5 mm link errors move it by ~17 mm, more than the 10 mm of the paper's line stops
    ({"generate.lines.n_stops": 15, "generate.robot.dh_errors.length_std_mm": 5.0}, "robot.dh_errors.length_std_mm"),
])
def test_a_robot_erring_more_than_the_stop_spacing_is_refused(tiny_raw, changes, key):
    parse_params(several(tiny_raw, {k: v for k, v in changes.items() if "robot" not in k}))  # valid without it
    with pytest.raises(ParamsError, match=f"generate.{key}: the robot's expected"):
        parse_params(several(tiny_raw, changes))
