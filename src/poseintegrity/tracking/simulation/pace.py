"""The pace of a motion: its truth's RMS rates, and the accuracy recording's motion set to a given pace (motion (c),
the paper's pace, params.yaml ``pace``).

Why a pace (section III, Fig. 9): a filter lagging tau behind a motion whose rate along one axis has RMS w errs by about
w tau along it, so the published lag, 199.5 ms, alone gives the published per-axis UKF errors, 1.51 deg and 1.77 mm, at
w = 1.51 deg / 0.1995 s = 0.132 rad/s per Euler angle and v = 1.77 mm / 0.1995 s = 8.9 mm/s per position axis: the
fastest pace the paper's numbers allow (its measurement noise adds to the lag's error).
"""

from __future__ import annotations

import copy

import numpy as np
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.params.track import MotionParams, PaceParams
from poseintegrity.tracking.simulation.errors import EULER_SEQUENCE
from poseintegrity.tracking.simulation.motion import Trajectory, simulate_trajectory

EULER_NAMES = ("yaw", "pitch", "roll")  # EULER_SEQUENCE's angles: about y, x, z (Unity)


def _rms_per_axis(rates: np.ndarray, names: tuple[str, str, str]) -> dict[str, float]:
    """RMS of each column of rates (k, 3) by name, and their mean ("mean", the paper's way of averaging axes)."""
    per_axis = {name: float(np.sqrt(np.mean(column**2))) for name, column in zip(names, rates.T)}
    return {**per_axis, "mean": float(np.mean(list(per_axis.values())))}


def trajectory_pace(trajectory: Trajectory) -> dict[str, dict[str, float]]:
    """The truth's RMS rates over its whole grid, per axis and their mean: ``euler_rad_s`` of the Unity Euler angles
    (yaw, pitch, roll; :data:`~.errors.EULER_SEQUENCE`, unwrapped and differenced over the grid step, so the jumps
    near pitch +-90 deg count, as the paper's Euler errors count them), ``body_rad_s`` of the body angular velocity
    (x, y, z: what a gyro on the tool reads) and ``velocity_mm_s`` of the position (x, y, z)."""
    dt = trajectory.t[1] - trajectory.t[0]
    euler = np.unwrap(Rotation.from_quat(trajectory.quat).as_euler(EULER_SEQUENCE), axis=0)
    return {"euler_rad_s": _rms_per_axis(np.diff(euler, axis=0) / dt, EULER_NAMES),
            "body_rad_s": _rms_per_axis(trajectory.omega_body, ("x", "y", "z")),
            "velocity_mm_s": _rms_per_axis(np.diff(trajectory.position, axis=0) / dt * 1000.0, ("x", "y", "z"))}


def paced_motion(motion: MotionParams, pace: PaceParams, rng: np.random.Generator) -> MotionParams:
    """``motion`` with omega_std and accel_std set so that the trajectory :func:`~.motion.simulate_trajectory` draws
    next from ``rng`` (whose state is left as it was) has the RMS rates of ``pace``: the mean over the three Euler
    angles of their RMS rates, and the mean over x, y, z of the RMS velocities (:func:`trajectory_pace`).

    The translation is linear in accel_std (it starts at rest at home), so one trial scales it exactly; the Euler
    rates are not linear in omega_std (a faster turn reaches other orientations, and near pitch +-90 deg yaw and roll
    turn faster than the body does), so omega_std is the root of the Euler rate's miss on the same noise (Brent's
    method between 1/8 and 2 times the target: the Euler rates' mean exceeds the body's, which is omega_std).
    """
    def measured(omega_std: float, accel_std: float) -> dict[str, dict[str, float]]:
        trial = motion.model_copy(update={"omega_std": omega_std, "accel_std": accel_std})
        return trajectory_pace(simulate_trajectory(trial, copy.deepcopy(rng)))

    w = pace.euler_rate_rms
    accel_std = pace.velocity_rms * 1000.0 / measured(w, 1.0)["velocity_mm_s"]["mean"]
    miss = lambda omega_std: measured(omega_std, accel_std)["euler_rad_s"]["mean"] - w  # noqa: E731
    low, high = w / 8, 2 * w
    if not miss(low) < 0 < miss(high):
        raise PoseIntegrityError(f"pace.euler_rate_rms: no OU spread between {low:g} and {high:g} rad/s gives an RMS Euler "
                                 f"rate of {w:g} rad/s on this draw (the motion's orientation sits near pitch +-90 deg)")
    return motion.model_copy(update={"omega_std": brentq(miss, low, high, xtol=1e-6 * w), "accel_std": accel_std})
