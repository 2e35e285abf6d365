"""Where world points, boards and targets fall in the image of a pinhole camera (K (3, 3), px; poses T_cam_world
(4, 4), mm), the geometry both board placements share (:mod:`.board_placement`, :mod:`.board_plan`): points projected
(:func:`project`, the points in front of the camera alone, for a silhouette's hull; :func:`pixels`, every point and
whether it is in front), a target's silhouette hull (:func:`hull`: the convex hull of its projected vertices contains
its silhouette), the pixels near the hulls (:func:`near_targets`, :class:`Mask`), whether points fall on them
(:func:`hits`), whether a hull vertex lies inside a board's quad (:func:`vertices_inside`) and whether two convex
polygons come within CLEARANCE_PX of each other (:func:`overlap`).

The per-point kernels are compiled (numba, no fastmath) and round as numpy and OpenBLAS do (:func:`to_camera`); they
read CLEARANCE_PX and NEAR_MM when compiled.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

CLEARANCE_PX = 6.0  # between a board (or its post) and a target's silhouette hull, in the image
NEAR_MM = 20.0  # points nearer the camera than this are behind it


def project(points: np.ndarray, T_cam_world: np.ndarray, K: np.ndarray) -> np.ndarray:
    """(n, 2) pixels of world points (n, 3) in front of the camera (those nearer than NEAR_MM are left out)."""
    cam = points @ T_cam_world[:3, :3].T + T_cam_world[:3, 3]
    cam = cam[cam[:, 2] > NEAR_MM]
    return (cam[:, :2] / cam[:, 2:3]) @ K[:2, :2].T + K[:2, 2]


def hull(points: np.ndarray) -> np.ndarray:
    """The convex hull (m, 2) of image points (k, 2) (those behind the camera already left out; a post seen end on
    is a line)."""
    return cv2.convexHull(points.astype(np.float32)).reshape(-1, 2) if len(points) else points


def near_targets(hulls: list[np.ndarray], width: int, height: int, clearance_px: float) -> np.ndarray:
    """(height, width) bool: the pixels within ``clearance_px`` of the targets' silhouette hulls (their hulls grown by
    a square of that half-width: a disc would do, the square errs on the side of clearance and is 20 x faster)."""
    mask = np.zeros((height, width), np.uint8)
    for polygon in hulls:
        cv2.fillConvexPoly(mask, np.round(polygon).astype(np.int32), 1)
    size = 2 * int(np.ceil(clearance_px)) + 1
    return cv2.dilate(mask, cv2.getStructuringElement(cv2.MORPH_RECT, (size, size))).astype(bool)


@dataclass(frozen=True)
class Mask:
    """Image pixels near an obstacle (:func:`near_targets`), kept as their bounding box: ``pixels`` (rows, columns)
    from pixel column ``u0`` and row ``v0`` (outside it the whole image's mask is False)."""

    pixels: np.ndarray
    u0: int
    v0: int

    @classmethod
    def near(cls, hull: np.ndarray, width: int, height: int, clearance_px: float) -> Mask:
        """The pixels within ``clearance_px`` of an image hull (h, 2)."""
        mask = near_targets([hull], width, height, clearance_px)
        rows, columns = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
        if len(rows) == 0:
            return cls(np.zeros((0, 0), bool), 0, 0)
        return cls(mask[rows[0]:rows[-1] + 1, columns[0]:columns[-1] + 1], int(columns[0]), int(rows[0]))

    def reaches(self, low: np.ndarray, high: np.ndarray) -> np.ndarray:
        """(k,) whether boxes from ``low`` to ``high`` (k, 2: u, v px) come within a pixel of the mask's: a point
        rounds onto a pixel of the mask only from within half a pixel of it."""
        rows, columns = self.pixels.shape
        return ((high[:, 0] >= self.u0 - 1) & (low[:, 0] <= self.u0 + columns) & (high[:, 1] >= self.v0 - 1)
                & (low[:, 1] <= self.v0 + rows))

    def on(self, points: np.ndarray, front: np.ndarray) -> np.ndarray:
        """(k, l) whether each point (k, l, 2 px) in front of the camera (``front`` (k, l)) falls on the mask, rounded
        to its pixel."""
        on = np.empty(front.shape, bool)
        _on_mask(points, front, self.pixels, self.u0, self.v0, on)
        return on


def hits(points: np.ndarray, front: np.ndarray, near: np.ndarray) -> np.ndarray:
    """(n,) whether any of each candidate's points (n, k, 2 px) in front of the camera and inside the image falls on
    ``near`` ((height, width): :func:`near_targets`), rounded to its pixel."""
    return Mask(near, 0, 0).on(points, front).any(axis=1)


def vertices_inside(quads: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(n,) whether any of ``points`` (m, 2) lies inside each convex quad (n, 4, 2) (either winding)."""
    edges = np.roll(quads, -1, axis=1) - quads  # (n, 4, 2)
    rel = points[None, None, :, :] - quads[:, :, None, :]  # (n, 4, m, 2)
    cross = edges[:, :, None, 0] * rel[..., 1] - edges[:, :, None, 1] * rel[..., 0]  # (n, 4, m)
    return (np.all(cross >= 0, axis=1) | np.all(cross <= 0, axis=1)).any(axis=1)


def pixels(points: np.ndarray, view: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pixels (k, m, 2) of world points (k, m, 3) at ``view`` (T_cam_world (4, 4), or one per pose (p, 4, 4): then
    (p, k, m, 2)) and whether each is in front of the camera (k, m or p, k, m), as numpy's ``points @ R.T + t`` (m >
    1) and ``fx x / z + cx`` compute them, to the bit (:func:`project_point`; behind the camera z is taken as 1)."""
    views = view.reshape(-1, 4, 4)
    uv, front = np.empty((len(views), *points.shape[:2], 2)), np.empty((len(views), *points.shape[:2]), bool)
    _pixels_at(points, views, K, uv, front)
    return (uv, front) if view.ndim == 3 else (uv[0], front[0])


@intrinsic
def fma(typingctx, a, b, c):
    """a b + c rounded once (LLVM's fma): OpenBLAS's kernels multiply and add so."""
    def codegen(context, builder, signature, args):
        double = ir.DoubleType()
        return builder.call(builder.module.declare_intrinsic("llvm.fma", [double],
                                                             ir.FunctionType(double, [double] * 3)), args)

    return types.float64(types.float64, types.float64, types.float64), codegen


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA unasked
def to_camera(p0, p1, p2, view):
    """The world point (p0, p1, p2) in the camera frame of ``view`` (T_cam_world), as numpy's ``points @ R.T + t``
    computes it: the product by the rotation as OpenBLAS's kernels do, fused multiply-adds from zero, term by term,
    then the translation added."""
    return (fma(p2, view[0, 2], fma(p1, view[0, 1], fma(p0, view[0, 0], 0.0))) + view[0, 3],
            fma(p2, view[1, 2], fma(p1, view[1, 1], fma(p0, view[1, 0], 0.0))) + view[1, 3],
            fma(p2, view[2, 2], fma(p1, view[2, 1], fma(p0, view[2, 0], 0.0))) + view[2, 3])


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA unasked
def project_point(p0, p1, p2, view, K):
    """(u, v, in front of the camera) of the world point (p0, p1, p2) at ``view`` (T_cam_world): one point of
    :func:`pixels`."""
    x, y, z = to_camera(p0, p1, p2, view)
    front = z > NEAR_MM
    z = z if front else 1.0
    return K[0, 0] * x / z + K[0, 2], K[1, 1] * y / z + K[1, 2], front


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _pixels_at(points, views, K, uv, front):
    """uv (p, k, m, 2), front (p, k, m) of :func:`pixels`."""
    for p in range(len(views)):
        for k in range(points.shape[0]):
            for m in range(points.shape[1]):
                uv[p, k, m, 0], uv[p, k, m, 1], front[p, k, m] = project_point(points[k, m, 0], points[k, m, 1],
                                                                               points[k, m, 2], views[p], K)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def on_pixel(u, v, front, pixels, u0, v0):
    """Whether the image point (u, v px), in front of the camera (``front``), rounds (half to even, as np.round) onto
    a True pixel of ``pixels`` (rows, columns), a mask's box from column u0 and row v0."""
    if not front:
        return False
    u, v = np.rint(u) - u0, np.rint(v) - v0
    return 0 <= u < pixels.shape[1] and 0 <= v < pixels.shape[0] and pixels[int(v), int(u)]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _on_mask(uv, front, pixels, u0, v0, on):
    """on (k, l) of :meth:`Mask.on`."""
    for k in range(uv.shape[0]):
        for l in range(uv.shape[1]):
            on[k, l] = on_pixel(uv[k, l, 0], uv[k, l, 1], front[k, l], pixels, u0, v0)


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA
def overlap(a, b):
    """Whether the convex polygons a (p, 2) and b (q, 2) (a segment when 2 points) come within CLEARANCE_PX of each
    other: no separating axis among their edges' normals (the separating axis theorem)."""
    return not (_separates(a, b) or _separates(b, a))


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA
def _separates(a, b):
    """Whether along the normal of an edge of polygon a (p, 2) polygon b (q, 2) lies more than CLEARANCE_PX beyond
    it. The normal is the edge turned by 90 deg over its length (at least 1e-9), each projection the sum of two
    products, in this order."""
    for e in range(len(a)):
        nx, ny = -(a[(e + 1) % len(a), 1] - a[e, 1]), a[(e + 1) % len(a), 0] - a[e, 0]
        length = max(np.sqrt(nx * nx + ny * ny), 1e-9)
        nx, ny = nx / length, ny / length
        own_low, own_high, other_low, other_high = np.inf, -np.inf, np.inf, -np.inf
        for q in range(len(a)):
            d = nx * a[q, 0] + ny * a[q, 1]
            own_low, own_high = min(own_low, d), max(own_high, d)
        for q in range(len(b)):
            d = nx * b[q, 0] + ny * b[q, 1]
            other_low, other_high = min(other_low, d), max(other_high, d)
        if max(other_low - own_high, own_low - other_high) > CLEARANCE_PX:
            return True
    return False
