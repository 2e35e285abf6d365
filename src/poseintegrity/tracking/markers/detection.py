"""IR marker detection (section II-B): threshold, contours, shape tests, centroid, depth, unprojection.

Usable on real HoloLens 2 AHAT frames: ``unproject`` is either a 3x3 pinhole K or the per-pixel unit-plane
lookup table (H, W, 2) of the Research Mode API; IR may be uint8 (already 8-bit) or uint16 (raw); depth is
millimetres along each pixel's ray.  The constants of their public code (docs/references.md, "Marker
tracking"): IR clipped at 1000 and scaled to 8 bit, threshold 222, contour area 2-1000 px, circularity >= 0.6
(area over the area of the minimum enclosing circle), convexity >= 0.75, depth window 100-900 mm.

Two additions of ours, both switchable in :class:`~poseintegrity.params.track.DetectionParams`:

- ``shape_measure: pixel`` measures a blob by its pixels instead of by the polygon through its boundary
  pixel centres.  A blob of 8-20 px (an 11 mm sphere at 0.6-0.9 m, focal ~250 px) has a contour polygon
  whose area is about half its pixel count (a 3 x 3 square: polygon area 4, 9 pixels), so the published
  ratio is dominated by pixelisation and genuine markers fall below 0.6.  The pixel forms count each pixel
  as a unit square: area = polygon area + boundary length / 2 + 1 (Pick's theorem), circle radius
  = enclosing radius of the pixel centres + 0.5, hull area likewise.  For large blobs both forms agree.
- ``split_touching``: two markers whose images touch or overlap make one blob.  If the depth inside a blob
  jumps by depth_split_mm or more, it is two markers one behind the other, cut at the jump
  (:func:`split_by_depth`); otherwise a blob that fails the shape tests is tried as the union of two discs:
  its boundary points are split between two circles fitted by least squares, kept if both fit within
  ``split_max_residual_px``, their union covers the blob and it narrows between them
  (:func:`split_two_discs`).  Elongated reflections are not two discs and stay rejected.
"""

from __future__ import annotations

import warnings

import cv2
import numba
import numpy as np

from poseintegrity.config import published
from poseintegrity.errors import ArgumentError, PoseIntegrityError, check_intrinsics, check_pose
from poseintegrity.params.track import DetectionParams
from poseintegrity.tracking.markers.blob_shape import blob_pixels, blob_shape
from poseintegrity.tracking.markers.blob_split import split_by_depth, split_two_discs
from poseintegrity.tracking.markers.depth_readings import compiled_depth, small_median, valid_depth_range, window_medians
from poseintegrity.tracking.markers.geometry import transform_points

MIN_METRES_DEPTH_MM = 10.0  # a median depth below this is metres, not millimetres (AHAT depth is 100-1000 mm)
MAX_UNIT_PLANE = 20.0  # |x|, |y| of a pixel ray on the unit plane: 20 is a field of view of 174 deg, beyond any depth camera


class FrameError(PoseIntegrityError):
    """A recorded frame cannot be used as given (wrong shape, dtype, units or lookup table)."""


def validate_frame(ir: np.ndarray, depth_mm: np.ndarray, unproject: np.ndarray) -> str:
    """Why a frame cannot be used, or "" if it can.

    ir : (H, W) uint8/uint16/float; depth_mm : (H, W) numeric, millimetres; unproject : (3, 3) K or (H, W, 2) LUT.
    Depth whose valid (positive, finite) median is below 10 is taken to be in metres; an all-zero or
    non-finite lookup table cannot unproject anything (both read on every 8th row and column); nor can a K that is
    not a finite [[fx, s, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0, or whose image corners lie beyond the
    lookup table's bound (a focal length of a fraction of a pixel).
    """
    ir, depth_mm, unproject = np.asarray(ir), np.asarray(depth_mm), np.asarray(unproject)
    if ir.ndim != 2 or ir.size == 0:
        return f"IR image must be 2-D and non-empty, got shape {ir.shape}"
    if depth_mm.shape != ir.shape:
        return f"depth shape {depth_mm.shape} differs from IR shape {ir.shape}"
    if not (np.issubdtype(ir.dtype, np.number) and np.issubdtype(depth_mm.dtype, np.number)) or ir.dtype == np.bool_:
        return f"IR and depth must be numeric arrays, got dtypes {ir.dtype} and {depth_mm.dtype}"
    if unproject.dtype.kind not in "iuf":
        return f"unproject must be a numeric K or lookup table, got dtype {unproject.dtype}"
    if unproject.shape != (3, 3) and unproject.shape != ir.shape + (2,):
        return f"unproject must be a 3x3 K or an (H, W, 2) = {ir.shape + (2,)} lookup table, got {unproject.shape}"
    if unproject.shape == (3, 3):
        try:
            K = check_intrinsics("unproject (a 3x3 K)", unproject)
        except ArgumentError as error:
            return f"{error}: it cannot unproject pixels"
        corners = np.array([[0.0, 0.0], [ir.shape[1] - 1.0, ir.shape[0] - 1.0]])
        if not np.all(np.abs(unit_plane_coordinates(corners, K)) <= MAX_UNIT_PLANE):
            return (f"unproject (a 3x3 K): fx {K[0, 0]:g}, fy {K[1, 1]:g} px put the image corners beyond "
                    f"{MAX_UNIT_PLANE:g} on the unit plane (a field of view over "
                    f"{2 * np.degrees(np.arctan(MAX_UNIT_PLANE)):.0f} deg): it cannot unproject pixels")
    grid = (slice(None, None, 8), slice(None, None, 8))  # the unit checks read every 8th row and column (fast)
    lut = unproject[grid] if unproject.shape != (3, 3) else None
    if lut is not None and (not np.all(np.abs(lut) <= MAX_UNIT_PLANE) or not np.any(lut)):
        return (f"unit-plane lookup table is all zero, not finite or beyond {MAX_UNIT_PLANE:g} (a field of view over "
                f"{2 * np.degrees(np.arctan(MAX_UNIT_PLANE)):.0f} deg): it cannot unproject pixels")
    sample = np.asarray(depth_mm[grid], dtype=float)
    median = small_median(sample[np.isfinite(sample) & (sample > 0)])
    if median < MIN_METRES_DEPTH_MM:  # False for NaN: no valid depth
        return f"depth looks like metres, not millimetres (median of valid depth {median:.3g} < {MIN_METRES_DEPTH_MM:g})"
    return ""


