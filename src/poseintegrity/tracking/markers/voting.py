"""Euclidean-distance voting point correspondence with outlier rejection (Black and Salcudean II-D, Algorithm 2):
only the confident matches are assigned; the rest is left to brute force (Alg. 3)."""

from __future__ import annotations

import numba
import numpy as np

from poseintegrity.tracking.markers.consistency import check_rows_of_3, finite_mask
from poseintegrity.tracking.markers.summation import einsum_norm, first_argmin


def match_voting(points: np.ndarray, geometry: np.ndarray, *, tolerance_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Alg. 2: Euclidean-distance voting.  Returns (assignment (m,) int, outlier (n,) bool).

    points : (n, 3) metres, rows with NaN never matched; geometry : (m, 3) metres.
    For every geometry pair (i, j), the measured pair (k, l) whose distance is closest to |y^i - y^j| gets
    one vote for each of i, j on each of k, l (V[i, k], V[i, l], V[j, k], V[j, l] += 1).  Beyond the paper,
    a pair only votes if its distance differs by at most tolerance_m (metres; the paper compares squared
    distances without a gate).  A point with no vote is an outlier.  Point k is assigned to geometry
    marker i only if V[i, k] is the unique maximum of its column, reaches m - 1 (every pair of i agreed),
    and no other point claims i; the rest is left for brute force.
    """
    points = check_rows_of_3("points", np.asarray(points, dtype=float).reshape(-1, 3))
    return voting_kernel(points, finite_mask(points), check_rows_of_3("geometry", geometry), float(tolerance_m))


@numba.njit(cache=True)
def voting_kernel(points, finite, geometry, tolerance_m):  # pragma: no cover - compiled
    """Alg. 2 (:func:`match_voting`) on float (n, 3) points with their finite rows marked, (m, 3) geometry."""
    m = geometry.shape[0]
    rows = np.flatnonzero(finite)
    n = rows.size
    assignment, outlier = np.full(m, -1, dtype=np.int64), np.ones(points.shape[0], dtype=np.bool_)
    if n < 2:
        return assignment, outlier
    D = np.empty(n * (n - 1) // 2)  # |r^k - r^l| of the measured pairs k < l, row-major
    pair_k, pair_l = np.empty(D.size, dtype=np.int64), np.empty(D.size, dtype=np.int64)
    q = 0
    for k in range(n):
        for l in range(k + 1, n):
            D[q], pair_k[q], pair_l[q] = einsum_norm(points[rows[k]], points[rows[l]]), k, l
            q += 1
    V = np.zeros((m, n), dtype=np.int64)
    diff = np.empty(D.size)
    for i in range(m):
        for j in range(i + 1, m):  # geometry pair (i, j): its closest measured pair votes if within tolerance_m
            Y = einsum_norm(geometry[i], geometry[j])  # offline in the paper
            for q in range(D.size):
                diff[q] = abs(D[q] - Y)
            best = first_argmin(diff)
            if diff[best] <= tolerance_m:  # V[i, k], V[i, l], V[j, k], V[j, l] += 1
                V[i, pair_k[best]] += 1
                V[i, pair_l[best]] += 1
                V[j, pair_k[best]] += 1
                V[j, pair_l[best]] += 1
    for k in range(n):
        outlier[rows[k]] = V[:, k].sum() == 0
        i = np.argmax(V[:, k])  # the point's best geometry marker
        top = V[i, k]
        unique_in_column = (V[:, k] == top).sum() == 1
        unique_in_row = (V[i] == top).sum() == 1 and np.argmax(V[i]) == k  # no other point claims i
        if top >= m - 1 and unique_in_column and unique_in_row:
            assignment[i] = rows[k]
    return assignment, outlier
