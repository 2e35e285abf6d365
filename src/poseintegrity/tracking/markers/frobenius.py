"""Frobenius-norm point correspondence (Black and Salcudean II-D, Algorithm 1 and appendix B): each marker takes the
current point closest to its previous position, as the permutation minimising ||X - Y P_y||_F."""

from __future__ import annotations

from itertools import combinations, permutations

import numpy as np

from poseintegrity.tracking.markers.consistency import finite_rows


def match_frobenius(points: np.ndarray, previous: np.ndarray, *, max_distance_m: float = np.inf) -> np.ndarray:
    """Alg. 1: the permutation P_y maximising tr(X^T Y P_y), i.e. minimising ||X - Y P_y||_F (eqs. 1-2, 13-15).

    points : (n, 3) current points X; previous : (m, 3) previous marker positions Y (geometry order).
    When n < m a marker is missing: the optimisation runs with every choice of columns of Y removed
    (appendix B); when n > m the extra points are left out the same way.  Because the candidates then
    differ in ||Y P_y||_F, they are compared by the full Frobenius distance, not by the trace alone.
    Pairs farther apart than max_distance_m are rejected (closest-last-point outliers).
    Returns the assignment (m,) int: for each marker the index of its point, or -1.
    """
    previous = np.asarray(previous, dtype=float)
    m = previous.shape[0]
    assignment = np.full(m, -1)
    rows = finite_rows(points)
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
