"""Point correspondence between measured marker points and the known geometry (section II-D).

Every matcher returns ``assignment`` : (m,) int, for each geometry marker the index of its measured point,
or -1 if it was not found.  Measured points are (n, 3) metres; rows with NaN are never matched.

- :func:`match_frobenius`  Alg. 1 and appendix B: closest previous points by the Frobenius norm,
  including a missing marker (a column of Y removed) and, beyond the paper, extra points.
- :func:`match_voting`     Alg. 2: Euclidean-distance voting with outlier rejection; only confident matches.
- :func:`match_brute_force` Alg. 3: permutations with Kabsch, generalised to phantoms and missing markers.
- :func:`match_gated`      beyond the paper: optimal assignment (scipy linear_sum_assignment) of the points
  to the filter's predicted marker positions, with a distance gate.
- :func:`match_markers`    the pipeline: gated assignment if a prediction is given, else / then voting,
  brute force for what voting leaves, brute force on everything as the last resort.
"""

from __future__ import annotations

from functools import lru_cache
from itertools import combinations, permutations

import numpy as np
from scipy.optimize import linear_sum_assignment

from poseintegrity.defaults import published
from poseintegrity.errors import ArgumentError, check_array
from poseintegrity.tracking.markers.geometry import pairwise_distances
from poseintegrity.tracking.markers.kabsch import kabsch_residuals
from poseintegrity.tracking.params import MatchingParams

MAX_ABS_M = 1e6  # a measured or body point farther than 1000 km is not a marker


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


def match_frobenius(points: np.ndarray, previous: np.ndarray, *, max_distance_m: float = np.inf) -> np.ndarray:
    """Alg. 1: the permutation P_y maximising tr(X^T Y P_y), i.e. minimising ||X - Y P_y||_F (eqs. 1-2, 13-15).

    points : (n, 3) current points X; previous : (m, 3) previous marker positions Y (geometry order).
    When n < m a marker is missing: the optimisation runs with every choice of columns of Y removed
    (appendix B); when n > m the extra points are left out the same way.  Because the candidates then
    differ in ||Y P_y||_F, they are compared by the full Frobenius distance, not by the trace alone.
    Pairs farther apart than max_distance_m are rejected (closest-last-point outliers).
    """
    previous = np.asarray(previous, dtype=float)
    m = previous.shape[0]
    assignment = np.full(m, -1)
    rows = _finite_rows(points)
    X = np.asarray(points, dtype=float).reshape(-1, 3)[rows]
    k = min(len(X), m)
    if k == 0:
        return assignment
    Z = X @ previous.T  # Z = X^T Y with points as columns
    x_sq, y_sq = np.einsum("ij,ij->i", X, X), np.einsum("ij,ij->i", previous, previous)
    best, best_cost = None, np.inf
    for x_idx in combinations(range(len(X)), k):
        for y_idx in permutations(range(m), k):
            e = Z[list(x_idx), list(y_idx)].sum()  # e = sum_j Z[j, i_j]
            cost = x_sq[list(x_idx)].sum() + y_sq[list(y_idx)].sum() - 2.0 * e  # ||X - Y P_y||_F^2
            if cost < best_cost:
                best, best_cost = (x_idx, y_idx), cost
    for j, i in zip(*best):
        if np.linalg.norm(X[j] - previous[i]) <= max_distance_m:
            assignment[i] = rows[j]
    return assignment


def match_voting(points: np.ndarray, geometry: np.ndarray, *, tolerance_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Alg. 2: Euclidean-distance voting.  Returns (assignment (m,) int, outlier (n,) bool).

    For every geometry pair (i, j), the measured pair (k, l) whose distance is closest to |y^i - y^j| gets
    one vote for each of i, j on each of k, l (V[i, k], V[i, l], V[j, k], V[j, l] += 1).  Beyond the paper,
    a pair only votes if its distance differs by at most tolerance_m (metres; the paper compares squared
    distances without a gate).  A point with no vote is an outlier.  Point k is assigned to geometry
    marker i only if V[i, k] is the unique maximum of its column, reaches m - 1 (every pair of i agreed),
    and no other point claims i; the rest is left for brute force.
    """
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


def match_brute_force(
    points: np.ndarray,
    geometry: np.ndarray,
    *,
    fixed: np.ndarray | None = None,
    candidates: np.ndarray | None = None,
    tolerance_m: float,
    min_markers: int,
) -> np.ndarray:
    """Alg. 3 generalised: try every injective map of geometry markers to points, Kabsch each, keep the best.

    fixed : (m,) int, matches already known (kept; -1 = open).  candidates : (n,) bool, points that may
    be used for the open markers (default: every finite point not in fixed).
    The map with the most matched markers whose every Kabsch residual is within tolerance_m wins, ties
    broken by the error e = sum |r_bar + R ell^i - r^i|^2 of Alg. 3.  All -1 if fewer than min_markers fit.
    All maps of one size and marker subset are evaluated as one batch of Kabsch problems.
    """
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


def match_markers(
    points: np.ndarray,
    geometry: np.ndarray,
    previous: np.ndarray | None = None,
    matching: MatchingParams | None = None,
) -> np.ndarray:
    """For each geometry marker (m, 3) the index of its measured point among points (n, 3), or -1.

    previous : (m, 3) predicted marker positions (metres, world) or None; matching : ``track.matching`` (None: the
    published defaults, params.yaml).  With a prediction the gated
    optimal assignment is tried first and kept if it rigidly matches at least min_markers markers and no
    other permutation of the same points fits the geometry better (Alg. 3 on those points).
    Otherwise voting (Alg. 2) fixes the confident matches and brute force (Alg. 3) fills the rest from the
    non-outliers; if that leaves markers unmatched although points remain, brute force also runs on all
    points and wins if it matches more.  If all of that finds nothing, a consistent
    gated match of one or two markers is returned (the filter can use a partial update); else all -1.
    Refused (:class:`~poseintegrity.errors.ArgumentError`): points not (n, 3) numbers (NaN rows are allowed:
    dropped detections), geometry not >= 3 finite (m, 3) markers, previous not (m, 3).
    """
    points = np.zeros((0, 3)) if np.size(points) == 0 and points is not None and not isinstance(points, str) else points
    points = check_array("points", points, shape=(None, 3), finite=False)  # NaN rows are dropped detections
    if not np.all(np.isnan(points) | (np.abs(points) <= MAX_ABS_M)):
        raise ArgumentError(f"points: entries must be NaN (no detection) or at most {MAX_ABS_M:g} m in magnitude")
    geometry = check_array("geometry", geometry, shape=(None, 3), min_rows=3, max_abs=MAX_ABS_M)
    if previous is not None:
        previous = check_array("previous", previous, shape=geometry.shape, finite=False)
    matching = published("track.matching") if matching is None else matching
    return match_markers_unchecked(points, geometry, previous, matching)


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
