import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from poseintegrity.poses import pose_errors, pose_matrix
from poseintegrity.tracking.simulation.errors import EULER_SEQUENCE, axis_errors, error_columns, rms, rms_summary


def _poses(rotvecs, positions):
    return pose_matrix(Rotation.from_rotvec(rotvecs).as_matrix(), np.asarray(positions, float))


def test_per_axis_rms_is_the_norm_rms_over_sqrt3_for_isotropic_errors():
    rng = np.random.default_rng(0)
    n = 20000
    truth = _poses(rng.normal(0, 0.5, (n, 3)), rng.normal(0, 0.1, (n, 3)))
    est = truth.copy()
    est[:, :3, 3] += rng.normal(0, 0.001, (n, 3))  # 1 mm per axis
    summary = rms_summary(pd.DataFrame(error_columns(est, truth)))
    assert abs(summary["axis_mm"] - 1.0) < 0.02 and abs(summary["norm_mm"] - np.sqrt(3)) < 0.03
    assert summary["geodesic_deg"] < 1e-6 and summary["euler_deg"] < 1e-6


def test_euler_differences_follow_unitys_convention_and_wrap():
    # Unity: R = R_y(yaw) R_x(pitch) R_z(roll); a yaw error of 2 deg shows in yaw only, also across +-180 deg
    truth = pose_matrix(Rotation.from_euler(EULER_SEQUENCE, [[179.0, 10.0, -20.0]], degrees=True).as_matrix(), np.zeros((1, 3)))
    est = pose_matrix(Rotation.from_euler(EULER_SEQUENCE, [[-179.0, 10.0, -20.0]], degrees=True).as_matrix(), np.zeros((1, 3)))
    R_y = Rotation.from_euler("y", 179.0, degrees=True).as_matrix()
    np.testing.assert_allclose(truth[0, :3, :3], R_y @ Rotation.from_euler("x", 10.0, degrees=True).as_matrix()
                               @ Rotation.from_euler("z", -20.0, degrees=True).as_matrix(), atol=1e-12)
    _, d_euler = axis_errors(est, truth)
    np.testing.assert_allclose(d_euler[0], [2.0, 0.0, 0.0], atol=1e-9)
    _, geodesic = pose_errors(est, truth)
    np.testing.assert_allclose(geodesic, [2.0], atol=1e-9)


def test_missing_poses_give_nan_rows_not_numbers():
    truth = _poses(np.zeros((2, 3)), np.zeros((2, 3)))
    est = truth.copy()
    est[1] = np.nan
    columns = error_columns(est, truth)
    assert all(np.isnan(v[1]) and np.isfinite(v[0]) for v in columns.values())


def test_rms_leaves_out_nan():
    assert rms(np.array([3.0, -4.0, np.nan])) == np.sqrt(12.5)
