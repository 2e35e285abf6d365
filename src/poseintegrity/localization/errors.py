"""Pose estimation errors of IV-C: E_t (Euclidean distance of translations, mm) and E_r (rotation magnitude, deg)."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def pose_errors(T_cam_board_est: np.ndarray, T_cam_board_true: np.ndarray) -> tuple[float, float]:
    """(E_t mm, E_r deg) between an estimated and a reference pose, both (4, 4) mapping board -> camera, mm.

    E_t = ||t_est - t_true||; E_r = angle of the relative rotation R_est R_true^T (0..180 deg).
    A pose holding NaN (a failed estimate) gives (NaN, NaN).
    """
    if not (np.all(np.isfinite(T_cam_board_est)) and np.all(np.isfinite(T_cam_board_true))):
        return float("nan"), float("nan")
    E_t_mm = float(np.linalg.norm(T_cam_board_est[:3, 3] - T_cam_board_true[:3, 3]))
    R_rel = T_cam_board_est[:3, :3] @ T_cam_board_true[:3, :3].T
    E_r_deg = float(np.degrees(Rotation.from_matrix(R_rel).magnitude()))
    return E_t_mm, E_r_deg