def raw_threshold(detection: DetectionParams, dtype: np.dtype) -> float:
    """The IR value a pixel of this dtype must exceed to be part of a blob: ``threshold`` for uint8 (already 8-bit),
    else raw reflectivity clipped at ir_clip and scaled to 8 bit, ``threshold * ir_clip / 255``."""
    return float(detection.threshold if np.dtype(dtype) == np.uint8 else detection.threshold * detection.ir_clip / 255.0)


def detect_blobs(ir: np.ndarray, detection: DetectionParams, depth_mm: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Centres (k, 2) float (u, v), pixels, of the bright round blobs of an IR image (II-B), and their depth
    (k,) mm where a depth split measured it (NaN elsewhere: :func:`lookup_depth` reads it at the centre).

    uint8 input is compared with ``threshold`` directly; other types are raw reflectivity, clipped at
    ir_clip and scaled to 8 bit, which is the comparison ``ir > threshold * ir_clip / 255``.
    With ``split_touching`` a blob is first tried as two markers one in front of the other (a depth gap inside
    it, :func:`split_by_depth`, when depth_mm (H, W) is given), and a blob that fails the shape tests as two
    touching discs (:func:`split_two_discs`).
    """
    return detect_blobs_each(ir, [detection], depth_mm)[0]


def detect_blobs_each(ir: np.ndarray, detections: list[DetectionParams], depth_mm: np.ndarray | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`detect_blobs` of one frame with each of several detectors, in order: detectors with the same threshold
    share the mask and its contours, and those with the same shape_measure each blob's shape and moments."""
    if ir.dtype not in (np.uint8, np.uint16, np.float32, np.float64):
        ir = ir.astype(np.float64)
    contours_at, shapes, moments = {}, {}, {}  # by threshold; by (threshold, measure, blob); by (threshold, blob)
    results = []
    for d in detections:
        threshold = raw_threshold(d, ir.dtype)
        if threshold not in contours_at:
            mask = cv2.compare(ir, threshold, cv2.CMP_GT)  # 255 where brighter: the only use of ir
            contours_at[threshold] = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)[0]
        centres, depths = [], []
        depth_range = (float(d.depth_min_mm), float(d.depth_max_mm))
        readable = compiled_depth(depth_mm) if d.split_touching and depth_mm is not None else None
        for b, contour in enumerate(contours_at[threshold]):
            key = (threshold, d.shape_measure, b)
            if key not in shapes:
                shapes[key] = blob_shape(contour, d.shape_measure)
            area, circularity, convexity = shapes[key]
            if not (d.min_area <= area <= 2.0 * d.max_area):
                continue
            # the depth split needs the blob's pixels, unless the readings of its bounding box already span less than a cut
            if readable is not None and valid_depth_range(readable, *cv2.boundingRect(contour), *depth_range) >= d.depth_split_mm:
                uv, dd = split_by_depth(blob_pixels(contour), depth_mm, d)
                if len(uv):
                    centres.extend(map(tuple, uv))
                    depths.extend(dd)
                    continue
            if area <= d.max_area and circularity >= d.min_circularity and convexity >= d.min_convexity:
                if (threshold, b) not in moments:
                    moments[threshold, b] = blob_centroid(contour)
                centres.append(moments[threshold, b])
                depths.append(np.nan)
            elif d.split_touching:
                uv = split_two_discs(contour, d)
                centres.extend(map(tuple, uv))
                depths.extend([np.nan] * len(uv))
        results.append((np.array(centres, dtype=float).reshape(-1, 2), np.array(depths, dtype=float)))
    return results


