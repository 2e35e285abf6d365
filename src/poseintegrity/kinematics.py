"""Kinematics of a UR-class 6R arm in standard Denavit-Hartenberg form: forward kinematics, the geometric Jacobian,
a numerical inverse and a singularity measure.

Frames: ``base`` is the robot's mounting surface (z along joint 1, up when mounted on a table), frame i the DH frame
of link i, ``flange`` = frame 6 (z out of the tool flange). Link i moves frame i-1 into frame i:
T_{i-1,i} = Rz(q_i + theta_offset_i) Tz(d_i) Tx(a_i) Rx(alpha_i) (standard DH; Universal Robots publishes its arms
in this form, docs/references.md "Robot"). Lengths in mm, angles in rad (params give degrees).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from poseintegrity.denavit_hartenberg import DH, N_JOINTS

ROTATION_WEIGHT_MM = 100.0  # IK residual: 1 rad of orientation weighs as 100 mm of position (1 mrad ~ 0.1 mm)
IK_TOLERANCE_MM = 1e-9  # a converged IK solution reaches the pose to this (rotation residual scaled as above)
IK_MAX_EVALUATIONS = 60  # from a seed on the solution's branch LM converges in ~10; more means another branch


def link_transforms(dh: DH, q: np.ndarray) -> np.ndarray:
    """T_{i-1,i} (6, 4, 4) of joint angles q (6,) rad: Rz(q + offset) Tz(d) Tx(a) Rx(alpha)."""
    theta = np.asarray(q, dtype=np.float64) + dh.theta_offset
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(dh.alpha), np.sin(dh.alpha)
    T = np.zeros((N_JOINTS, 4, 4))
    T[:, 0, 0], T[:, 0, 1], T[:, 0, 2], T[:, 0, 3] = ct, -st * ca, st * sa, dh.a * ct
    T[:, 1, 0], T[:, 1, 1], T[:, 1, 2], T[:, 1, 3] = st, ct * ca, -ct * sa, dh.a * st
    T[:, 2, 1], T[:, 2, 2], T[:, 2, 3] = sa, ca, dh.d
    T[:, 3, 3] = 1.0
    return T


def joint_frames(dh: DH, q: np.ndarray) -> np.ndarray:
    """T_base_i (7, 4, 4) for i = 0 (the base) .. 6 (the flange); joint i turns about the z axis of frame i - 1."""
    links = link_transforms(dh, q)
    frames = np.empty((N_JOINTS + 1, 4, 4))
    frames[0] = np.eye(4)
    for i in range(N_JOINTS):
        np.matmul(frames[i], links[i], out=frames[i + 1])
    return frames


def forward(dh: DH, q: np.ndarray) -> np.ndarray:
    """T_base_flange (4, 4) of joint angles q (6,) rad."""
    return joint_frames(dh, q)[-1]


def jacobian(dh: DH, q: np.ndarray) -> np.ndarray:
    """Geometric Jacobian (6, 6) of the flange at q: rows 0-2 d(position)/dq in mm/rad, rows 3-5 the angular
    velocity (rad/rad), both in the base frame; column i = (z_{i-1} x (p - o_{i-1}), z_{i-1})."""
    frames = joint_frames(dh, q)
    z, o = frames[:-1, :3, 2], frames[:-1, :3, 3]
    return np.vstack([np.cross(z, frames[-1, :3, 3] - o).T, z.T])


def branch(dh: DH, q: np.ndarray) -> tuple[int, int, int]:
    """Which of a UR arm's 8 IK branches q (6,) is on: the signs of the three factors of its Jacobian's
    determinant (:func:`manipulability`): shoulder (the wrist's reach from joint 1's axis), elbow (sin q3), wrist
    (sin q5). A continuous motion changes branch only through a singularity, where a factor vanishes."""
    reach = dh.a[1] * np.cos(q[1]) + dh.a[2] * np.cos(q[1] + q[2]) + dh.d[4] * np.sin(q[1] + q[2] + q[3])
    return int(np.sign(reach)), int(np.sign(np.sin(q[2]))), int(np.sign(np.sin(q[4])))


def manipulability(dh: DH, q: np.ndarray) -> float:
    """|det J| / (|a2| |a3| (|a2| + |a3|)): Yoshikawa's manipulability of the square Jacobian, scaled to ~[0, 1].
    For a UR arm det J = a2 a3 sin(q3) sin(q5) (a2 cos q2 + a3 cos(q2 + q3) + d5 sin(q2 + q3 + q4)), the last
    factor the wrist's reach away from joint 1's axis: it vanishes at each of the arm's three singularities (elbow
    stretched or folded, wrist axes aligned, wrist over the base axis) and is ~1 with elbow and wrist at right
    angles and the wrist a full arm's length out."""
    a2, a3 = abs(dh.a[1]), abs(dh.a[2])
    return float(abs(np.linalg.det(jacobian(dh, q))) / (a2 * a3 * (a2 + a3)))


