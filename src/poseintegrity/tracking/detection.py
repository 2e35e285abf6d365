"""IR marker detection (section II-B): threshold, contours, circularity filter, centroid, depth, unprojection.

Usable on real HoloLens 2 AHAT frames: ``unproject`` is either a 3x3 pinhole K or the per-pixel unit-plane
lookup table (H, W, 2) of the Research Mode API; IR may be uint8 (already 8-bit) or uint16 (raw).
Constants are those of their public code (FACTS.md): IR clipped at 1000 and scaled to 8 bit, threshold 222,
contour area 2-1000 px, circularity >= 0.6 (area over the area of the minimum enclosing circle), convexity
>= 0.75, depth window 100-900 mm.
"""

from __future__ import annotations

import warnings

import cv2
import numpy as np

from poseintegrity.tracking.geometry import transform_points


def validate_frame(ir: np.ndarray, depth_mm: np.ndarray, unproject: np.ndarray) -> str:
    """Why a frame cannot be used, or "" if it can.

    ir : (H, W) uint8/uint16/float; depth_mm : (H, W) numeric; unproject : (3, 3) K or (H, W, 2) LUT.
    """
    ir, depth_mm, unproject = np.asarray(ir), np.asarray(depth_mm), np.asarray(unproject)
    if ir.ndim != 2 or ir.size == 0:
        return f"IR image must be 2-D and non-empty, got shape {ir.shape}"
    if depth_mm.shape != ir.shape:
        return f"depth shape {depth_mm.shape} differs from IR shape {ir.shape}"
    if not (np.issubdtype(ir.dtype, np.number) and np.issubdtype(depth_mm.dtype, np.number)):
        return "IR and depth must be numeric"
    if unproject.shape != (3, 3) and unproject.shape != ir.shape + (2,):
        return f"unproject must be a 3x3 K or an (H, W, 2) = {ir.shape + (2,)} lookup table, got {unproject.shape}"
    return ""


def detect_blobs(
    ir: np.ndarray,
    *,
    threshold: int = 222,
    ir_clip: float = 1000.0,
    min_area: float = 2.0,
    max_area: float = 1000.0,
    min_circularity: float = 0.6,
    min_convexity: float = 0.75,
) -> np.ndarray:
    """Centroids (k, 2) float (u, v), pixels, of the bright round blobs of an IR image (II-B).

    uint8 input is compared with ``threshold`` directly; other types are raw reflectivity, clipped at
    ir_clip and scaled to 8 bit, which is the comparison ``ir > threshold * ir_clip / 255``.
    """
    raw_threshold = threshold if ir.dtype == np.uint8 else threshold * ir_clip / 255.0
    if ir.dtype not in (np.uint8, np.uint16, np.float32, np.float64):
        ir = ir.astype(np.float64)
    mask = cv2.compare(ir, float(raw_threshold), cv2.CMP_GT)  # 255 where brighter
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    centroids = []
    for contour in contours:
        area = cv2.contourArea(contour)
        if not (min_area <= area <= max_area):
            continue
        _, radius = cv2.minEnclosingCircle(contour)
        if area / (np.pi * radius * radius) < min_circularity:  # circularity (FACTS.md form of 4 pi a / c^2)
            continue
        hull_area = cv2.contourArea(cv2.convexHull(contour))
        if hull_area <= 0 or area / hull_area < min_convexity:
            continue
        m = cv2.moments(contour)
        centroids.append((m["m10"] / m["m00"], m["m01"] / m["m00"]))  # m00 = area > 0 here
    return np.array(centroids, dtype=float).reshape(-1, 2)


