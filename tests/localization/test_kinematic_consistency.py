"""The estimates' disagreement with the robot's kinematics (localization/kinematic_consistency.py) against known
answers built with scipy's rotations: none for exact estimates and robot poses, an estimate's own error when the
robot is exact, the robot's error when the estimate is exact, NaN where a pose is unknown."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity.errors import ArgumentError
from poseintegrity.localization.kinematic_consistency import kinematic_errors, reported_pose


def rigid(rotvec_deg, t) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(np.radians(rotvec_deg)).as_matrix()
    T[:3, 3] = t
    return T


RNG = np.random.default_rng(3)
T_BASE_BOARD = rigid([10.0, -20.0, 5.0], [400.0, -50.0, 30.0])
T_BASE_CAM = np.stack([rigid(RNG.normal(0, 30, 3), RNG.normal(0, 200, 3)) for _ in range(6)])
TRUTH = np.linalg.inv(T_BASE_CAM) @ T_BASE_BOARD  # T_cam_board of a board that stands still in the base frame


def test_exact_estimates_and_robot_poses_agree():
    E_t, E_r = kinematic_errors(T_BASE_CAM, TRUTH, T_BASE_BOARD)
    np.testing.assert_allclose(E_t, 0.0, atol=1e-9)
    np.testing.assert_allclose(E_r, 0.0, atol=1e-5)


def test_an_exact_robot_observes_the_estimates_own_error():
    shift = np.array([0.3, -1.2, 2.0])  # mm, in the camera frame: E_t = |shift|
    off = rigid([0, 0, 0], shift) @ TRUTH
    E_t, E_r = kinematic_errors(T_BASE_CAM, off, T_BASE_BOARD)
    np.testing.assert_allclose(E_t, np.linalg.norm(shift), rtol=1e-9)
    np.testing.assert_allclose(E_r, 0.0, atol=1e-5)
    turned = TRUTH @ rigid([0.0, 1.5, 0.0], [0, 0, 0])  # about the board origin: E_r 1.5 deg, the origin stays
    E_t, E_r = kinematic_errors(T_BASE_CAM, turned, T_BASE_BOARD)
    np.testing.assert_allclose(E_t, 0.0, atol=1e-9)
    np.testing.assert_allclose(E_r, 1.5, rtol=1e-6)


def test_an_exact_estimate_observes_the_robots_error():
    """The robot reports T_base_cam but the camera stood at T_base_cam @ delta: the board origin is seen
    displaced by the same motion, so the disagreement is delta's action on the board origin."""
    delta = rigid([0.0, 0.0, 0.05], [0.1, 0.0, -0.2])
    actual = T_BASE_CAM @ delta
    seen = np.linalg.inv(actual) @ T_BASE_BOARD  # what an exact estimate gives from where the camera really was
    E_t, E_r = kinematic_errors(T_BASE_CAM, seen, T_BASE_BOARD)
    origin_in_cam = seen[:, :3, 3]
    expected = np.linalg.norm(origin_in_cam - (np.linalg.inv(T_BASE_CAM) @ T_BASE_BOARD)[:, :3, 3], axis=1)
    np.testing.assert_allclose(E_t, expected, rtol=1e-9)
    assert np.all(E_t > 0.1)
    np.testing.assert_allclose(E_r, 0.05, rtol=1e-4)


def test_unknown_poses_give_nan_and_non_rigid_ones_are_refused():
    for values in (None, np.nan, [np.nan] * 16, [1.0] * 16, [0.0] * 15):
        assert np.isnan(reported_pose(values)).all()
    np.testing.assert_array_equal(reported_pose(T_BASE_CAM[0].ravel().tolist()), T_BASE_CAM[0])
    E_t, E_r = kinematic_errors(reported_pose(None), TRUTH[0], T_BASE_BOARD)
    assert np.isnan(E_t) and np.isnan(E_r)
    E_t, _ = kinematic_errors(T_BASE_CAM[0], TRUTH[0], np.full((4, 4), np.nan))
    assert np.isnan(E_t)
    with pytest.raises(ArgumentError):
        kinematic_errors(T_BASE_CAM[0], 2.0 * TRUTH[0], T_BASE_BOARD)
