import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.tracking.simulation.motion import brief_occlusions, sample_sensors, simulate_hand_motion, simulate_trajectory

from tracking.track_section import TRACK

TINY = TRACK.motion.model_copy(update={"duration_s": 4.0, "occlusions": [(2.0, 0.5)]})


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


def test_full_turns_make_whole_revolutions_and_brief_occlusions_hide_about_the_planned_share():
    hand = TRACK.hand.model_copy(update={"pause_s": (0.5, 0.5), "turn_s": (2.0, 2.0), "wobble_std": 0.0})
    motion = TRACK.motion.model_copy(update=dict(duration_s=10.2))  # turns about x, y, z, x; the next one would start at 10.5 s
    traj = simulate_hand_motion(motion, hand, np.random.default_rng(5))
    turned = np.abs(traj.omega_body).sum(axis=0) * motion.sim_dt / (2 * np.pi)  # turns about x, y, z
    np.testing.assert_allclose(turned, np.round(turned), atol=0.01)
    assert (np.round(turned) >= 1).all()  # every axis gets full turns
    R = Rotation.from_quat(traj.quat)
    assert np.abs((R[:-1].inv() * R[1:]).as_rotvec() / motion.sim_dt - traj.omega_body[:-1]).max() < 1e-9
    t = np.arange(0, 2000, 0.046)
    hidden = brief_occlusions(t, 4, TRACK.hand, np.random.default_rng(6))
    expected = TRACK.hand.occlusion_rate_hz * np.mean(TRACK.hand.occlusion_s)
    assert abs(hidden.mean() - expected) < 0.3 * expected
