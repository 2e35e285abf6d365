"""AHAT-like IR reflectivity and depth frames with marker blobs, phantom reflections and noise.

A pinhole camera stands in for the HoloLens 2 AHAT camera (512 x 512, docs/references.md).  Markers are spheres
rendered by ray casting with ``supersampling**2`` rays per pixel: IR is proportional to the covered
fraction of the pixel, depth is the distance in millimetres *along the ray* to the first hit (as AHAT
reports it), so the detector's depth lookup lands on the sphere surface, not its centre.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from poseintegrity.tracking.params import CameraParams, FrameParams


@dataclass(frozen=True)
class Phantom:
    """A reflection that is not a marker: an ellipse in the image at a constant depth.

    u, v : centre, px; radius_px : minor semi-axis; elongation : major / minor axis (1 = round);
    angle : orientation, rad; depth_mm : along the ray.
    """

    u: float
    v: float
    radius_px: float
    elongation: float
    angle: float
    depth_mm: float


def intrinsics(camera: CameraParams) -> np.ndarray:
    """Pinhole K (3, 3), principal point at the image centre."""
    return np.array(
        [[camera.focal_px, 0.0, (camera.width - 1) / 2.0], [0.0, camera.focal_px, (camera.height - 1) / 2.0], [0.0, 0.0, 1.0]]
    )


def unit_plane_lut(K: np.ndarray, width: int, height: int) -> np.ndarray:
    """Per-pixel unit-plane lookup table of a pinhole camera, (H, W, 2): ``lut[v, u] = (x, y)`` at z = 1.

    This is the form the HoloLens Research Mode API gives (docs/references.md).
    """
    u, v = np.meshgrid(np.arange(width, dtype=float), np.arange(height, dtype=float))
    return np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1]], axis=-1)


def draw_phantoms(n: int, camera: CameraParams, frames: FrameParams, round_fraction: float, rng: np.random.Generator) -> list[Phantom]:
    """n random reflections; a share ``round_fraction`` of them round (they pass the circularity test)."""
    phantoms = []
    for _ in range(n):
        is_round = rng.random() < round_fraction
        phantoms.append(
            Phantom(
                u=rng.uniform(10, camera.width - 10),
                v=rng.uniform(10, camera.height - 10),
                radius_px=rng.uniform(*frames.phantom_radius_px),
                elongation=1.0 if is_round else rng.uniform(*frames.phantom_elongation),
                angle=rng.uniform(0, np.pi),
                depth_mm=rng.uniform(*frames.phantom_depth_mm),
            )
        )
    return phantoms


@lru_cache(maxsize=8)
def _subpixel_offsets(s: int) -> tuple[np.ndarray, np.ndarray]:
    """Offsets (s*s,) in u and in v of ``s x s`` rays from the centre of their pixel, px (row-major grid)."""
    offsets = (np.arange(s) + 0.5) / s - 0.5
    du, dv = np.meshgrid(offsets, offsets)
    return du.ravel(), dv.ravel()


def _subpixel_grid(u0: int, v0: int, u1: int, v1: int, s: int) -> tuple[np.ndarray, np.ndarray]:
    """Sample positions (h, w, s*s) of ``s x s`` rays per pixel in the patch [u0, u1) x [v0, v1)."""
    du, dv = _subpixel_offsets(s)
    uu = np.arange(u0, u1, dtype=float)[None, :, None] + du
    vv = np.arange(v0, v1, dtype=float)[:, None, None] + dv
    return np.broadcast_to(uu, (v1 - v0, u1 - u0, s * s)), np.broadcast_to(vv, (v1 - v0, u1 - u0, s * s))


def render_frame(
    markers_cam: np.ndarray,
    phantoms: list[Phantom],
    camera: CameraParams,
    frames: FrameParams,
    marker_radius_m: float,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """Render one IR and one depth frame.

    markers_cam : (k, 3) centres of the visible markers in the camera frame, metres (z forward).
    phantoms : reflections to draw.  marker_radius_m : sphere radius, m.
    Returns ir : (H, W) uint16 (raw reflectivity, background ~80, markers saturate above 1000) and
    depth_mm : (H, W) uint16, millimetres along the ray (background_depth_mm where nothing is hit).

    Depth is kept as whole millimetres throughout: rounding and clipping to uint16 are monotone, so rounding
    each surface before taking the nearest one gives the same image as rounding the nearest float depth.
    """
    H, W, s = camera.height, camera.width, frames.supersampling
    K = intrinsics(camera)
    brightness = np.zeros((H, W), dtype=np.float32)
    depth = np.full((H, W), depth_mm_uint16(frames.background_depth_mm), dtype=np.uint16)
    frame_bias = rng.normal(0.0, frames.frame_depth_bias_std_mm)
    for c in markers_cam[np.argsort(-markers_cam[:, 2])] if len(markers_cam) else []:
        if c[2] <= marker_radius_m:
            continue
        u_c, v_c = K[0, 0] * c[0] / c[2] + K[0, 2], K[1, 1] * c[1] / c[2] + K[1, 2]
        rho = camera.focal_px * marker_radius_m / np.sqrt(c[2] ** 2 - marker_radius_m**2) + 2.0
        u0, u1 = max(int(u_c - rho), 0), min(int(u_c + rho) + 2, W)
        v0, v1 = max(int(v_c - rho), 0), min(int(v_c + rho) + 2, H)
        if u0 >= u1 or v0 >= v1:
            continue
        uu, vv = _subpixel_grid(u0, v0, u1, v1, s)
        rays = np.stack([(uu - K[0, 2]) / K[0, 0], (vv - K[1, 2]) / K[1, 1], np.ones_like(uu)], axis=-1)
        rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
        proj = rays @ c  # ray-sphere intersection: t = d.c - sqrt(R^2 - |c|^2 + (d.c)^2)
        disc = marker_radius_m**2 - (c @ c - proj**2)
        hit = disc > 0
        t_mm = np.where(hit, (proj - np.sqrt(np.where(hit, disc, 0.0))) * 1000.0, np.inf)
        cover = hit.mean(axis=-1)
        near = t_mm.min(axis=-1)
        bias = frame_bias + rng.normal(0.0, frames.depth_bias_std_mm)
        noisy = depth_mm_uint16(near + bias + rng.normal(0.0, frames.depth_noise_mm, near.shape))
        patch = (slice(v0, v1), slice(u0, u1))
        depth[patch] = np.where(cover > 0, np.minimum(depth[patch], noisy), depth[patch])
        level = frames.marker_ir + rng.normal(0.0, frames.marker_ir_std)
        brightness[patch] = np.maximum(brightness[patch], level * cover)
    for p in phantoms:
        extent = p.radius_px * p.elongation + 2.0
        u0, u1 = max(int(p.u - extent), 0), min(int(p.u + extent) + 2, W)
        v0, v1 = max(int(p.v - extent), 0), min(int(p.v + extent) + 2, H)
        uu, vv = _subpixel_grid(u0, v0, u1, v1, s)
        cos, sin = np.cos(p.angle), np.sin(p.angle)
        a = ((uu - p.u) * cos + (vv - p.v) * sin) / (p.radius_px * p.elongation)
        b = (-(uu - p.u) * sin + (vv - p.v) * cos) / p.radius_px
        cover = (a * a + b * b <= 1.0).mean(axis=-1)
        patch = (slice(v0, v1), slice(u0, u1))
        noisy = depth_mm_uint16(p.depth_mm + rng.normal(0.0, frames.depth_noise_mm, cover.shape))
        depth[patch] = np.where(cover > 0, np.minimum(depth[patch], noisy), depth[patch])
        brightness[patch] = np.maximum(brightness[patch], (frames.marker_ir + rng.normal(0.0, frames.marker_ir_std)) * cover)
    ir = rng.standard_normal((H, W), dtype=np.float32)  # in place: frames.ir_background + frames.ir_noise_std * noise + brightness
    ir *= np.float32(frames.ir_noise_std)
    ir += np.float32(frames.ir_background)
    ir += brightness
    return np.clip(np.rint(ir, out=ir), 0, 65535, out=ir).astype(np.uint16), depth


def depth_mm_uint16(depth_mm: np.ndarray | float) -> np.ndarray:
    """Depth (any shape) in mm rounded to whole millimetres and clipped to the uint16 range, as the sensor stores it."""
    return np.clip(np.rint(depth_mm), 0, 65535).astype(np.uint16)
