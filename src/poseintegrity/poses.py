"""Rigid poses as 4 x 4 homogeneous matrices T_a_b (maps points of frame b into frame a): built, inverted, compared.

One place for what both papers need: Windsor et al. score a pose by E_t (distance of translations) and E_r (angle of
the relative rotation, IV-C); Black and Salcudean's ours-metrics (section II-F) are the same two numbers per frame.
Lengths are the caller's (mm in localization and scenes, metres in tracking); angles are degrees. Every function
takes a single pose (4, 4) or a stack (..., 4, 4).
"""

from __future__ import annotations

import cv2
import numpy as np

from poseintegrity.errors import ArgumentError, check_array

NAN_POSE = np.full((4, 4), np.nan)  # the documented value of a pose that could not be estimated
NAN_POSE.flags.writeable = False  # shared: a caller that fills a pose in copies it first


def pose_matrix(R: np.ndarray, t: np.ndarray) -> np.ndarray:
    """T (..., 4, 4) with rotation R (..., 3, 3) and translation t (..., 3)."""
    R = np.asarray(R, dtype=np.float64)
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = t
    T[..., 3, 3] = 1.0
    return T


def inverse(T: np.ndarray) -> np.ndarray:
    """T_b_a of T_a_b (..., 4, 4), rigid: (R^T, -R^T t)."""
    if np.shape(T)[-2:] != (4, 4):
        raise ArgumentError(f"T: expected a pose (4, 4) or a stack (..., 4, 4), got shape {np.shape(T)}")
    R_t = np.swapaxes(T[..., :3, :3], -1, -2)
    return pose_matrix(R_t, -(R_t @ T[..., :3, 3, None])[..., 0])


def pose_from_rvec_tvec(rvec: np.ndarray, tvec: np.ndarray) -> np.ndarray:
    """T (4, 4) of an OpenCV pose: Rodrigues rotation vector (3,) rad and translation (3,)."""
    R, _ = cv2.Rodrigues(np.asarray(rvec, dtype=np.float64).reshape(3))
    return pose_matrix(R, np.asarray(tvec, dtype=np.float64).reshape(3))


def rotation_angle_deg(R_a: np.ndarray, R_b: np.ndarray) -> np.ndarray:
    """Geodesic angle (...) in [0, 180] deg of R_a R_b^T, for rotations (..., 3, 3).

    atan2(sin, cos) of the relative rotation (sin from its skew part, cos from its trace): accurate at every angle,
    where arccos of the trace alone loses half the digits near 0 (E_r of a good pose is ~0.1 deg).
    """
    R = np.asarray(R_a) @ np.swapaxes(R_b, -1, -2)
    skew = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], axis=-1)
    sin = np.linalg.norm(skew, axis=-1) / 2.0
    cos = (np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0
    return np.degrees(np.arctan2(sin, cos))


RIGID_ATOL = 1e-5  # |R^T R - I| of a rotation from float32 data stays well below this; a scaled or sheared R does not


def _rigid_or_unknown(name: str, T: object) -> np.ndarray:
    """T as float64 (..., 4, 4) whose every finite matrix is a rigid transform (matrices holding NaN or inf are
    unknown poses and pass); :class:`~poseintegrity.errors.ArgumentError` naming ``name`` otherwise."""
    T = check_array(name, T, finite=False)
    if T.shape[-2:] != (4, 4):
        raise ArgumentError(f"{name}: expected a pose (4, 4) or a stack (..., 4, 4), got shape {T.shape}")
    finite = np.isfinite(T).all(axis=(-2, -1))
    R = np.where(finite[..., None, None], T, np.eye(4))[..., :3, :3]
    gap = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max(axis=(-2, -1))
    last = np.where(finite[..., None], T[..., 3, :], [0.0, 0.0, 0.0, 1.0])
    bad = ~(gap <= RIGID_ATOL) | (np.linalg.det(R) < 0) | (np.abs(last - [0.0, 0.0, 0.0, 1.0]).max(axis=-1) > 0)
    bad |= finite & (np.abs(np.where(finite[..., None, None], T, 0.0)) > 1e12).any(axis=(-2, -1))
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(np.atleast_1d(bad))[0])
        raise ArgumentError(f"{name}: expected rigid transforms (or NaN for an unknown pose), the matrix at "
                            f"{index if T.ndim > 2 else 'its only index'} is not one (|R^T R - I| "
                            f"{float(np.atleast_1d(gap)[index]):.3g}, last row {np.atleast_2d(last)[index].tolist()})")
    return T


def pose_errors(T_est: np.ndarray, T_true: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(E_t, E_r) of Windsor et al. IV-C between poses (..., 4, 4): E_t = ||t_est - t_true|| in the poses' length
    unit, E_r = the angle of R_est R_true^T in degrees (:func:`rotation_angle_deg`); shapes (...). NaN where either
    pose holds NaN or inf (a failed estimate, an unknown truth). Refused (:class:`~poseintegrity.errors.ArgumentError`
    naming the argument): anything but numbers of shape (..., 4, 4), and a finite matrix that is not a rigid transform
    (R^T R = I to 1e-5, det R > 0, last row [0, 0, 0, 1], |t| <= 1e12)."""
    T_est, T_true = _rigid_or_unknown("T_est", T_est), _rigid_or_unknown("T_true", T_true)
    known = np.isfinite(T_est).all(axis=(-2, -1)) & np.isfinite(T_true).all(axis=(-2, -1))
    E_t = np.linalg.norm(T_est[..., :3, 3] - T_true[..., :3, 3], axis=-1)
    with np.errstate(invalid="ignore"):
        E_r = rotation_angle_deg(T_est[..., :3, :3], T_true[..., :3, :3])
    return np.where(known, E_t, np.nan), np.where(known, E_r, np.nan)