def blob_centroid(contour: np.ndarray) -> tuple[float, float]:
    """(u, v) px: the centroid of the area inside a contour (k, 1, 2) from its moments, or the mean of its points
    for a blob one pixel wide (its polygon has no area)."""
    m = cv2.moments(contour)
    if m["m00"] > 0:
        return m["m10"] / m["m00"], m["m01"] / m["m00"]
    return tuple(contour.reshape(-1, 2).mean(axis=0))


def lookup_depth(depth_mm: np.ndarray, uv: np.ndarray, detection: DetectionParams) -> np.ndarray:
    """Depth (k,) mm at the centroids uv (k, 2): median of the valid pixels in a (2w+1)^2 window, NaN if none.

    Valid means finite and inside [depth_min_mm, depth_max_mm] (zero, NaN and far readings are rejected).
    """
    uv_int = np.ascontiguousarray(np.rint(uv).astype(np.int64).reshape(-1, 2))
    return window_medians(compiled_depth(depth_mm), uv_int, int(detection.depth_window), float(detection.depth_min_mm), float(detection.depth_max_mm))


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
    detection: DetectionParams | None = None,
    T_world_cam: np.ndarray | None = None,
) -> np.ndarray:
    """Marker centres (n, 3), metres, in the world frame, from one IR + depth frame (section II-B).

    ir : (H, W) uint8 or uint16 reflectivity; depth_mm : (H, W) millimetres along each pixel's ray
    (0 or NaN = invalid); unproject : (3, 3) pinhole K or (H, W, 2) unit-plane LUT, lut[v, u] = (x, y);
    detection : the detector's constants (``track.detection``; None: the published defaults); T_world_cam : (4, 4) extrinsics, identity if
    None.  depth_offset_mm is added along the ray (the sphere radius: from the reflecting surface to the centre).
    Blobs without a valid depth are dropped.  An unusable frame (see :func:`validate_frame`: IR, depth, K or lookup
    table) gives an empty (0, 3) array and a ``RuntimeWarning`` naming the reason; a frame never raises.
    T_world_cam that is not a finite rigid (4, 4) transform is refused (:class:`~poseintegrity.errors.ArgumentError`
    naming it): points through NaN extrinsics would be NaN.
    """
    detection = published("track.detection") if detection is None else detection
    T_world_cam = None if T_world_cam is None else check_pose("T_world_cam", T_world_cam)
    reason = validate_frame(ir, depth_mm, unproject)
    if reason:
        warnings.warn(f"detect_markers: {reason}", RuntimeWarning, stacklevel=2)
        return np.zeros((0, 3))
    return detect_markers_unchecked(np.asarray(ir), np.asarray(depth_mm), np.asarray(unproject, dtype=float), detection, T_world_cam)


def detect_markers_unchecked(ir: np.ndarray, depth_mm: np.ndarray, unproject: np.ndarray, detection: DetectionParams,
                             T_world_cam: np.ndarray | None = None) -> np.ndarray:
    """:func:`detect_markers` on a frame known to be usable (arrays that :func:`validate_frame` accepts, unproject
    float): the per-frame path of frames the library rendered or validated itself."""
    return detect_markers_each(ir, depth_mm, unproject, [detection], T_world_cam)[0]


def detect_markers_each(ir: np.ndarray, depth_mm: np.ndarray, unproject: np.ndarray, detections: list[DetectionParams],
                        T_world_cam: np.ndarray | None = None) -> list[np.ndarray]:
    """:func:`detect_markers_unchecked` of one frame with each of several detectors (sharing what they have in
    common, :func:`detect_blobs_each`): one (n, 3) array of points per detector, in order."""
    points = []
    for detection, (uv, d_split) in zip(detections, detect_blobs_each(ir, detections, depth_mm)):
        d_mm = np.where(np.isnan(d_split), lookup_depth(depth_mm, uv, detection), d_split)
        keep = np.isfinite(d_mm)
        points_cam = points_along_rays(unit_plane_coordinates(uv[keep], unproject), d_mm[keep] + detection.depth_offset_mm)
        points.append(points_cam if T_world_cam is None else transform_points(T_world_cam, points_cam))
    return points


@numba.njit(cache=True, nogil=True)
def points_along_rays(xy, distance_mm):  # pragma: no cover - compiled
    """Points (k, 3) m at distance_mm (k,) along the rays through xy (k, 2) on the z = 1 plane (AHAT depth is measured
    along the ray): (x, y, 1) / |(x, y, 1)| * distance_mm / 1000, rounded as numpy rounds it (the norm's squares
    summed in order, then the division, then the product)."""
    points = np.empty((len(xy), 3))
    for k in range(len(xy)):
        x, y = xy[k, 0], xy[k, 1]
        norm = np.sqrt((x * x + y * y) + 1.0 * 1.0)
        scale = distance_mm[k] / 1000.0
        points[k, 0], points[k, 1], points[k, 2] = (x / norm) * scale, (y / norm) * scale, (1.0 / norm) * scale
    return points
