"""Pinhole camera of the eye-in-hand rig and camera placement helpers.

Frames: OpenCV camera frame (x right, y down, z forward); lengths in millimetres; ``T_a_b`` is a 4x4 matrix
mapping coordinates of frame b into frame a.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from poseintegrity.poses import pose_matrix

if TYPE_CHECKING:
    from poseintegrity.scenes.params import CameraParams


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics of the rendered images (no distortion).

    width, height : image size in pixels; K : (3, 3) float, pixels.
    """

    width: int
    height: int
    K: np.ndarray

    @classmethod
    def from_params(cls, camera: "CameraParams") -> "Intrinsics":
        """IDS U3-3060CP: f_px = f_mm / pixel pitch (docs/references.md, "Camera of the Windsor et al. experiments"), principal point at the centre, downscaled."""
        scale = 1.0 / camera.downscale
        f_px = camera.lens_mm / (camera.pixel_um * 1e-3) * scale
        width = camera.sensor_width_px // camera.downscale
        height = camera.sensor_height_px // camera.downscale
        # pixel centres at integer coordinates: the optical axis meets the image centre at (w - 1) / 2
        K = np.array([[f_px, 0.0, (width - 1) / 2], [0.0, f_px, (height - 1) / 2], [0.0, 0.0, 1.0]])
        return cls(width, height, K)


def defocus_sigma_px(depth_mm: float, focus_mm: float, camera: "CameraParams") -> float:
    """Gaussian sigma (rendered pixels) of the defocus blur of a point at ``depth_mm`` when the lens is focused
    at ``focus_mm``: the thin-lens circle of confusion c = f^2 / N * |d - d_f| / (d (d_f - f)), taken as a
    Gaussian of sigma c / 2 (the lens is focused once, at the model view, and never refocused)."""
    f = camera.lens_mm
    c_mm = f**2 / camera.f_number * abs(depth_mm - focus_mm) / (depth_mm * (focus_mm - f))
    return 0.5 * c_mm / (camera.pixel_um * 1e-3) / camera.downscale


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

