"""The correspondence pipeline before it was compiled (poseintegrity.tracking.markers.correspondence as of 91f5bef), kept
only to prove that the compiled matchers return the same assignments, element for element (test_matching_equivalence.py,
benchmarks/bench_matching.py).  Same names and arguments as the package's functions; not used by the package.
kabsch_residuals is the numpy one of poseintegrity.tracking.markers.kabsch as of that commit (R and t from the compiled
Kabsch kernel, the residuals by numpy: matmul through BLAS, then norm).
"""

from __future__ import annotations

from functools import lru_cache
from itertools import combinations, permutations

import numpy as np
from scipy.optimize import linear_sum_assignment

from poseintegrity.tracking.markers.geometry import pairwise_distances
from poseintegrity.tracking.markers.kabsch import kabsch_unchecked
from poseintegrity.params.track import MatchingParams


def kabsch_residuals(points_world: np.ndarray, points_body: np.ndarray) -> np.ndarray:
    """Distances ``|R y^i + t - r^i|`` after the Kabsch fit, (..., n) metres (the error of Alg. 3); unchecked
    (correspondence calls it on its own candidate sets, see :func:`kabsch_unchecked`)."""
    R, t = kabsch_unchecked(points_world, points_body)
    fitted = points_body @ np.swapaxes(R, -1, -2) + t[..., None, :]
    return np.linalg.norm(fitted - points_world, axis=-1)


def _finite_rows(points: np.ndarray) -> np.ndarray:
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    return np.flatnonzero(np.all(np.isfinite(points), axis=1))


