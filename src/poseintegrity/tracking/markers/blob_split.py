"""Two markers in one blob (ours, ``split_touching``; :mod:`.detection`'s docstring): cut where the depth inside the
blob jumps (:func:`split_by_depth`), or else fit the blob as the union of two touching discs
(:func:`split_two_discs`). Pixels (u, v), depths in mm.
"""

from __future__ import annotations

import numpy as np

from poseintegrity.params.track import DetectionParams
from poseintegrity.tracking.markers.blob_shape import blob_pixels
from poseintegrity.tracking.markers.depth_readings import compiled_depth, largest_depth_gap, small_median


def fit_circle(points: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Least-squares circle (Kasa) through points (k, 2): (centre (2,), radius, RMS radial residual), px."""
    A = np.column_stack([2.0 * points, np.ones(len(points))])
    b = (points**2).sum(axis=1)
    (cx, cy, c), *_ = np.linalg.lstsq(A, b, rcond=None)
    centre = np.array([cx, cy])
    radius = float(np.sqrt(max(c + cx * cx + cy * cy, 0.0)))
    residual = float(np.sqrt(np.mean((np.linalg.norm(points - centre, axis=1) - radius) ** 2)))
    return centre, radius, residual


def lens_area(d: float, R1: float, R2: float) -> float:
    """Area of the overlap of two discs of radii R1, R2 whose centres are d apart (px^2)."""
    if d >= R1 + R2:
        return 0.0
    if d <= abs(R1 - R2):
        return float(np.pi * min(R1, R2) ** 2)
    a1 = R1 * R1 * np.arccos((d * d + R1 * R1 - R2 * R2) / (2 * d * R1))
    a2 = R2 * R2 * np.arccos((d * d + R2 * R2 - R1 * R1) / (2 * d * R2))
    return float(a1 + a2 - 0.5 * np.sqrt(max((-d + R1 + R2) * (d + R1 - R2) * (d - R1 + R2) * (d + R1 + R2), 0.0)))


def split_two_discs(contour: np.ndarray, detection: DetectionParams) -> np.ndarray:
    """Centres (2, 2) px of two touching discs whose union is this blob, or (0, 2) if it is not such a union.

    Boundary points start split along the blob's principal axis and are then reassigned to the circle whose
    radius they fit better until the split settles (k-means with circles as centres).  Accepted when both
    circles fit within split_max_residual_px, their radii agree within a factor 2, their centres are apart by
    more than half the smaller radius, the discs touch, 97 % of the blob's pixels lie in one of them, the
    area of their union is the blob's within 30 %, and the blob narrows between the centres (a neck at most
    0.85 times as wide as the blob through either centre: an elongated reflection is a bar, not two discs).
    """
    points = contour.reshape(-1, 2).astype(float)
    if len(points) < 8:
        return np.zeros((0, 2))
    mean = points.mean(axis=0)
    _, _, Vt = np.linalg.svd(points - mean, full_matrices=False)
    side = (points - mean) @ Vt[0] > 0
    for _ in range(10):
        if side.sum() < 4 or (~side).sum() < 4:
            return np.zeros((0, 2))
        fits = [fit_circle(points[s]) for s in (side, ~side)]
        gaps = np.stack([np.abs(np.linalg.norm(points - c, axis=1) - r) for c, r, _ in fits], axis=1)
        new_side = gaps[:, 0] < gaps[:, 1]
        if np.array_equal(new_side, side):
            break
        side = new_side
    (c1, r1, e1), (c2, r2, e2) = fits
    d = float(np.linalg.norm(c1 - c2))
    if max(e1, e2) > detection.split_max_residual_px or not (0.5 < r1 / max(r2, 1e-9) < 2.0) or d < 0.5 * min(r1, r2):
        return np.zeros((0, 2))
    R1, R2 = r1 + 0.5, r2 + 0.5  # boundary pixel centres lie half a pixel inside the disc edge
    if d > R1 + R2 + 0.5:  # the images of two markers touch or overlap; separate blobs would not be one contour
        return np.zeros((0, 2))
    pixels = blob_pixels(contour).astype(float)
    inside = (np.linalg.norm(pixels - c1, axis=1) <= R1 + 0.5) | (np.linalg.norm(pixels - c2, axis=1) <= R2 + 0.5)
    union = np.pi * (R1 * R1 + R2 * R2) - lens_area(d, R1, R2)
    if inside.mean() < 0.97 or abs(union - len(pixels)) > 0.3 * len(pixels):  # the blob is the union of the discs
        return np.zeros((0, 2))
    axis = (c2 - c1) / max(d, 1e-9)
    along, across = (pixels - c1) @ axis, (pixels - c1) @ np.array([-axis[1], axis[0]])

    def width(at: float) -> float:  # extent of the blob across the axis, in a one-pixel slab
        slab = np.abs(along - at) <= 0.5
        return float(np.ptp(across[slab]) + 1.0) if slab.any() else 0.0

    if width(d / 2) > 0.85 * min(width(0.0), width(d)):  # two discs have a neck between them; a bar does not
        return np.zeros((0, 2))
    return np.stack([c1, c2])


def split_by_depth(pixels: np.ndarray, depth_mm: np.ndarray, detection: DetectionParams) -> tuple[np.ndarray, np.ndarray]:
    """Markers one partly in front of the other: (centres (m, 2) px, depths (m,) mm), m = 0, 1 or 2.

    pixels : (k, 2) int (u, v) of one blob.  Two markers whose images overlap lie nearly on one ray, so their
    depths differ by a good part of their distance (tens of mm) while one sphere's visible surface spans at most
    its radius (5.5 mm) plus noise.  If the sorted valid depths of the blob have a gap of at least
    depth_split_mm, the blob is cut there: the front set is a whole disc (its pixel centroid is its centre); the
    back set is the visible crescent of the hidden marker, whose disc has the front disc's radius scaled by the
    depth ratio and reaches to the crescent's farthest pixel, which places its centre even when only a sliver
    shows.  Depths are the medians of each set.  A set smaller than min_area is left out.  m = 0: no depth gap.
    """
    gap = largest_depth_gap(compiled_depth(depth_mm), np.ascontiguousarray(pixels, dtype=np.int64), float(detection.depth_min_mm), float(detection.depth_max_mm))
    if not gap >= detection.depth_split_mm:
        return np.zeros((0, 2)), np.zeros(0)  # one marker (nearly every blob): decided in one compiled call
    d_all = np.asarray(depth_mm[pixels[:, 1], pixels[:, 0]], dtype=float)
    valid = np.isfinite(d_all) & (d_all >= detection.depth_min_mm) & (d_all <= detection.depth_max_mm)
    ordered = np.sort(d_all[valid])
    i = int(np.argmax(np.diff(ordered)))
    cut = 0.5 * (ordered[i] + ordered[i + 1])
    front, back = valid & (d_all <= cut), valid & (d_all > cut)
    centres, depths = [], []
    if front.sum() >= detection.min_area:
        c_front = pixels[front].mean(axis=0)
        d_front, d_back = small_median(d_all[front]), small_median(d_all[back])
        centres.append(c_front)
        depths.append(d_front)
        if back.sum() >= detection.min_area:
            # the hidden marker's disc: radius from the front disc's (pixel count = pi r^2) scaled by the depth
            # ratio of the sphere centres; it reaches exactly to the farthest visible pixel of the crescent
            r_back = np.sqrt(front.sum() / np.pi) * (d_front + detection.depth_offset_mm) / (d_back + detection.depth_offset_mm)
            offset = pixels[back].mean(axis=0) - c_front
            u = offset / max(np.linalg.norm(offset), 1e-9)
            reach = float(((pixels[back] - c_front) @ u).max()) + 0.5  # edge of the farthest pixel
            centres.append(c_front + u * max(reach - r_back, 0.0))
            depths.append(d_back)
    elif back.sum() >= detection.min_area:
        centres.append(pixels[back].mean(axis=0))
        depths.append(small_median(d_all[back]))
    return np.array(centres, dtype=float).reshape(-1, 2), np.array(depths)