def lookup_depth(
    depth_mm: np.ndarray, uv: np.ndarray, *, window: int = 1, depth_min_mm: float = 100.0, depth_max_mm: float = 900.0
) -> np.ndarray:
    """Depth (k,) mm at the centroids: median of the valid pixels in a (2w+1)^2 window, NaN if none.

    Valid means finite and inside [depth_min_mm, depth_max_mm] (zero, NaN and far readings are rejected).
    """
    H, W = depth_mm.shape
    out = np.full(len(uv), np.nan)
    for k, (u, v) in enumerate(np.rint(uv).astype(int)):
        patch = np.asarray(depth_mm[max(v - window, 0) : v + window + 1, max(u - window, 0) : u + window + 1], dtype=float)
        valid = patch[np.isfinite(patch) & (patch >= depth_min_mm) & (patch <= depth_max_mm)]
        if valid.size:
            valid = np.sort(valid)
            out[k] = 0.5 * (valid[(valid.size - 1) // 2] + valid[valid.size // 2])  # median
    return out


def unit_plane_coordinates(uv: np.ndarray, unproject: np.ndarray) -> np.ndarray:
    """(k, 2) points (x, y) on the z = 1 plane for pixels uv (k, 2), via K or bilinear LUT interpolation."""
    if unproject.shape == (3, 3):
        K = unproject
        return np.stack([(uv[:, 0] - K[0, 2]) / K[0, 0], (uv[:, 1] - K[1, 2]) / K[1, 1]], axis=-1)
    H, W = unproject.shape[:2]
    u = np.clip(uv[:, 0], 0, W - 1.000001)
    v = np.clip(uv[:, 1], 0, H - 1.000001)
    u0, v0 = np.floor(u).astype(int), np.floor(v).astype(int)
    fu, fv = (u - u0)[:, None], (v - v0)[:, None]
    top = (1 - fu) * unproject[v0, u0] + fu * unproject[v0, u0 + 1]
    bottom = (1 - fu) * unproject[v0 + 1, u0] + fu * unproject[v0 + 1, u0 + 1]
    return (1 - fv) * top + fv * bottom


def detect_markers(
    ir: np.ndarray,
    depth_mm: np.ndarray,
    unproject: np.ndarray,
    *,
    T_world_cam: np.ndarray | None = None,
    threshold: int = 222,
    ir_clip: float = 1000.0,
    min_area: float = 2.0,
    max_area: float = 1000.0,
    min_circularity: float = 0.6,
    min_convexity: float = 0.75,
    depth_min_mm: float = 100.0,
    depth_max_mm: float = 900.0,
    depth_window: int = 1,
    depth_offset_mm: float = 0.0,
) -> np.ndarray:
    """Marker centres (n, 3), metres, in the world frame, from one IR + depth frame (section II-B).

    ir : (H, W) uint8 or uint16 reflectivity; depth_mm : (H, W) millimetres along each pixel's ray
    (0 or NaN = invalid); unproject : (3, 3) pinhole K or (H, W, 2) unit-plane LUT, lut[v, u] = (x, y);
    T_world_cam : (4, 4) extrinsics, identity if None; depth_offset_mm : added along the ray (the sphere
    radius, to go from the reflecting surface to the marker centre).
    Blobs without a valid depth are dropped.  An unusable frame (see :func:`validate_frame`) gives an
    empty (0, 3) array and a ``RuntimeWarning`` naming the reason; it never raises.
    """
    reason = validate_frame(ir, depth_mm, unproject)
    if reason:
        warnings.warn(f"detect_markers: {reason}", RuntimeWarning, stacklevel=2)
        return np.zeros((0, 3))
    ir, depth_mm, unproject = np.asarray(ir), np.asarray(depth_mm), np.asarray(unproject, dtype=float)
    uv = detect_blobs(
        ir, threshold=threshold, ir_clip=ir_clip, min_area=min_area, max_area=max_area,
        min_circularity=min_circularity, min_convexity=min_convexity,
    )
    d_mm = lookup_depth(depth_mm, uv, window=depth_window, depth_min_mm=depth_min_mm, depth_max_mm=depth_max_mm)
    keep = np.isfinite(d_mm)
    xy = unit_plane_coordinates(uv[keep], unproject)
    rays = np.column_stack([xy, np.ones(len(xy))])
    rays /= np.linalg.norm(rays, axis=1, keepdims=True)
    points_cam = rays * ((d_mm[keep] + depth_offset_mm) / 1000.0)[:, None]  # depth is measured along the ray
    return points_cam if T_world_cam is None else transform_points(T_world_cam, points_cam)
