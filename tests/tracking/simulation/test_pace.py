"""Motion (c), the paper's pace (tracking/simulation/pace.py): the pace the paper's numbers give, and a motion that
has it, measured independently of the module's own measure."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity.paper_results import BLACK_RESULTS
from poseintegrity.params.track import PaceParams
from poseintegrity.seeding import keyed_rng
from poseintegrity.tracking.simulation.motion import simulate_trajectory
from poseintegrity.tracking.simulation.pace import paced_motion, trajectory_pace
from tracking.track_section import TRACK


def test_the_pace_is_the_papers_errors_over_its_lag():
    lag_s = BLACK_RESULTS["lag_ms"] / 1000.0
    assert TRACK.pace.euler_rate_rms == pytest.approx(math.radians(BLACK_RESULTS["rms_deg"]["ukf"]) / lag_s, rel=1e-3)
    assert TRACK.pace.velocity_rms == pytest.approx(BLACK_RESULTS["rms_mm"]["ukf"] / 1000.0 / lag_s, rel=1e-3)


def euler_rates(trajectory) -> np.ndarray:
    """(T, 3) rates (rad/s) of the Unity angles a, b, c of R = R_y(a) R_x(b) R_z(c), from the body angular velocity
    by the kinematic equations, w_body = R_z(c)^T R_x(b)^T e_y a' + R_z(c)^T e_x b' + e_z c' (no differencing)."""
    a, b, c = Rotation.from_quat(trajectory.quat).as_euler("YXZ").T
    Rz_T, Rx_T = Rotation.from_euler("z", -c[:, None]), Rotation.from_euler("x", -b[:, None])
    columns = np.stack([Rz_T.apply(Rx_T.apply(np.tile([0.0, 1.0, 0.0], (len(a), 1)))), Rz_T.apply(np.tile([1.0, 0.0, 0.0], (len(a), 1))),
                        np.tile([0.0, 0.0, 1.0], (len(a), 1))], axis=-1)
    return np.linalg.solve(columns, trajectory.omega_body[..., None])[..., 0]


@pytest.mark.parametrize("euler_rate, velocity", [(0.1321, 0.00887), (0.4, 0.03)])
def test_a_paced_motion_has_the_rates_it_asks_for(euler_rate, velocity):
    motion = TRACK.motion.model_copy(update={"duration_s": 30.0})
    rng = keyed_rng(3, "paced")
    state = rng.bit_generator.state
    paced = paced_motion(motion, PaceParams(euler_rate_rms=euler_rate, velocity_rms=velocity), rng)
    assert rng.bit_generator.state == state  # the draw is left to the recording
    truth = simulate_trajectory(paced, rng)
    rates = euler_rates(truth)
    away_from_pitch_90 = np.abs(Rotation.from_quat(truth.quat).as_euler("YXZ")[:, 1]) < np.radians(85)  # where the solve is well posed
    assert away_from_pitch_90.mean() > 0.99
    assert np.sqrt(np.mean(rates[away_from_pitch_90] ** 2, axis=0)).mean() == pytest.approx(euler_rate, rel=0.03)
    assert np.sqrt(np.mean(np.gradient(truth.position, truth.t, axis=0) ** 2, axis=0)).mean() == pytest.approx(velocity, rel=0.01)
    assert trajectory_pace(truth)["body_rad_s"]["mean"] == pytest.approx(np.sqrt(np.mean(truth.omega_body**2, axis=0)).mean())


def test_the_pace_scales_the_motion_down():
    """The Euler rates of a slow motion are its body rates (orientation near where it started): omega_std is then
    about the target, and twice the target's motion is about twice as fast."""
    motion = TRACK.motion.model_copy(update={"duration_s": 30.0})
    slow = paced_motion(motion, PaceParams(euler_rate_rms=0.05, velocity_rms=0.005), keyed_rng(4, "slow"))
    fast = paced_motion(motion, PaceParams(euler_rate_rms=0.1, velocity_rms=0.01), keyed_rng(4, "slow"))
    assert slow.omega_std == pytest.approx(0.05, rel=0.2) and fast.accel_std == pytest.approx(2 * slow.accel_std, rel=1e-9)
