"""Stop positions and the model pair's relative pose from camera poses (Windsor et al. III-B, IV-D).

Poses are T_cam_ref (4, 4): reference frame -> camera, mm (the package's convention, poseintegrity.poses).
"""

from __future__ import annotations

import numpy as np

from poseintegrity.poses import inverse, rotation_angle_deg


def viewing_angle_deg(T_cam0_ref: np.ndarray, T_cam_ref: np.ndarray) -> np.ndarray:
    """theta_i (...,) deg: the angle of the rotation between the model pose (camera 0 of the model pair, where M_t
    was created) and pose i (III-D: "the absolute magnitude of the difference in the camera orientations").
    T_cam_ref: (4, 4) or (n, 4, 4)."""
    return rotation_angle_deg(np.asarray(T_cam_ref)[..., :3, :3], np.asarray(T_cam0_ref)[:3, :3])


def camera_centre(T_cam_ref: np.ndarray) -> np.ndarray:
    """(..., 3) mm: the camera centre in the reference frame, -R^T t."""
    return inverse(np.asarray(T_cam_ref, dtype=np.float64))[..., :3, 3]


def distance_mm(origin_mm: np.ndarray, T_cam_ref: np.ndarray) -> np.ndarray:
    """x_i (...,) mm: the distance of camera i's centre from ``origin_mm`` (3,), a point of the reference frame (for
    lines the trajectory's first position, V-A: "the 3D camera translation between the first position of the
    trajectory and position i")."""
    return np.linalg.norm(camera_centre(T_cam_ref) - np.asarray(origin_mm, dtype=np.float64), axis=-1)


def relative_pose(T_cam0_ref: np.ndarray, T_cam1_ref: np.ndarray) -> np.ndarray:
    """T_cam1_cam0 (4, 4) mm: camera 0 -> camera 1 of the model pair (III-B), T_cam1_ref inv(T_cam0_ref)."""
    return np.asarray(T_cam1_ref, dtype=np.float64) @ np.linalg.inv(np.asarray(T_cam0_ref, dtype=np.float64))
