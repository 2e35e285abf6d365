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

from itertools import combinations, permutations

import numba
import numpy as np
from scipy.optimize import linear_sum_assignment

from poseintegrity.defaults import published
from poseintegrity.errors import ArgumentError, check_array
from poseintegrity.tracking.markers.kabsch import centre_into, fused_multiply_add, kabsch_into, residuals_into
from poseintegrity.params.track import MatchingParams

MAX_ABS_M = 1e6  # a measured or body point farther than 1000 km is not a marker


BIG = 1e6  # the cost of a pair beyond the gate in match_gated's assignment


def _finite_rows(points: np.ndarray) -> np.ndarray:
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    return np.flatnonzero(np.all(np.isfinite(points), axis=1))


def _check_rows_of_3(name: str, array: np.ndarray) -> np.ndarray:
    """array as float64 (k, 3), C-contiguous, for the compiled matchers; ArgumentError if it is not (k, 3)."""
    array = np.ascontiguousarray(array, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != 3:
        raise ArgumentError(f"{name}: expected shape (k, 3), got {array.shape}")
    return array


def _check_assignment(name: str, assignment: np.ndarray, geometry: np.ndarray, points: np.ndarray) -> np.ndarray:
    """assignment as int64 (m,) for the compiled matchers; ArgumentError if it is not one entry per geometry marker
    or names a point that does not exist."""
    assignment = np.asarray(assignment).astype(np.int64)
    if assignment.shape != (geometry.shape[0],) or np.any(assignment >= len(points)):
        raise ArgumentError(f"{name}: expected ({geometry.shape[0]},) indices below {len(points)} (or -1), got {assignment!r}")
    return assignment


def is_consistent(points: np.ndarray, geometry: np.ndarray, assignment: np.ndarray, tolerance_m: float) -> bool:
    """Do the matched points fit the rigid geometry?  Kabsch residuals (3+ matches) or the pair distance
    (2 matches) within tolerance_m; a single match is accepted.  No match is not consistent."""
    points, geometry = _check_rows_of_3("points", points), _check_rows_of_3("geometry", geometry)
    assignment = _check_assignment("assignment", assignment, geometry, points)
    return _is_consistent(points, geometry, assignment, float(tolerance_m))


@numba.njit(cache=True)
def _is_consistent(points, geometry, assignment, tolerance_m):  # pragma: no cover - compiled
    """:func:`is_consistent` on float (n, 3) points, (m, 3) geometry and an int (m,) assignment."""
    g = np.flatnonzero(assignment >= 0)
    if g.size == 0:
        return False
    if g.size == 1:
        return True
    if g.size == 2:
        p, q = points[assignment[g[0]]], points[assignment[g[1]]]
        return abs(_dot_norm(p, q) - _dot_norm(geometry[g[0]], geometry[g[1]])) <= tolerance_m
    world, body = np.empty((g.size, 3)), np.empty((g.size, 3))
    for j in range(g.size):
        world[j], body[j] = points[assignment[g[j]]], geometry[g[j]]
    ell, y_bar, scratch, R, t, res = np.empty((g.size, 3)), np.empty(3), np.empty((4, 4, 4)), np.empty((3, 3)), np.empty(3), np.empty(g.size)
    centre_into(body, ell, y_bar)
    kabsch_into(world, ell, y_bar, scratch, R, t)
    residuals_into(world, body, R, t, res)
    return _all_within(res, tolerance_m)


@numba.njit(cache=True)
def _all_within(res, tolerance_m):  # pragma: no cover - compiled
    """numpy's ``res.max() <= tolerance_m``: every residual within, and False if one is NaN."""
    for r in res:
        if not r <= tolerance_m:
            return False
    return True


@numba.njit(cache=True)
def _dot_norm(p, q):  # pragma: no cover - compiled
    """|p - q| for (3,) points as np.linalg.norm of a vector rounds it (BLAS ddot: a fused multiply-add per term)."""
    d0, d1, d2 = p[0] - q[0], p[1] - q[1], p[2] - q[2]
    return np.sqrt(fused_multiply_add(d2, d2, fused_multiply_add(d1, d1, d0 * d0)))


@numba.njit(cache=True)
def _reduce_norm(p, q):  # pragma: no cover - compiled
    """|p - q| for (3,) points as np.linalg.norm(..., axis=-1) rounds it (the squares summed in order)."""
    d0, d1, d2 = p[0] - q[0], p[1] - q[1], p[2] - q[2]
    return np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@numba.njit(cache=True)
def _einsum_norm(p, q):  # pragma: no cover - compiled
    """|p - q| for (3,) points as geometry.pairwise_distances rounds it (einsum's two-lane sum: x^2 + z^2, then + y^2)."""
    d0, d1, d2 = p[0] - q[0], p[1] - q[1], p[2] - q[2]
    return np.sqrt((d0 * d0 + d2 * d2) + d1 * d1)


@numba.njit(cache=True)
def _numpy_sum(a):  # pragma: no cover - compiled
    """sum(a) rounded as numpy's add.reduce (pairwise_sum): a block of at most 128 terms by _block_sum, a longer range
    as the sum of its halves (the first n // 2 rounded down to a multiple of 8), here without recursion (numba's
    cache cannot hold recursive functions): a stack of the ranges being split and their first halves' sums."""
    start, size = np.zeros(64, dtype=np.int64), np.zeros(64, dtype=np.int64)
    first, has_first = np.empty(64), np.zeros(64, dtype=np.bool_)  # the sum of a range's first half once known
    size[0] = a.size
    depth = 0
    while size[depth] > 128:  # split down to the first block
        half = size[depth] // 2 - size[depth] // 2 % 8
        start[depth + 1], size[depth + 1] = start[depth], half
        depth += 1
    while True:
        total = _block_sum(a, start[depth], size[depth])
        while depth > 0 and has_first[depth - 1]:  # the second half of its parent: the parent is done
            depth -= 1
            total = first[depth] + total
            has_first[depth] = False
        if depth == 0:
            return total
        first[depth - 1], has_first[depth - 1] = total, True  # a first half: go on with its sibling, split down to its first block
        parent = depth - 1
        half = size[parent] // 2 - size[parent] // 2 % 8
        start[depth], size[depth] = start[parent] + half, size[parent] - half
        while size[depth] > 128:
            half = size[depth] // 2 - size[depth] // 2 % 8
            start[depth + 1], size[depth + 1] = start[depth], half
            depth += 1


@numba.njit(cache=True)
def _block_sum(a, start, n):  # pragma: no cover - compiled
    """sum(a[start:start + n]), n <= 128, as numpy's pairwise_sum adds a block: in order below 8 terms, else 8
    running sums (term i into sum i % 8), combined pairwise, then the rest in order."""
    if n < 8:
        total = 0.0
        for i in range(n):
            total += a[start + i]
        return total
    r = a[start:start + 8].copy()
    i = 8
    while i < n - n % 8:
        for j in range(8):
            r[j] += a[start + i + j]
        i += 8
    total = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    for j in range(i, n):
        total += a[start + j]
    return total


@numba.njit(cache=True)
def _first_argmin(values):  # pragma: no cover - compiled
    """np.argmin: the first minimum, or the first NaN if there is one."""
    best = 0
    for q in range(values.size):
        if np.isnan(values[q]):
            return q
        if values[q] < values[best]:
            best = q
    return best


@numba.njit(cache=True)
def _finite_mask(points):  # pragma: no cover - compiled
    """(n,) bool: rows of points (n, 3) whose coordinates are all finite."""
    finite = np.empty(points.shape[0], dtype=np.bool_)
    for k in range(points.shape[0]):
        finite[k] = np.isfinite(points[k, 0]) and np.isfinite(points[k, 1]) and np.isfinite(points[k, 2])
    return finite


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
    points = _check_rows_of_3("points", np.asarray(points, dtype=float).reshape(-1, 3))
    return _voting(points, _finite_mask(points), _check_rows_of_3("geometry", geometry), float(tolerance_m))


@numba.njit(cache=True)
def _voting(points, finite, geometry, tolerance_m):  # pragma: no cover - compiled
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
            D[q], pair_k[q], pair_l[q] = _einsum_norm(points[rows[k]], points[rows[l]]), k, l
            q += 1
    V = np.zeros((m, n), dtype=np.int64)
    diff = np.empty(D.size)
    for i in range(m):
        for j in range(i + 1, m):  # geometry pair (i, j): its closest measured pair votes if within tolerance_m
            Y = _einsum_norm(geometry[i], geometry[j])  # offline in the paper
            for q in range(D.size):
                diff[q] = abs(D[q] - Y)
            best = _first_argmin(diff)
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
    The maps are tried in order (marker subsets as itertools.combinations, points as itertools.permutations);
    among equal errors the first wins.
    """
    geometry = _check_rows_of_3("geometry", geometry)
    points = _check_rows_of_3("points", np.asarray(points, dtype=float).reshape(-1, 3))
    fixed = np.full(geometry.shape[0], -1) if fixed is None else _check_assignment("fixed", fixed, geometry, points)
    usable = _finite_mask(points)
    if candidates is not None:
        usable &= np.asarray(candidates, dtype=bool)
    usable[fixed[fixed >= 0]] = False
    return _brute_force(points, geometry, fixed.astype(np.int64), np.flatnonzero(usable), float(tolerance_m), int(min_markers))


@numba.njit(cache=True)
def _brute_force(points, geometry, fixed, pool, tolerance_m, min_markers):  # pragma: no cover - compiled
    """Alg. 3 (:func:`match_brute_force`): the markers fixed >= 0 keep their points, the open ones take points of
    pool (int, ascending).  Per number of open markers matched, from the most down to min_markers in all, every
    marker subset (combinations) and every map of it to the pool (permutations) is fitted with Kabsch (Alg. 4) in
    the order [known markers, chosen markers]; a map counts if every residual is within tolerance_m, and the first
    one with the least error e wins.

    Maps that cannot count are skipped without the fit, with every map sharing their first points: if two matched
    points are farther apart or closer than their markers by more than 2 tolerance_m (+ ``slack``), no pose puts both
    within tolerance_m (triangle inequality: |R (y^a - y^b) - (r^a - r^b)| <= res_a + res_b, and R keeps lengths).
    The slack, 1e-9 of the largest coordinate (+ 1e-9 m), is far above the rounding of the computed residuals and of
    R's length error (< 1e-12 of it), so a skipped map would have failed the test as computed too."""
    m = geometry.shape[0]
    known, open_markers = np.flatnonzero(fixed >= 0), np.flatnonzero(fixed < 0)
    n_known, n_pool = known.size, pool.size
    most = n_known + min(open_markers.size, n_pool)
    world, body, ell, res, squares = np.empty((most, 3)), np.empty((most, 3)), np.empty((most, 3)), np.empty(most), np.empty(most)
    y_bar, scratch, R, t = np.empty(3), np.empty((4, 4, 4)), np.empty((3, 3)), np.empty(3)
    for j in range(n_known):
        world[j], body[j] = points[fixed[known[j]]], geometry[known[j]]
    scale = 0.0
    for j in range(n_known):
        scale = max(scale, np.abs(world[j]).max())
    for j in range(n_pool):
        scale = max(scale, np.abs(points[pool[j]]).max())
    for i in range(m):
        scale = max(scale, np.abs(geometry[i]).max())
    slack = 2.0 * tolerance_m + 1e-9 * (1.0 + scale)  # a pair whose distance misses its markers' by more cannot count
    for a in range(n_known):
        for b in range(a):
            if abs(_reduce_norm(world[a], world[b]) - _reduce_norm(body[a], body[b])) > slack:
                return np.full(m, -1, dtype=np.int64)  # the known markers are in every map
    for n_open in range(min(open_markers.size, n_pool), -1, -1):
        k = n_known + n_open
        if k < min_markers:
            break
        best, best_e = np.full(m, -1, dtype=np.int64), np.inf
        perm, taken = np.empty(n_open, dtype=np.int64), np.empty(n_pool, dtype=np.bool_)
        chosen = np.arange(n_open)  # positions in open_markers, as itertools.combinations
        while True:
            for j in range(n_open):
                body[n_known + j] = geometry[open_markers[chosen[j]]]
            centre_into(body[:k], ell[:k], y_bar)
            more = _first_permutation(perm, taken)  # perm: positions in pool, as itertools.permutations
            while more:
                misfit = _first_misfit(world, body, points, pool, perm, n_known, slack)
                if misfit < n_open:  # every map starting with perm[:misfit + 1] has the misfitting pair
                    more = _next_permutation(perm, taken, misfit)
                    continue
                kabsch_into(world[:k], ell[:k], y_bar, scratch, R, t)
                residuals_into(world[:k], body[:k], R, t, res[:k])
                if _all_within(res[:k], tolerance_m):
                    for j in range(k):
                        squares[j] = res[j] * res[j]
                    e = _numpy_sum(squares[:k])  # Alg. 3's error, summed as numpy's (res**2).sum(axis=1)
                    if e < best_e:
                        best_e = e
                        best[:] = -1
                        for j in range(n_known):
                            best[known[j]] = fixed[known[j]]
                        for j in range(n_open):
                            best[open_markers[chosen[j]]] = pool[perm[j]]
                more = _next_permutation(perm, taken, n_open - 1)
            if not _next_combination(chosen, open_markers.size):
                break
        if best_e < np.inf:
            return best
    return np.full(m, -1, dtype=np.int64)


@numba.njit(cache=True)
def _first_misfit(world, body, points, pool, perm, n_known, slack):  # pragma: no cover - compiled
    """Fill world[n_known:] with the points of the map perm and return the first position j of perm whose point is
    misplaced against an earlier one (the distance of the pair misses that of its markers by more than slack), or
    perm.size if none is; world[:n_known] and body hold the known points and the markers in map order."""
    for j in range(perm.size):
        a = n_known + j
        world[a] = points[pool[perm[j]]]
        for b in range(a):
            if abs(_reduce_norm(world[a], world[b]) - _reduce_norm(body[a], body[b])) > slack:
                return j
    return perm.size


@numba.njit(cache=True)
def _next_combination(chosen, n):  # pragma: no cover - compiled
    """Advance chosen (r,) ascending positions of range(n) to the next r-combination in itertools order; False after
    the last."""
    r = chosen.size
    i = r - 1
    while i >= 0 and chosen[i] == n - r + i:
        i -= 1
    if i < 0:
        return False
    chosen[i] += 1
    for j in range(i + 1, r):
        chosen[j] = chosen[j - 1] + 1
    return True


@numba.njit(cache=True)
def _first_permutation(perm, taken):  # pragma: no cover - compiled
    """Set perm (r,) to the first r-permutation of range(n) (0, 1, ..., r - 1), taken (n,) marking its positions;
    False if there is none (r > n)."""
    if perm.size > taken.size:
        return False
    taken[:] = False
    for j in range(perm.size):
        perm[j] = j
        taken[j] = True
    return True


@numba.njit(cache=True)
def _next_permutation(perm, taken, level):  # pragma: no cover - compiled
    """Advance perm (r,) distinct positions of range(n), taken (n,) marking them, to the next r-permutation in
    itertools order (lexicographic) whose first level + 1 positions differ from perm's (level = r - 1: the very next);
    False after the last."""
    r, n = perm.size, taken.size
    for i in range(level + 1, r):
        taken[perm[i]] = False
    for i in range(level, -1, -1):
        taken[perm[i]] = False  # the positions after i are free already
        v = perm[i] + 1
        while v < n and taken[v]:
            v += 1
        if v < n:
            perm[i] = v
            taken[v] = True
            u = 0
            for j in range(i + 1, r):  # the rest ascending from the smallest free position
                while taken[u]:
                    u += 1
                perm[j] = u
                taken[u] = True
            return True
    return False


def match_gated(points: np.ndarray, predicted: np.ndarray, *, gate_m: float) -> np.ndarray:
    """Optimal assignment (scipy.optimize.linear_sum_assignment) to predicted marker positions.

    predicted : (m, 3) metres, e.g. the filter's prior markers.  Minimises the summed distance; pairs
    beyond gate_m are not matched.
    """
    points = _check_rows_of_3("points", np.asarray(points, dtype=float).reshape(-1, 3))
    return _gated(points, _finite_mask(points), _check_rows_of_3("predicted", predicted), float(gate_m))


def _gated(points: np.ndarray, finite: np.ndarray, predicted: np.ndarray, gate_m: float) -> np.ndarray:
    """:func:`match_gated` on float (n, 3) points with their finite rows marked and float (m, 3) predicted."""
    assignment, cost, decided = _gated_pairs(points, finite, predicted, gate_m)
    if not decided:
        assignment[:] = -1
        gi, pj = linear_sum_assignment(np.where(cost <= gate_m, cost, BIG))
        keep = cost[gi, pj] <= gate_m
        assignment[gi[keep]] = np.flatnonzero(finite)[pj[keep]]
    return assignment


@numba.njit(cache=True)
def _gated_pairs(points, finite, predicted, gate_m):  # pragma: no cover - compiled
    """The distances cost (m, n finite points) of predicted markers to points, and the assignment if it is decided
    without linear_sum_assignment: when every marker and every point lies in at most one pair within gate_m and
    those distances are below BIG / 2, every optimal assignment contains all those pairs (one left out costs BIG
    instead, i.e. more by over BIG / 2, far beyond rounding), and the pairs beyond the gate are dropped after it.
    Returns (assignment (m,) int, cost, decided)."""
    m = predicted.shape[0]
    rows = np.flatnonzero(finite)
    assignment = np.full(m, -1, dtype=np.int64)
    cost = np.empty((m, rows.size))
    column_pairs = np.zeros(rows.size, dtype=np.int64)
    decided = True
    for i in range(m):
        row_pairs = 0
        for j in range(rows.size):
            cost[i, j] = _reduce_norm(predicted[i], points[rows[j]])
            if cost[i, j] <= gate_m:
                row_pairs += 1
                column_pairs[j] += 1
                assignment[i] = rows[j]
                decided &= cost[i, j] < BIG / 2
        decided &= row_pairs <= 1
    for j in range(rows.size):
        decided &= column_pairs[j] <= 1
    return assignment, cost, decided


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
    geometry = np.ascontiguousarray(geometry, dtype=np.float64)
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    finite = _finite_mask(points)
    if previous is None:
        gated = np.full(geometry.shape[0], -1, dtype=np.int64)
    else:
        gated = _gated(points, finite, np.ascontiguousarray(previous, dtype=np.float64), matching.gate_m)
    return _match(points, finite, geometry, gated, previous is not None, matching.tolerance_m, matching.min_markers)


@numba.njit(cache=True)
def _match(points, finite, geometry, gated, predicted, tolerance_m, min_markers):  # pragma: no cover - compiled
    """The pipeline of :func:`match_markers` after the gated assignment (of the prediction if predicted)."""
    m = geometry.shape[0]
    no_fixed = np.full(m, -1, dtype=np.int64)
    if predicted:
        if not _is_consistent(points, geometry, gated, tolerance_m):
            gated[:] = -1
        used = np.zeros(points.shape[0], dtype=np.bool_)
        for i in range(m):
            if gated[i] >= 0:
                used[gated[i]] = True
        if used.sum() >= min_markers:
            # the marker body is nearly symmetric under some permutations (the published geometry: (4, 3, 2, 1) fits
            # within 3.7 mm), so keep the gated match only if it is also the best rigid fit of its points
            best = _brute_force(points, geometry, no_fixed, np.flatnonzero(used & finite), tolerance_m, used.sum())
            if np.all(best == gated):
                return gated
    voted, outlier = _voting(points, finite, geometry, tolerance_m)  # Alg. 2
    if (voted >= 0).sum() >= 2 and not _is_consistent(points, geometry, voted, tolerance_m):
        voted[:] = -1
    if np.all(voted >= 0):
        return voted
    usable = finite & ~outlier  # Alg. 3 for the markers voting left open
    for i in range(m):
        if voted[i] >= 0:
            usable[voted[i]] = False
    found = _brute_force(points, geometry, voted, np.flatnonzero(usable), tolerance_m, min_markers)
    if (found >= 0).sum() < min(m, finite.sum()):  # voting may have misled it
        unguided = _brute_force(points, geometry, no_fixed, np.flatnonzero(finite), tolerance_m, min_markers)
        if (unguided >= 0).sum() > (found >= 0).sum():
            found = unguided
    return found if np.any(found >= 0) else gated
