"""The eye-in-hand camera as stage 01 renders it (true intrinsics and lens) and camera placement helpers.

Frames: OpenCV camera frame (x right, y down, z forward); lengths in millimetres; ``T_a_b`` is a 4x4 matrix
mapping coordinates of frame b into frame a.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from poseintegrity.lens import Camera
from poseintegrity.poses import pose_matrix

if TYPE_CHECKING:
    from poseintegrity.params.camera import CameraParams


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics of the rendered images, the true ones (the pipeline only sees a calibration's estimate).

    width, height : image size in pixels; K : (3, 3) float, pixels.
    """

    width: int
    height: int
    K: np.ndarray

    @classmethod
    def from_params(cls, camera: "CameraParams") -> "Intrinsics":
        """The true intrinsics of ``camera`` (:meth:`poseintegrity.params.camera.CameraParams.intrinsics`)."""
        K, width, height = camera.intrinsics()
        return cls(width, height, K)


@lru_cache(maxsize=4)
def true_camera(camera: "CameraParams") -> Camera:
    """The camera stage 01 renders through: the true intrinsics and the lens' true distortion. One object per
    process and camera section, so that its canvas and sensor maps (cached on it, ~0.1 s) are computed once: the
    calibration session's views computed them again for every view."""
    cam = Intrinsics.from_params(camera)
    return Camera(cam.K, np.asarray(camera.distortion, dtype=float), cam.width, cam.height)


def look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray = np.array([0.0, 0.0, 1.0])) -> np.ndarray:
    """T_world_cam of a camera at ``eye`` whose optical axis points at ``target``; image "up" is towards ``up``.

    eye, target, up : (3,) float, world frame (mm).
    """
    z = target - eye
    z = z / np.linalg.norm(z)
    x = np.cross(z, up)  # y points down in the image, so x = z cross up (right-handed: x cross y = z)
    if np.linalg.norm(x) < 1e-9:  # looking straight along `up`: any horizontal x will do
        x = np.cross(z, np.array([0.0, 1.0, 0.0]))
    x = x / np.linalg.norm(x)
    return pose_matrix(np.column_stack([x, np.cross(z, x), z]), eye)

