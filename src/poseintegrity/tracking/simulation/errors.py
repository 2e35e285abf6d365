"""Pose errors against ground truth, the paper's way and ours (section II-F, "Testing").

The paper (Black and Salcudean, IEEE TIM 2024, section II-F) computes "the root-mean-square (RMS) of the
element-wise difference between the two signals": per axis for position (x, y, z) and per Euler angle for
rotation, and reports the mean of the three RMS values ("mean positional RMS error", "mean RMS Euler angle").
Ours are the RMS of the 3-D error norm and of the geodesic angle, which do not depend on axes or on an Euler
convention.  For isotropic errors the norm RMS is sqrt(3) times the per-axis RMS.

Euler convention (stated because the paper does not): Unity's, as the HoloLens application of the paper runs
in Unity: rotations about z, then x, then y in the world frame, R = R_y R_x R_z, i.e. scipy's intrinsic
``"YXZ"``; differences are wrapped into [-180, 180) degrees.  Near pitch +-90 deg the Euler signals jump, as
they did for the paper: those samples inflate the Euler RMS and are kept, as the paper's metric keeps them.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity import poses

EULER_SEQUENCE = "YXZ"  # Unity: R = R_y R_x R_z (intrinsic y, x, z)
EULER_AXES = ("y", "x", "z")


def axis_errors(T_est: np.ndarray, T_true: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Element-wise differences of the two signals (section II-F): position (k, 3) mm (x, y, z) and Unity Euler
    angles (k, 3) deg (y, x, z), wrapped into [-180, 180).  NaN rows where T_est is NaN."""
    d_pos = (T_est[:, :3, 3] - T_true[:, :3, 3]) * 1000.0
    ok = np.isfinite(T_est[:, :3, :3]).all(axis=(1, 2))
    d_euler = np.full((len(T_est), 3), np.nan)
    if ok.any():
        est = Rotation.from_matrix(T_est[ok, :3, :3]).as_euler(EULER_SEQUENCE, degrees=True)
        true = Rotation.from_matrix(T_true[ok, :3, :3]).as_euler(EULER_SEQUENCE, degrees=True)
        d_euler[ok] = (est - true + 180.0) % 360.0 - 180.0
    return d_pos, d_euler


def error_columns(T_est: np.ndarray, T_true: np.ndarray) -> dict[str, np.ndarray]:
    """Per-pose error columns for a table: pos_err_mm, rot_err_deg (ours) and dx/dy/dz_mm, dyaw/dpitch/droll_deg
    (the paper's element-wise differences; yaw about y, pitch about x, roll about z in Unity's convention)."""
    pos_m, rot = poses.pose_errors(T_est, T_true)
    d_pos, d_euler = axis_errors(T_est, T_true)
    return {
        "pos_err_mm": pos_m * 1000.0, "rot_err_deg": rot,
        "dx_mm": d_pos[:, 0], "dy_mm": d_pos[:, 1], "dz_mm": d_pos[:, 2],
        "dyaw_deg": d_euler[:, 0], "dpitch_deg": d_euler[:, 1], "droll_deg": d_euler[:, 2],
    }


def rms(values: np.ndarray) -> float:
    """Root mean square over the finite values (NaN if none)."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    return float(np.sqrt(np.mean(values**2))) if values.size else float("nan")


def rms_summary(rows) -> dict[str, float]:
    """RMS errors of a table with :func:`error_columns`: ours (norm_mm, geodesic_deg), the paper's (axis_mm and
    euler_deg, the mean of the three per-axis RMS) and each axis (x_mm ..., yaw_deg ...)."""
    out = {"norm_mm": rms(rows["pos_err_mm"]), "geodesic_deg": rms(rows["rot_err_deg"])}
    per_axis = {f"{a}_mm": rms(rows[f"d{a}_mm"]) for a in "xyz"}
    per_angle = {f"{a}_deg": rms(rows[f"d{a}_deg"]) for a in ("yaw", "pitch", "roll")}
    out["axis_mm"] = float(np.mean(list(per_axis.values())))
    out["euler_deg"] = float(np.mean(list(per_angle.values())))
    return {**out, **per_axis, **per_angle}