def rotation_vector(R: np.ndarray) -> np.ndarray:
    """The rotation vector (3,) rad of a rotation matrix R (3, 3): the axis from R's skew part, the angle as
    atan2(sin, cos), exact to rounding at small angles (OpenCV's Rodrigues re-orthonormalises R first and loses
    ~1e-9 rad; scipy's is exact but ~50x slower per call, which the IK makes thousands of)."""
    skew = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    sin = np.linalg.norm(skew)
    cos = 0.5 * (np.trace(R) - 1.0)
    if sin < 1e-6 and cos < 0:  # near a half turn the skew part loses the axis
        return Rotation.from_matrix(R).as_rotvec()
    return skew * (np.arctan2(sin, cos) / sin if sin > 0 else 1.0)


def _pose_residual(dh: DH, q: np.ndarray, T_target: np.ndarray) -> np.ndarray:
    """(6,) position error (mm) and rotation error (rotation vector of R(q) R_target^T, base frame, scaled to mm)."""
    T = forward(dh, q)
    rotation_error = rotation_vector(T[:3, :3] @ T_target[:3, :3].T)
    return np.concatenate([T[:3, 3] - T_target[:3, 3], ROTATION_WEIGHT_MM * rotation_error])


def wrap(q: np.ndarray) -> np.ndarray:
    """Joint angles (..., 6) rad wrapped into [-pi, pi) (a revolute joint's pose repeats every turn)."""
    return (np.asarray(q) + np.pi) % (2 * np.pi) - np.pi


def within_reach(dh: DH, T_base_flange: np.ndarray) -> bool:
    """A necessary condition for T_base_flange (4, 4) to be reachable: the wrist point (joint 6's axis, d6 behind
    the flange) lies within the sum of the link lengths between it and the shoulder (frame 1's origin, d1 above
    the base): a quick refusal before a numerical search that could not converge."""
    wrist = T_base_flange[:3, 3] - dh.d[5] * T_base_flange[:3, 2]
    shoulder = np.array([0.0, 0.0, dh.d[0]])
    return bool(np.linalg.norm(wrist - shoulder) <= np.abs(dh.a[1:]).sum() + np.abs(dh.d[1:5]).sum())


def inverse(dh: DH, T_base_flange: np.ndarray, q_seed: np.ndarray) -> np.ndarray | None:
    """Joint angles (6,) rad, wrapped, reaching T_base_flange (4, 4), found by Levenberg-Marquardt from q_seed (6,):
    the solution of the seed's branch (the one it converges to); None where it does not converge to within
    IK_TOLERANCE_MM (a pose out of reach, or a seed across a singularity from every solution)."""
    if not within_reach(dh, T_base_flange):
        return None
    scale = np.concatenate([np.ones(3), np.full(3, ROTATION_WEIGHT_MM)])

    def residual(q):
        return _pose_residual(dh, q, T_base_flange)

    def residual_jacobian(q):
        return scale[:, None] * jacobian(dh, q)  # exact for position, first order for the rotation error

    fit = least_squares(residual, np.asarray(q_seed, dtype=np.float64), jac=residual_jacobian, method="lm",
                        xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=IK_MAX_EVALUATIONS)
    if not np.all(np.abs(residual(fit.x)) < IK_TOLERANCE_MM):
        return None
    return wrap(fit.x)
