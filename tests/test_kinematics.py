"""Kinematics of the UR5e (poseintegrity.kinematics on the DH table of poseintegrity.denavit_hartenberg): forward
kinematics against elementary rotations, the Jacobian against finite differences, the closed-form manipulability,
and the numerical inverse."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity import kinematics
from poseintegrity.denavit_hartenberg import UR5E


def test_forward_kinematics_at_zero_is_the_stretched_arm_of_the_dh_table():
    """At q = 0 a UR arm lies stretched along -x: flange at (a2 + a3, -(d4 + d6), d1 - d5), its z along -y."""
    T = kinematics.forward(UR5E, np.zeros(6))
    np.testing.assert_allclose(T[:3, 3], [-425.0 - 392.2, -(133.3 + 99.6), 162.5 - 99.7], atol=1e-12)
    np.testing.assert_allclose(T[:3, :3], [[1, 0, 0], [0, 0, -1], [0, 1, 0]], atol=1e-12)


def test_forward_kinematics_equals_a_chain_of_elementary_rotations():
    """The same DH chain written with scipy rotations and translations, one elementary motion at a time."""
    for q in np.random.default_rng(1).uniform(-np.pi, np.pi, (5, 6)):
        R, p = Rotation.identity(), np.zeros(3)
        for i in range(6):
            R = R * Rotation.from_euler("z", q[i])
            p = p + R.apply([0.0, 0.0, UR5E.d[i]]) + R.apply([UR5E.a[i], 0.0, 0.0])
            R = R * Rotation.from_euler("x", UR5E.alpha[i])
        T = kinematics.forward(UR5E, q)
        np.testing.assert_allclose(T[:3, 3], p, atol=1e-9)
        np.testing.assert_allclose(T[:3, :3], R.as_matrix(), atol=1e-12)


def test_jacobian_is_the_derivative_of_forward_kinematics():
    q = np.radians([20.0, -100.0, 95.0, -60.0, 80.0, 30.0])
    J, h = kinematics.jacobian(UR5E, q), 1e-6
    for i in range(6):
        dq = np.zeros(6)
        dq[i] = h
        T_plus, T_minus = kinematics.forward(UR5E, q + dq), kinematics.forward(UR5E, q - dq)  # central differences
        np.testing.assert_allclose((T_plus[:3, 3] - T_minus[:3, 3]) / (2 * h), J[:3, i], atol=1e-5)
        omega = Rotation.from_matrix(T_plus[:3, :3] @ T_minus[:3, :3].T).as_rotvec() / (2 * h)
        np.testing.assert_allclose(omega, J[3:, i], atol=1e-8)


def test_manipulability_is_the_closed_form_determinant_of_a_ur_arm():
    a2, a3, d5 = UR5E.a[1], UR5E.a[2], UR5E.d[4]
    for q in np.random.default_rng(2).uniform(-np.pi, np.pi, (5, 6)):
        reach = a2 * np.cos(q[1]) + a3 * np.cos(q[1] + q[2]) + d5 * np.sin(q[1] + q[2] + q[3])
        expected = abs(np.sin(q[2]) * np.sin(q[4]) * reach) / (abs(a2) + abs(a3))
        assert kinematics.manipulability(UR5E, q) == pytest.approx(expected, rel=1e-9)
    assert kinematics.manipulability(UR5E, np.radians([0, -90, 0, -90, 90, 0])) == pytest.approx(0.0, abs=1e-12)


def test_inverse_of_forward_returns_the_joint_angles():
    rng = np.random.default_rng(3)
    for _ in range(10):
        q = rng.uniform(-np.pi, np.pi, 6)
        if kinematics.manipulability(UR5E, q) < 0.05:
            continue
        T = kinematics.forward(UR5E, q)
        solution = kinematics.inverse(UR5E, T, q + rng.normal(0, 0.05, 6))
        np.testing.assert_allclose(kinematics.wrap(solution - q), 0.0, atol=1e-9)
        np.testing.assert_allclose(kinematics.forward(UR5E, solution), T, atol=1e-9)


def test_rotation_vector_is_scipys_at_every_angle():
    rng = np.random.default_rng(4)
    axes = rng.normal(size=(4, 3))
    for axis in axes / np.linalg.norm(axes, axis=1, keepdims=True):
        for angle in (1e-9, 1e-4, 0.5, 2.0, np.pi - 1e-8):
            R = Rotation.from_rotvec(angle * axis).as_matrix()
            np.testing.assert_allclose(kinematics.rotation_vector(R), Rotation.from_matrix(R).as_rotvec(),
                                       rtol=1e-9, atol=1e-15 if angle < 1 else 1e-7)


def test_inverse_of_a_pose_out_of_reach_is_none():
    far = np.eye(4)
    far[:3, 3] = [2000.0, 0.0, 300.0]
    assert kinematics.inverse(UR5E, far, np.radians([0, -90, 90, -90, 90, 0])) is None
