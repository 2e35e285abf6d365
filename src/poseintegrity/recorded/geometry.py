"""Stop positions and the model pair's relative pose from camera poses (Windsor et al. III-B, III-D, V-A).

Poses are T_cam_ref (4, 4): reference frame -> camera, mm (the package's convention, poseintegrity.poses). Every
function checks its poses once (:func:`poses`): finite rigid transforms, else
:class:`~poseintegrity.errors.ArgumentError` naming the argument.
"""

from __future__ import annotations

import numpy as np

from poseintegrity.errors import ArgumentError, check_array, check_pose
from poseintegrity.poses import inverse, rotation_angle_deg


def poses(name: str, T: object) -> np.ndarray:
    """``T`` as float64 (4, 4) or (n, 4, 4), every matrix a finite rigid transform (:func:`check_pose`)."""
    array = check_array(name, T)
    if array.ndim not in (2, 3) or array.shape[-2:] != (4, 4):
        raise ArgumentError(f"{name}: expected a pose (4, 4) or a stack (n, 4, 4), got shape {array.shape}")
    for index, matrix in enumerate(array.reshape(-1, 4, 4)):
        check_pose(name if array.ndim == 2 else f"{name}[{index}]", matrix)
    return array


def viewing_angle_deg(T_cam0_ref: object, T_cam_ref: object) -> np.ndarray:
    """theta_i (...,) deg: the angle of the rotation between the model pose (camera 0 of the model pair, where M_t
    was created) and pose i (III-D: "the absolute magnitude of the difference in the camera orientations").
    T_cam0_ref: (4, 4); T_cam_ref: (4, 4) or (n, 4, 4)."""
    T0, T = poses("T_cam0_ref", T_cam0_ref), poses("T_cam_ref", T_cam_ref)
    if T0.ndim != 2:
        raise ArgumentError(f"T_cam0_ref: expected one pose (4, 4), got shape {T0.shape}")
    return rotation_angle_deg(T[..., :3, :3], T0[:3, :3])


def camera_centre(T_cam_ref: object) -> np.ndarray:
    """(3,) or (n, 3) mm: the camera centre in the reference frame, -R^T t."""
    return inverse(poses("T_cam_ref", T_cam_ref))[..., :3, 3]


def distance_mm(origin_mm: object, T_cam_ref: object) -> np.ndarray:
    """x_i (...,) mm: the distance of camera i's centre from ``origin_mm`` (3,), a point of the reference frame (for
    lines the trajectory's first position, V-A: "the 3D camera translation between the first position of the
    trajectory and position i")."""
    origin = check_array("origin_mm", origin_mm, shape=(3,))
    return np.linalg.norm(camera_centre(T_cam_ref) - origin, axis=-1)


def relative_pose(T_cam0_ref: object, T_cam1_ref: object) -> np.ndarray:
    """T_cam1_cam0 (4, 4) mm: camera 0 -> camera 1 of the model pair (III-B), T_cam1_ref inv(T_cam0_ref)."""
    T0, T1 = poses("T_cam0_ref", T_cam0_ref), poses("T_cam1_ref", T_cam1_ref)
    if T0.ndim != 2 or T1.ndim != 2:
        raise ArgumentError(f"T_cam0_ref, T_cam1_ref: expected one pose (4, 4) each, got shapes {T0.shape}, {T1.shape}")
    return T1 @ inverse(T0)