@lru_cache(maxsize=32)
def _pairs(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The index pairs (k, l), k < l, of n points, row-major (np.triu_indices(n, 1)), read-only."""
    pairs = np.triu_indices(n, 1)
    for index in pairs:
        index.flags.writeable = False
    return pairs


def is_consistent(points: np.ndarray, geometry: np.ndarray, assignment: np.ndarray, tolerance_m: float) -> bool:
    """Do the matched points fit the rigid geometry?  Kabsch residuals (3+ matches) or the pair distance
    (2 matches) within tolerance_m; a single match is accepted.  No match is not consistent."""
    g = np.flatnonzero(assignment >= 0)
    if g.size == 0:
        return False
    if g.size == 1:
        return True
    p = points[assignment[g]]
    if g.size == 2:
        return abs(np.linalg.norm(p[0] - p[1]) - np.linalg.norm(geometry[g[0]] - geometry[g[1]])) <= tolerance_m
    return bool(kabsch_residuals(p, geometry[g]).max() <= tolerance_m)


def match_voting(points, geometry, *, tolerance_m):
    """Alg. 2 with a (geometry pairs, measured pairs) difference matrix and np.add.at votes."""
    geometry = np.asarray(geometry, dtype=float)
    m = geometry.shape[0]
    rows = _finite_rows(points)
    n_all = np.asarray(points).reshape(-1, 3).shape[0]
    assignment, outlier = np.full(m, -1), np.ones(n_all, dtype=bool)
    X = np.asarray(points, dtype=float).reshape(-1, 3)[rows]
    n = len(X)
    if n < 2:
        return assignment, outlier
    D = pairwise_distances(X)  # D[k, l] = |r^k - r^l|
    Y = pairwise_distances(geometry)  # offline in the paper
    k_idx, l_idx = _pairs(n)
    g_i, g_j = _pairs(m)
    diff = np.abs(D[k_idx, l_idx][None, :] - Y[g_i, g_j][:, None])  # (geometry pairs, measured pairs)
    best = np.argmin(diff, axis=1)  # per geometry pair (i, j) the closest measured pair (k, l)
    votes = diff[np.arange(len(g_i)), best] <= tolerance_m
    k, l = k_idx[best[votes]], l_idx[best[votes]]
    V = np.zeros((m, n), dtype=int)
    for a, b in ((g_i[votes], k), (g_i[votes], l), (g_j[votes], k), (g_j[votes], l)):  # V[i, k], V[i, l], V[j, k], V[j, l] += 1
        np.add.at(V, (a, b), 1)
    outlier[rows] = V.sum(axis=0) == 0
    i = np.argmax(V, axis=0)  # per point k its best geometry marker
    top = V[i, np.arange(n)]
    unique_in_column = (V == top).sum(axis=0) == 1
    unique_in_row = ((V[i] == top[:, None]).sum(axis=1) == 1) & (np.argmax(V[i], axis=1) == np.arange(n))  # no other point claims i
    confident = (top >= m - 1) & unique_in_column & unique_in_row
    assignment[i[confident]] = rows[confident]
    return assignment, outlier


def match_brute_force(points, geometry, *, fixed=None, candidates=None, tolerance_m, min_markers):
    """Alg. 3 as numpy batches: every map of one size and marker subset fitted as one batch of Kabsch problems."""
    geometry = np.asarray(geometry, dtype=float)
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    m = geometry.shape[0]
    fixed = np.full(m, -1) if fixed is None else np.asarray(fixed)
    usable = np.zeros(len(points), dtype=bool)
    usable[_finite_rows(points)] = True
    if candidates is not None:
        usable &= np.asarray(candidates, dtype=bool)
    usable[fixed[fixed >= 0]] = False
    pool = np.flatnonzero(usable)
    known = np.flatnonzero(fixed >= 0)
    open_markers = np.flatnonzero(fixed < 0)
    for n_open in range(min(len(open_markers), len(pool)), -1, -1):
        if len(known) + n_open < min_markers:
            break
        best, best_e = None, np.inf
        for chosen in combinations(open_markers, n_open):
            g = np.concatenate([known, chosen]).astype(int)
            perms = list(permutations(pool, n_open))
            maps = np.array(perms, dtype=int).reshape(len(perms), n_open)
            idx = np.concatenate([np.broadcast_to(fixed[known], (len(maps), len(known))), maps], axis=1)
            res = kabsch_residuals(points[idx], geometry[g])  # (b, k)
            ok = res.max(axis=1) <= tolerance_m
            if not ok.any():
                continue
            e = np.where(ok, (res**2).sum(axis=1), np.inf)
            b = int(np.argmin(e))
            if e[b] < best_e:
                best_e = e[b]
                best = np.full(m, -1)
                best[g] = idx[b]
        if best is not None:
            return best
    return np.full(m, -1)


def match_gated(points: np.ndarray, predicted: np.ndarray, *, gate_m: float) -> np.ndarray:
    """Optimal assignment (scipy.optimize.linear_sum_assignment) to predicted marker positions.

    predicted : (m, 3) metres, e.g. the filter's prior markers.  Minimises the summed distance; pairs
    beyond gate_m are not matched.
    """
    predicted = np.asarray(predicted, dtype=float)
    assignment = np.full(predicted.shape[0], -1)
    rows = _finite_rows(points)
    if rows.size == 0:
        return assignment
    X = np.asarray(points, dtype=float).reshape(-1, 3)[rows]
    cost = np.linalg.norm(predicted[:, None, :] - X[None, :, :], axis=-1)
    big = 1e6
    gi, pj = linear_sum_assignment(np.where(cost <= gate_m, cost, big))
    keep = cost[gi, pj] <= gate_m
    assignment[gi[keep]] = rows[pj[keep]]
    return assignment


def match_markers_unchecked(points: np.ndarray, geometry: np.ndarray, previous: np.ndarray | None,
                            matching: MatchingParams) -> np.ndarray:
    """:func:`match_markers` on checked arguments (float (n, 3) points, (m, 3) geometry): the per-frame path."""
    tolerance_m, min_markers = matching.tolerance_m, matching.min_markers
    geometry = np.asarray(geometry, dtype=float)
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    gated = np.full(geometry.shape[0], -1)
    if previous is not None:
        gated = match_gated(points, previous, gate_m=matching.gate_m)
        if not is_consistent(points, geometry, gated, tolerance_m):
            gated[:] = -1
        used = np.zeros(len(points), dtype=bool)
        used[gated[gated >= 0]] = True
        if used.sum() >= min_markers:
            # the marker body is nearly symmetric under some permutations (the published geometry: (4, 3, 2, 1) fits
            # within 3.7 mm), so keep the gated match only if it is also the best rigid fit of its points
            best = match_brute_force(points, geometry, candidates=used, tolerance_m=tolerance_m, min_markers=int(used.sum()))
            if np.array_equal(best, gated):
                return gated
    voted, outlier = match_voting(points, geometry, tolerance_m=tolerance_m)
    if (voted >= 0).sum() >= 2 and not is_consistent(points, geometry, voted, tolerance_m):
        voted[:] = -1
    if (voted >= 0).all():
        return voted
    found = match_brute_force(points, geometry, fixed=voted, candidates=~outlier, tolerance_m=tolerance_m, min_markers=min_markers)
    if (found >= 0).sum() < min(geometry.shape[0], _finite_rows(points).size):  # voting may have misled it
        unguided = match_brute_force(points, geometry, tolerance_m=tolerance_m, min_markers=min_markers)
        if (unguided >= 0).sum() > (found >= 0).sum():
            found = unguided
    return found if (found >= 0).any() else gated
