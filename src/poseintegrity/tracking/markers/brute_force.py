"""Brute-force point correspondence (Black and Salcudean II-D, Algorithm 3), generalised to phantom points and
missing markers: every injective map of geometry markers to points is fitted with Kabsch (Alg. 4), the best kept.

The maps are enumerated by compiled combination and permutation kernels in itertools order, so that among equal
errors the same map wins as with itertools.
"""

from __future__ import annotations

import numba
import numpy as np

from poseintegrity.tracking.markers.consistency import all_within, check_assignment, check_rows_of_3, finite_mask
from poseintegrity.tracking.markers.kabsch import centre_into, kabsch_into, residuals_into
from poseintegrity.tracking.markers.summation import numpy_sum, reduce_norm


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
    Returns the assignment (m,) int: for each geometry marker the index of its point, or -1.

    points : (n, 3) metres, rows with NaN never matched; geometry : (m, 3) metres.
    fixed : (m,) int, matches already known (kept; -1 = open).  candidates : (n,) bool, points that may
    be used for the open markers (default: every finite point not in fixed).
    The map with the most matched markers whose every Kabsch residual is within tolerance_m wins, ties
    broken by the error e = sum |r_bar + R ell^i - r^i|^2 of Alg. 3.  All -1 if fewer than min_markers fit.
    The maps are tried in order (marker subsets as itertools.combinations, points as itertools.permutations);
    among equal errors the first wins.
    """
    geometry = check_rows_of_3("geometry", geometry)
    points = check_rows_of_3("points", np.asarray(points, dtype=float).reshape(-1, 3))
    fixed = np.full(geometry.shape[0], -1) if fixed is None else check_assignment("fixed", fixed, geometry, points)
    usable = finite_mask(points)
    if candidates is not None:
        usable &= np.asarray(candidates, dtype=bool)
    usable[fixed[fixed >= 0]] = False
    return brute_force_kernel(points, geometry, fixed.astype(np.int64), np.flatnonzero(usable), float(tolerance_m), int(min_markers))


@numba.njit(cache=True)
def brute_force_kernel(points, geometry, fixed, pool, tolerance_m, min_markers):  # pragma: no cover - compiled
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
            if abs(reduce_norm(world[a], world[b]) - reduce_norm(body[a], body[b])) > slack:
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
                kabsch_into(world[:k], ell[:k], y_bar, scratch, R, t)  # Alg. 4
                residuals_into(world[:k], body[:k], R, t, res[:k])
                if all_within(res[:k], tolerance_m):
                    for j in range(k):
                        squares[j] = res[j] * res[j]
                    e = numpy_sum(squares[:k])  # Alg. 3's error, summed as numpy's (res**2).sum(axis=1)
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
            if abs(reduce_norm(world[a], world[b]) - reduce_norm(body[a], body[b])) > slack:
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
