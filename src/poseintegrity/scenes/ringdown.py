"""The camera's ring-down after a stop: a lightweight arm's tool keeps vibrating briefly after the controller
reports it has stopped (docs/references.md "Robot", ring-down). Modelled as one damped mode: the camera turns
about a fixed axis (drawn per stop, camera frame) by

    phi(t) = A exp(-zeta omega_n t) cos(omega_d t + psi),   omega_d = omega_n sqrt(1 - zeta^2),

t seconds after the stop, amplitude A and phase psi drawn per stop. The rotation is small (hundredths of a
degree): a renderer warps the image by it (the camera rotated by the rotation vector phi(t) u in its own frame,
T_world_cam(t) = T_world_cam Rot(phi(t) u)) and blurs along the path it takes during the exposure. Independent of
the renderer; angles in rad unless a name says deg.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from poseintegrity.params.robot import RingDownParams


@dataclass(frozen=True)
class Exposure:
    """The ring-down seen by one image: ``mid`` (3,) the rotation vector (rad, camera frame) at mid-exposure,
    ``path`` (n, 3) the rotation vectors at ``times_s`` (n,) evenly spread over the exposure (both ends
    included)."""

    mid: np.ndarray
    path: np.ndarray
    times_s: np.ndarray


@dataclass(frozen=True)
class RingDown:
    """One stop's vibration: unit ``axis`` (3,) in the camera frame, envelope ``amplitude_rad`` at the stop,
    ``phase_rad``, natural angular frequency ``omega_n`` (rad/s) and damping ratio ``zeta`` (0 < zeta < 1)."""

    axis: np.ndarray
    amplitude_rad: float
    phase_rad: float
    omega_n: float
    zeta: float

    @property
    def omega_d(self) -> float:
        """Damped angular frequency (rad/s)."""
        return self.omega_n * np.sqrt(1.0 - self.zeta**2)

    def angle(self, t_s: np.ndarray | float) -> np.ndarray:
        """phi(t) (rad), t_s (...) seconds after the stop (>= 0)."""
        t = np.asarray(t_s, dtype=np.float64)
        return (self.amplitude_rad * np.exp(-self.zeta * self.omega_n * t)
                * np.cos(self.omega_d * t + self.phase_rad))

    def angular_rate(self, t_s: np.ndarray | float) -> np.ndarray:
        """d phi / dt (rad/s) at t_s (...) seconds after the stop."""
        t = np.asarray(t_s, dtype=np.float64)
        decay = self.amplitude_rad * np.exp(-self.zeta * self.omega_n * t)
        phase = self.omega_d * t + self.phase_rad
        return -decay * (self.zeta * self.omega_n * np.cos(phase) + self.omega_d * np.sin(phase))

    def rotation(self, t_s: np.ndarray | float) -> np.ndarray:
        """Rotation vectors (..., 3) rad, camera frame, at t_s (...) seconds after the stop."""
        return self.angle(t_s)[..., None] * self.axis

    def exposure(self, t0_s: float, t1_s: float, n: int) -> Exposure:
        """The rotation at mid-exposure and its path at n >= 2 instants of an exposure from t0_s to t1_s seconds
        after the stop (0 <= t0_s <= t1_s)."""
        if not 0.0 <= t0_s <= t1_s or n < 2:
            raise ValueError(f"an exposure needs 0 <= t0_s <= t1_s and n >= 2 samples, got t0_s={t0_s}, "
                             f"t1_s={t1_s}, n={n}")
        times = np.linspace(t0_s, t1_s, n)
        return Exposure(self.rotation(0.5 * (t0_s + t1_s)), self.rotation(times), times)


def ring_down(params: "RingDownParams", rng: np.random.Generator) -> RingDown:
    """One stop's ring-down: an axis uniform on the sphere, the envelope ``amplitude_deg`` and a phase uniform in
    [0, 2 pi) (the controller reports the stop at any point of the swing), the mode of ``params``."""
    axis = rng.normal(size=3)
    return RingDown(axis=axis / np.linalg.norm(axis), amplitude_rad=float(np.radians(params.amplitude_deg)),
                    phase_rad=float(rng.uniform(0.0, 2 * np.pi)),
                    omega_n=2 * np.pi * params.natural_frequency_hz, zeta=params.damping_ratio)
