import numpy as np
import pytest
import yaml
from pydantic import ValidationError
from scipy.spatial.transform import Rotation

from poseintegrity.tracking.motion import sample_sensors, simulate_trajectory
from poseintegrity.tracking.params import MotionParams, TrackParams

TINY = MotionParams(duration_s=4.0, occlusions=[(2.0, 0.5)])


def test_same_seed_same_trajectory_and_sensors():
    a = simulate_trajectory(TINY, np.random.default_rng(7))
    b = simulate_trajectory(TINY, np.random.default_rng(7))
    np.testing.assert_array_equal(a.quat, b.quat)
    sa, sb = sample_sensors(a, 4, TINY, np.random.default_rng(1)), sample_sensors(b, 4, TINY, np.random.default_rng(1))
    np.testing.assert_array_equal(sa.gyro, sb.gyro)
    np.testing.assert_array_equal(sa.occluded, sb.occluded)


def test_gyro_matches_the_orientation_and_arrives_two_or_three_times_per_frame():
    traj = simulate_trajectory(TINY, np.random.default_rng(3))
    R = Rotation.from_quat(traj.quat)
    increment = (R[:-1].inv() * R[1:]).as_rotvec() / TINY.sim_dt  # body-frame rate from the orientation
    np.testing.assert_allclose(increment, traj.omega_body[:-1], atol=1e-9)
    sensors = sample_sensors(traj, 4, TINY, np.random.default_rng(4))
    counts = np.diff(np.searchsorted(sensors.gyro_index, sensors.frame_index, side="right"))
    assert set(counts) <= {2, 3}
    t = traj.t[sensors.frame_index]
    assert sensors.occluded[(t >= 2.0) & (t < 2.5)].all()
    assert 0.03 < np.diff(t).mean() < 0.06


def test_params_validate_and_name_the_bad_key():
    raw = yaml.safe_load("seed: 1\nmotion: {duration_s: 5}\nfilter: {alpha: 1.0}\n")
    assert TrackParams.model_validate(raw).motion.duration_s == 5
    with pytest.raises(ValidationError, match="motion.p_occlusion"):
        TrackParams.model_validate({"motion": {"p_occlusion": 1.5}})
    with pytest.raises(ValidationError, match="detection.depth_typo"):
        TrackParams.model_validate({"detection": {"depth_typo": 1}})
    with pytest.raises(ValidationError, match="drop_marker"):
        TrackParams.model_validate({"drop_marker": 9})
