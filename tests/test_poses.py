"""poseintegrity.poses against independent references: scipy's Rotation, numpy's matrix inverse, a known answer."""

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from poseintegrity.poses import NAN_POSE, inverse, pose_errors, pose_from_rvec_tvec, pose_matrix


def pose(rotvec, t):
    return pose_matrix(Rotation.from_rotvec(rotvec).as_matrix(), np.asarray(t, dtype=float))


def test_known_translation_and_rotation():
    T_true = pose([0.1, -0.2, 0.3], [10.0, 20.0, 300.0])
    T_est = T_true.copy()
    T_est[:3, 3] += [3.0, 4.0, 0.0]
    T_est[:3, :3] = Rotation.from_euler("z", 30, degrees=True).as_matrix() @ T_true[:3, :3]
    E_t_mm, E_r_deg = pose_errors(T_est, T_true)
    assert np.isclose(E_t_mm, 5.0) and np.isclose(E_r_deg, 30.0)


@settings(deadline=None, max_examples=50)
@given(axis=st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda a: np.linalg.norm(a) > 0.1),
       angle=st.floats(0.0, 180.0), seed=st.integers(0, 1000))
def test_rotation_error_is_the_applied_angle_and_symmetric(axis, angle, seed):
    rng = np.random.default_rng(seed)
    T_true = pose(rng.normal(size=3), rng.normal(size=3))
    delta = Rotation.from_rotvec(np.radians(angle) * np.asarray(axis) / np.linalg.norm(axis)).as_matrix()
    T_est = T_true.copy()
    T_est[:3, :3] = delta @ T_true[:3, :3]
    assert np.isclose(pose_errors(T_est, T_true)[1], angle, atol=1e-9)
    assert np.isclose(pose_errors(T_true, T_est)[1], angle, atol=1e-9)


def test_small_angles_keep_their_digits():
    """E_r of a good pose is ~0.1 deg and below: arccos of the trace would give ~1e-6 deg of noise."""
    angles = np.array([1e-7, 1e-4, 0.1])
    R = Rotation.from_rotvec(np.radians(angles)[:, None] * [0.0, 0.0, 1.0]).as_matrix()
    _, E_r = pose_errors(pose_matrix(R, np.zeros((3, 3))), pose_matrix(np.eye(3), np.zeros(3)))
    np.testing.assert_allclose(E_r, angles, rtol=1e-9)


def test_stacks_equal_one_pose_at_a_time_and_scipy():
    rng = np.random.default_rng(3)
    T_est = pose_matrix(Rotation.random(6, random_state=1).as_matrix(), rng.normal(size=(6, 3)))
    T_true = pose_matrix(Rotation.random(6, random_state=2).as_matrix(), rng.normal(size=(6, 3)))
    E_t, E_r = pose_errors(T_est, T_true)
    assert E_t.shape == E_r.shape == (6,)
    for k in range(6):
        assert np.allclose(pose_errors(T_est[k], T_true[k]), (E_t[k], E_r[k]))
    reference = Rotation.from_matrix(T_est[:, :3, :3] @ np.swapaxes(T_true[:, :3, :3], 1, 2)).magnitude()
    np.testing.assert_allclose(E_r, np.degrees(reference), atol=1e-9)
    np.testing.assert_allclose(E_t, np.linalg.norm(T_est[:, :3, 3] - T_true[:, :3, 3], axis=1))


def test_a_failed_or_unknown_pose_gives_nan_only_in_its_row():
    E_t_mm, E_r_deg = pose_errors(NAN_POSE, np.eye(4))
    assert np.isnan(E_t_mm) and np.isnan(E_r_deg)
    T_true = np.stack([np.eye(4), np.eye(4)])
    T_true[1, 0, 3] = np.inf
    E_t, E_r = pose_errors(np.stack([np.eye(4), np.eye(4)]), T_true)
    assert E_t[0] == 0 and E_r[0] == 0 and np.isnan(E_t[1]) and np.isnan(E_r[1])


def test_nan_pose_is_shared_read_only():
    with pytest.raises(ValueError):
        NAN_POSE[0, 0] = 1.0


def test_inverse_is_the_matrix_inverse():
    T = pose_matrix(Rotation.random(4, random_state=5).as_matrix(), np.random.default_rng(5).normal(size=(4, 3)))
    np.testing.assert_allclose(inverse(T), np.linalg.inv(T), atol=1e-12)
    np.testing.assert_allclose(inverse(T[0]) @ T[0], np.eye(4), atol=1e-12)


def test_opencv_pose_maps_points_as_project_points_does():
    rvec, tvec = np.array([0.2, -0.1, 0.4]), np.array([5.0, -3.0, 400.0])
    points = np.random.default_rng(0).normal(size=(5, 3)) * 50
    K = np.array([[800.0, 0, 320], [0, 800, 240], [0, 0, 1]])
    expected, _ = cv2.projectPoints(points, rvec, tvec, K, None)
    T = pose_from_rvec_tvec(rvec, tvec)
    camera = points @ T[:3, :3].T + T[:3, 3]
    projected = camera[:, :2] / camera[:, 2:] * [800.0, 800.0] + [320.0, 240.0]
    np.testing.assert_allclose(projected, expected.reshape(-1, 2), atol=1e-9)
