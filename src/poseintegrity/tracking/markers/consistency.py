"""Whether a match fits the rigid marker geometry (:func:`is_consistent`), and the checks of points, geometry and
assignments that every matcher shares.

Points are (n, 3) metres, rows with NaN never matched; an assignment is (m,) int, for each geometry marker the index
of its measured point or -1.
"""

from __future__ import annotations

import numba
import numpy as np

from poseintegrity.errors import ArgumentError
from poseintegrity.tracking.markers.kabsch import centre_into, kabsch_into, residuals_into
from poseintegrity.tracking.markers.summation import dot_norm


def finite_rows(points: np.ndarray) -> np.ndarray:
    """(k,) int: the rows of points (n, 3) whose coordinates are all finite."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    return np.flatnonzero(np.all(np.isfinite(points), axis=1))


@numba.njit(cache=True)
def finite_mask(points):  # pragma: no cover - compiled
    """(n,) bool: rows of points (n, 3) whose coordinates are all finite."""
    finite = np.empty(points.shape[0], dtype=np.bool_)
    for k in range(points.shape[0]):
        finite[k] = np.isfinite(points[k, 0]) and np.isfinite(points[k, 1]) and np.isfinite(points[k, 2])
    return finite


def check_rows_of_3(name: str, array: np.ndarray) -> np.ndarray:
    """array as float64 (k, 3), C-contiguous, for the compiled matchers; ArgumentError if it is not (k, 3)."""
    array = np.ascontiguousarray(array, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != 3:
        raise ArgumentError(f"{name}: expected shape (k, 3), got {array.shape}")
    return array


def check_assignment(name: str, assignment: np.ndarray, geometry: np.ndarray, points: np.ndarray) -> np.ndarray:
    """assignment as int64 (m,) for the compiled matchers; ArgumentError if it is not one entry per geometry marker
    or names a point that does not exist."""
    assignment = np.asarray(assignment).astype(np.int64)
    if assignment.shape != (geometry.shape[0],) or np.any(assignment >= len(points)):
        raise ArgumentError(f"{name}: expected ({geometry.shape[0]},) indices below {len(points)} (or -1), got {assignment!r}")
    return assignment


def is_consistent(points: np.ndarray, geometry: np.ndarray, assignment: np.ndarray, tolerance_m: float) -> bool:
    """Do the matched points fit the rigid geometry?  Kabsch residuals (3+ matches) or the pair distance
    (2 matches) within tolerance_m; a single match is accepted.  No match is not consistent."""
    points, geometry = check_rows_of_3("points", points), check_rows_of_3("geometry", geometry)
    assignment = check_assignment("assignment", assignment, geometry, points)
    return is_consistent_kernel(points, geometry, assignment, float(tolerance_m))


@numba.njit(cache=True)
def is_consistent_kernel(points, geometry, assignment, tolerance_m):  # pragma: no cover - compiled
    """:func:`is_consistent` on float (n, 3) points, (m, 3) geometry and an int (m,) assignment."""
    g = np.flatnonzero(assignment >= 0)
    if g.size == 0:
        return False
    if g.size == 1:
        return True
    if g.size == 2:
        p, q = points[assignment[g[0]]], points[assignment[g[1]]]
        return abs(dot_norm(p, q) - dot_norm(geometry[g[0]], geometry[g[1]])) <= tolerance_m
    world, body = np.empty((g.size, 3)), np.empty((g.size, 3))
    for j in range(g.size):
        world[j], body[j] = points[assignment[g[j]]], geometry[g[j]]
    ell, y_bar, scratch, R, t, res = np.empty((g.size, 3)), np.empty(3), np.empty((4, 4, 4)), np.empty((3, 3)), np.empty(3), np.empty(g.size)
    centre_into(body, ell, y_bar)
    kabsch_into(world, ell, y_bar, scratch, R, t)  # Alg. 4
    residuals_into(world, body, R, t, res)
    return all_within(res, tolerance_m)


@numba.njit(cache=True)
def all_within(res, tolerance_m):  # pragma: no cover - compiled
    """numpy's ``res.max() <= tolerance_m``: every residual within, and False if one is NaN."""
    for r in res:
        if not r <= tolerance_m:
            return False
    return True
