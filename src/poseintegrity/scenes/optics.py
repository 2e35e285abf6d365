"""The lens between the rendered radiance and the sensor: depth of field and the lens' own blur.

The camera is focused once per session (IV-D: the robot then moves; a fixed-focus machine-vision lens is not
refocused): an arc's at the model view's aim point, the lines' where ``generate.lines.focus`` says (the model view,
or the range the lines image), so every point is blurred by its own circle of confusion, which grows with its
distance from the focus plane: the far clutter of a view, the far side of a target seen obliquely, the target at the
ends of a line. The blur of a pixel is a Gaussian of sigma = hypot(lens blur, defocus(depth)),
applied as a layered depth-of-field approximation (the radiance blurred at a ladder of sigmas, each pixel
interpolated between the two rungs around its own sigma): exact inside a surface, approximate at depth edges.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import cv2
import numpy as np

if TYPE_CHECKING:
    from poseintegrity.params.camera import CameraParams

LADDER_RATIO = 1.25  # successive blur sigmas of the layered approximation; interpolation error < 3 % of a sigma
SHARPEST_SIGMA_PX = 0.1  # below this a Gaussian blur changes nothing a sensor can see


def defocus_sigma_px(depth_mm: np.ndarray | float, focus_mm: float, camera: "CameraParams") -> np.ndarray:
    """Gaussian sigma (rendered pixels) of the defocus blur of points at ``depth_mm`` (along z; inf: the background)
    when the lens is focused at ``focus_mm``: the thin-lens circle of confusion
    c = f^2 / N * |d - d_f| / (d (d_f - f)), taken as a Gaussian of sigma c / 2."""
    f = camera.lens_mm
    d = np.asarray(depth_mm, dtype=float)
    with np.errstate(invalid="ignore"):
        relative = np.where(np.isinf(d), 1.0, np.abs(d - focus_mm) / d)  # |d - d_f| / d -> 1 as d -> inf
    c_mm = f**2 / camera.f_number * relative / (focus_mm - f)
    return 0.5 * c_mm / (camera.pixel_um * 1e-3) / camera.downscale


def blur_by_sigma(radiance: np.ndarray, sigma_px: np.ndarray) -> np.ndarray:
    """(h, w) float32 radiance blurred per pixel by a Gaussian of that pixel's sigma (h, w), px.

    The rungs sigma_0 < sigma_1 < ... step by LADDER_RATIO from the smallest sigma to the largest; a pixel takes
    (1 - t) B_i + t B_{i+1} with B_i the radiance blurred at sigma_i and t its sigma's place between the two.
    """
    radiance = np.ascontiguousarray(radiance, dtype=np.float32)
    low, high = float(sigma_px.min()), float(sigma_px.max())
    if high <= SHARPEST_SIGMA_PX:
        return radiance.copy()
    low = max(low, SHARPEST_SIGMA_PX)
    n = max(int(np.ceil(np.log(high / low) / np.log(LADDER_RATIO))), 1)
    rungs = low * (high / low) ** (np.arange(n + 1) / n)
    position = np.interp(sigma_px, rungs, np.arange(n + 1, dtype=float)).astype(np.float32)
    out = np.zeros_like(radiance)
    for i, sigma in enumerate(rungs):
        weight = np.clip(1.0 - np.abs(position - i), 0.0, 1.0)  # hat function: rungs i-1, i, i+1
        if not weight.any():
            continue
        blurred = cv2.GaussianBlur(radiance, (0, 0), float(sigma)) if sigma > SHARPEST_SIGMA_PX else radiance
        out += weight * blurred
    return out


def lens(radiance: np.ndarray, depth_mm: np.ndarray, focus_mm: float, blur_sigma_px: float,
         camera: "CameraParams") -> np.ndarray:
    """The lens: (h, w) radiance and its depth (mm along z, inf: nothing) -> (h, w) irradiance, each pixel blurred
    by hypot(the lens' own blur, its defocus). Done once per robot pose: blur is linear and the flicker a scalar
    gain, so the two commute."""
    sigma = np.hypot(blur_sigma_px, defocus_sigma_px(depth_mm, focus_mm, camera)).astype(np.float32)
    return blur_by_sigma(radiance, sigma)
