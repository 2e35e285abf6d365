"""Hand-like motion of the marker body and its sensor timeline (section II-F).

Random linear and angular accelerations are integrated into motion: the linear acceleration is an
Ornstein-Uhlenbeck (OU) process pulled back to a home position by a spring and damped, so the tool stays in
front of the camera; the body angular velocity is an OU process (the accuracy recording, and motion (b), the
stress test, with a large spread), or, for motion (a), the paper-like one of section III, a sequence of full
turns about the body x, y, z axes at hand speeds plus an OU wobble (:func:`simulate_hand_motion`) with brief
per-marker occlusions (:func:`brief_occlusions`).  Marker frames arrive every ``frame_interval_s`` (+- jitter, the paper measured 45.98 +- 7.67 ms), and
between two frames the gyro delivers 2 samples with probability P_2, else 3 (P_3 = 1 - P_2).
Each frame gets per-marker occlusions (probability P_o), phantom reflections (P_p per slot) and the
deliberate extended occlusions of the params (all markers hidden).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.params.track import HandMotionParams, MotionParams


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
def _translate(noise, dt, home, accel_std, accel_tau, spring, damping):  # pragma: no cover - compiled
    """Positions (T, 3): OU random acceleration, pulled home by a damped spring, integrated (semi-implicit Euler)."""
    T = noise.shape[0]
    pos, vel, acc = home.copy(), np.zeros(3), np.zeros(3)
    positions = np.empty((T, 3))
    a_acc = np.exp(-dt / accel_tau)
    s_acc = accel_std * np.sqrt(1 - a_acc**2)
    k, c = (2 * np.pi * spring) ** 2, 2 * damping * 2 * np.pi * spring
    for i in range(T):
        positions[i] = pos
        vel = vel + dt * (acc - k * (pos - home) - c * vel)
        pos = pos + dt * vel
        acc = a_acc * acc + s_acc * noise[i]
    return positions


@numba.njit(cache=True)
def _ornstein_uhlenbeck(noise, dt, std, tau):  # pragma: no cover - compiled
    """OU process (T, 3) of stationary spread std and correlation time tau, starting at 0."""
    out = np.empty(noise.shape)
    a = np.exp(-dt / tau)
    s = std * np.sqrt(1 - a**2)
    w = np.zeros(3)
    for i in range(noise.shape[0]):
        out[i] = w
        w = a * w + s * noise[i]
    return out


@numba.njit(cache=True)
def _rotate(omega_body, dt):  # pragma: no cover - compiled
    """Quaternions (T, 4) scalar-last from identity, q <- q * exp(w dt / 2) with the body-frame rate w (T, 3)."""
    T = omega_body.shape[0]
    q = np.array([0.0, 0.0, 0.0, 1.0])  # x, y, z, w
    quats = np.empty((T, 4))
    for i in range(T):
        quats[i] = q
        w = omega_body[i]
        angle = np.sqrt(w @ w) * dt
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
    return quats


def simulate_trajectory(motion: MotionParams, rng: np.random.Generator, omega_std: float | None = None) -> Trajectory:
    """Integrate random accelerations into a trajectory of motion.duration_s seconds on a sim_dt grid (II-F).

    omega_std : rad/s, overrides motion.omega_std (motion (b), the stress test, uses a larger one).
    """
    T = int(round(motion.duration_s / motion.sim_dt)) + 1
    noise = rng.standard_normal((T, 6))
    dt = motion.sim_dt
    positions = _translate(noise[:, :3], dt, np.array(motion.home_m), motion.accel_std, motion.accel_tau_s, motion.spring_hz, motion.damping)
    omegas = _ornstein_uhlenbeck(noise[:, 3:], dt, motion.omega_std if omega_std is None else omega_std, motion.omega_tau_s)
    return Trajectory(t=np.arange(T) * dt, position=positions, quat=_rotate(omegas, dt), omega_body=omegas)


def full_turns(t: np.ndarray, hand: HandMotionParams, rng: np.random.Generator) -> np.ndarray:
    """Body angular velocity (T, 3) rad/s of a sequence of full turns about the body x, y, z axes in turn.

    Each turn of duration T_turn ~ U(hand.turn_s) has speed (4 pi / T_turn) sin^2(pi tau / T_turn), which
    integrates to 2 pi over the turn; its sign is random; turns are separated by pauses ~ U(hand.pause_s).
    """
    omega = np.zeros((len(t), 3))
    start, axis = rng.uniform(*hand.pause_s), 0
    while start < t[-1]:
        duration = rng.uniform(*hand.turn_s)
        inside = slice(*np.searchsorted(t, [start, start + duration]))  # start <= t < start + duration (t increases)
        tau = t[inside] - start
        omega[inside, axis] = rng.choice([-1.0, 1.0]) * 4 * np.pi / duration * np.sin(np.pi * tau / duration) ** 2
        start += duration + rng.uniform(*hand.pause_s)
        axis = (axis + 1) % 3
    return omega


def simulate_hand_motion(motion: MotionParams, hand: HandMotionParams, rng: np.random.Generator) -> Trajectory:
    """Motion (a), paper-like (section III): full turns about every axis at hand speeds (:func:`full_turns`) plus
    an OU wobble of hand.wobble_std, and the large translations of ``motion`` with hand.accel_std."""
    T = int(round(motion.duration_s / motion.sim_dt)) + 1
    dt, t = motion.sim_dt, np.arange(T) * motion.sim_dt
    noise = rng.standard_normal((T, 6))
    positions = _translate(noise[:, :3], dt, np.array(motion.home_m), hand.accel_std, motion.accel_tau_s, motion.spring_hz, motion.damping)
    omegas = full_turns(t, hand, rng) + _ornstein_uhlenbeck(noise[:, 3:], dt, hand.wobble_std, motion.omega_tau_s)
    return Trajectory(t=t, position=positions, quat=_rotate(omegas, dt), omega_body=omegas)


def brief_occlusions(frame_t: np.ndarray, n_markers: int, hand: HandMotionParams, rng: np.random.Generator) -> np.ndarray:
    """(F, n) bool: markers hidden by brief occlusions (a finger passing over one marker), Poisson events at
    hand.occlusion_rate_hz per marker, each lasting U(hand.occlusion_s)."""
    hidden = np.zeros((len(frame_t), n_markers), dtype=bool)
    span = frame_t[-1] if len(frame_t) else 0.0
    for i in range(n_markers):
        starts = np.sort(rng.uniform(0.0, span, rng.poisson(hand.occlusion_rate_hz * span)))
        for s, d in zip(starts, rng.uniform(*hand.occlusion_s, len(starts))):
            hidden[(frame_t >= s) & (frame_t < s + d), i] = True
    return hidden


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

    def first_frames(self, n: int) -> SensorTimeline:
        """The timeline up to its n-th marker frame (n >= 1): the first n frames and the gyro samples up to the
        last of them (each frame's samples lie after the frame before it).  The whole timeline if it is shorter."""
        if n >= len(self.frame_index):
            return self
        keep = self.gyro_index <= self.frame_index[n - 1]
        return SensorTimeline(self.frame_index[:n], self.occluded[:n], self.n_phantoms[:n], self.gyro_index[keep], self.gyro[keep])


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
