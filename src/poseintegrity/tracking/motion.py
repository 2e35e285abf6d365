"""Hand-like motion of the marker body and its sensor timeline (section II-F).

Random linear and angular accelerations are integrated into motion: the linear acceleration is an
Ornstein-Uhlenbeck (OU) process pulled back to a home position by a spring and damped, so the tool stays in
front of the camera; the body angular velocity is an OU process whose spread gives full turns about every
axis.  Marker frames arrive every ``frame_interval_s`` (+- jitter, the paper measured 45.98 +- 7.67 ms), and
between two frames the gyro delivers 2 samples with probability P_2, else 3 (P_3 = 1 - P_2).
Each frame gets per-marker occlusions (probability P_o), phantom reflections (P_p per slot) and the
deliberate extended occlusions of the params (all markers hidden).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.tracking.params import MotionParams


@dataclass(frozen=True)
class Trajectory:
    """Ground truth on a uniform grid.

    t : (T,) s; position : (T, 3) m, body origin in the world; quat : (T, 4) scalar-last, R_world_body;
    omega_body : (T, 3) rad/s, angular velocity in the body frame (what a gyro on the tool measures).
    """

    t: np.ndarray
    position: np.ndarray
    quat: np.ndarray
    omega_body: np.ndarray

    def rotation(self, index: np.ndarray) -> np.ndarray:
        """R_world_body (k, 3, 3) at grid indices."""
        return Rotation.from_quat(self.quat[index]).as_matrix()


@numba.njit(cache=True)
def _integrate(noise, dt, home, accel_std, accel_tau, spring, damping, omega_std, omega_tau):  # pragma: no cover
    T = noise.shape[0]
    pos, vel, acc = home.copy(), np.zeros(3), np.zeros(3)
    w = np.zeros(3)
    q = np.array([0.0, 0.0, 0.0, 1.0])  # x, y, z, w
    positions, quats, omegas = np.empty((T, 3)), np.empty((T, 4)), np.empty((T, 3))
    a_acc, a_w = np.exp(-dt / accel_tau), np.exp(-dt / omega_tau)
    s_acc, s_w = accel_std * np.sqrt(1 - a_acc**2), omega_std * np.sqrt(1 - a_w**2)
    k, c = (2 * np.pi * spring) ** 2, 2 * damping * 2 * np.pi * spring
    for i in range(T):
        positions[i], quats[i], omegas[i] = pos, q, w
        vel = vel + dt * (acc - k * (pos - home) - c * vel)
        pos = pos + dt * vel
        angle = np.sqrt(w @ w) * dt  # q <- q * exp(w dt / 2): body-frame increment
        if angle > 0:
            axis = w / np.sqrt(w @ w)
            dq = np.array([axis[0] * np.sin(angle / 2), axis[1] * np.sin(angle / 2), axis[2] * np.sin(angle / 2), np.cos(angle / 2)])
            x1, y1, z1, w1 = q
            x2, y2, z2, w2 = dq
            q = np.array(
                [
                    w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                    w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                    w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
                    w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                ]
            )
            q = q / np.sqrt(q @ q)
        acc = a_acc * acc + s_acc * noise[i, :3]  # OU random acceleration
        w = a_w * w + s_w * noise[i, 3:]  # OU body angular velocity
    return positions, quats, omegas


def simulate_trajectory(motion: MotionParams, rng: np.random.Generator, omega_std: float | None = None) -> Trajectory:
    """Integrate random accelerations into a trajectory of motion.duration_s seconds on a sim_dt grid.

    omega_std : rad/s, overrides motion.omega_std (the large-motion runs of section III use a larger one).
    """
    T = int(round(motion.duration_s / motion.sim_dt)) + 1
    noise = rng.standard_normal((T, 6))
    positions, quats, omegas = _integrate(
        noise, motion.sim_dt, np.array(motion.home_m), motion.accel_std, motion.accel_tau_s, motion.spring_hz,
        motion.damping, motion.omega_std if omega_std is None else omega_std, motion.omega_tau_s,
    )
    return Trajectory(t=np.arange(T) * motion.sim_dt, position=positions, quat=quats, omega_body=omegas)


@dataclass(frozen=True)
class SensorTimeline:
    """When each measurement arrives, as indices into the trajectory grid.

    frame_index : (F,) int, marker frames; occluded : (F, n) bool; n_phantoms : (F,) int;
    gyro_index : (G,) int, gyro samples; gyro : (G, 3) rad/s, body-frame gyro readings with noise.
    """

    frame_index: np.ndarray
    occluded: np.ndarray
    n_phantoms: np.ndarray
    gyro_index: np.ndarray
    gyro: np.ndarray


def sample_sensors(trajectory: Trajectory, n_markers: int, motion: MotionParams, rng: np.random.Generator) -> SensorTimeline:
    """Draw frame times, occlusions, phantom counts and gyro samples for a trajectory (II-F)."""
    dt, T = motion.sim_dt, len(trajectory.t)
    intervals = np.maximum(rng.normal(motion.frame_interval_s, motion.frame_jitter_s, int(trajectory.t[-1] / motion.frame_interval_s) + 10), 4 * dt)
    times = np.cumsum(intervals)
    frame_index = np.rint(times[times < trajectory.t[-1]] / dt).astype(int)
    F = len(frame_index)
    occluded = rng.random((F, n_markers)) < motion.p_occlusion
    for start, duration in motion.occlusions:
        t_frames = frame_index * dt
        occluded[(t_frames >= start) & (t_frames < start + duration)] = True
    n_phantoms = rng.binomial(motion.max_phantoms, motion.p_phantom, F)
    per_frame = np.where(rng.random(F) < motion.p_gyro_2, 2, 3)
    previous = np.concatenate([[0], frame_index[:-1]])
    gyro_index = np.concatenate(
        [np.rint(a + (b - a) * np.arange(1, k + 1) / k).astype(int) for a, b, k in zip(previous, frame_index, per_frame)]
    )
    gyro_index = np.clip(gyro_index, 0, T - 1)
    gyro = trajectory.omega_body[gyro_index] + rng.normal(0.0, motion.gyro_noise_std, (len(gyro_index), 3))
    return SensorTimeline(frame_index=frame_index, occluded=occluded, n_phantoms=n_phantoms, gyro_index=gyro_index, gyro=gyro)
