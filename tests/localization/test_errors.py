import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from poseintegrity.localization.errors import pose_errors


def pose(rotvec, t):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
    T[:3, 3] = t
    return T


def test_known_translation_and_rotation():
    T_true = pose([0.1, -0.2, 0.3], [10.0, 20.0, 300.0])
    T_est = T_true.copy()
    T_est[:3, 3] += [3.0, 4.0, 0.0]
    T_est[:3, :3] = Rotation.from_euler("z", 30, degrees=True).as_matrix() @ T_true[:3, :3]
    E_t_mm, E_r_deg = pose_errors(T_est, T_true)
    assert np.isclose(E_t_mm, 5.0) and np.isclose(E_r_deg, 30.0)


@settings(deadline=None, max_examples=50)
@given(axis=st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda a: np.linalg.norm(a) > 0.1),
       angle=st.floats(0.0, 179.0), seed=st.integers(0, 1000))
def test_rotation_error_is_the_applied_angle_and_symmetric(axis, angle, seed):
    rng = np.random.default_rng(seed)
    T_true = pose(rng.normal(size=3), rng.normal(size=3))
    delta = Rotation.from_rotvec(np.radians(angle) * np.asarray(axis) / np.linalg.norm(axis)).as_matrix()
    T_est = T_true.copy()
    T_est[:3, :3] = delta @ T_true[:3, :3]
    assert np.isclose(pose_errors(T_est, T_true)[1], angle, atol=1e-6)
    assert np.isclose(pose_errors(T_true, T_est)[1], angle, atol=1e-6)


def test_failed_pose_gives_nan():
    E_t_mm, E_r_deg = pose_errors(np.full((4, 4), np.nan), np.eye(4))
    assert np.isnan(E_t_mm) and np.isnan(E_r_deg)
