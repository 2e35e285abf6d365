"""A 6R arm's standard Denavit-Hartenberg parameters (:class:`DH`) and Universal Robots' published UR5e table
(:data:`UR5E`): the arm's geometry, which the params schema checks reach against and :mod:`poseintegrity.kinematics`
moves. Link i moves frame i-1 into frame i: T_{i-1,i} = Rz(q_i + theta_offset_i) Tz(d_i) Tx(a_i) Rx(alpha_i)
(docs/references.md "Robot"). Lengths in mm, angles in rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

N_JOINTS = 6


@dataclass(frozen=True)
class DH:
    """Standard DH parameters of a 6R arm, joint i = 1..6 at index i - 1.

    a, d : (6,) float, mm; alpha, theta_offset : (6,) float, rad.
    """

    a: np.ndarray
    d: np.ndarray
    alpha: np.ndarray
    theta_offset: np.ndarray

    def perturbed(self, da: np.ndarray, dd: np.ndarray, dalpha: np.ndarray, dtheta: np.ndarray) -> "DH":
        """These parameters plus the deviations (same shapes and units): a physical arm's actual kinematics."""
        return DH(self.a + da, self.d + dd, self.alpha + dalpha, self.theta_offset + dtheta)

    @property
    def reach_mm(self) -> float:
        """An upper bound of the distance from joint 2's axis to the flange: the sum of every link's lengths."""
        return float(np.abs(self.a).sum() + np.abs(self.d[1:]).sum())


# Universal Robots' published DH table of the UR5e (docs/references.md "Robot"): a, d in mm, alpha in deg.
UR5E = DH(a=np.array([0.0, -425.0, -392.2, 0.0, 0.0, 0.0]),
          d=np.array([162.5, 0.0, 0.0, 133.3, 99.7, 99.6]),
          alpha=np.radians([90.0, 0.0, 0.0, 90.0, -90.0, 0.0]),
          theta_offset=np.zeros(N_JOINTS))
