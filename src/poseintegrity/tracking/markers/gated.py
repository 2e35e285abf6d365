"""Gated optimal assignment (ours, beyond the paper's Alg. 1-3): the measured points are assigned to the filter's
predicted marker positions by scipy.optimize.linear_sum_assignment, minimising the summed distance, and pairs farther
apart than a gate are dropped."""

from __future__ import annotations

import numba
import numpy as np
from scipy.optimize import linear_sum_assignment

from poseintegrity.tracking.markers.consistency import check_rows_of_3, finite_mask
from poseintegrity.tracking.markers.summation import reduce_norm

BIG = 1e6  # the cost of a pair beyond the gate in the assignment


def match_gated(points: np.ndarray, predicted: np.ndarray, *, gate_m: float) -> np.ndarray:
    """Optimal assignment (scipy.optimize.linear_sum_assignment) to predicted marker positions.

    points : (n, 3) metres, rows with NaN never matched; predicted : (m, 3) metres, e.g. the filter's prior markers.
    Minimises the summed distance; pairs beyond gate_m (metres) are not matched.  Returns the assignment (m,) int:
    for each marker the index of its point, or -1.
    """
    points = check_rows_of_3("points", np.asarray(points, dtype=float).reshape(-1, 3))
    return match_gated_unchecked(points, finite_mask(points), check_rows_of_3("predicted", predicted), float(gate_m))


def match_gated_unchecked(points: np.ndarray, finite: np.ndarray, predicted: np.ndarray, gate_m: float) -> np.ndarray:
    """:func:`match_gated` on float (n, 3) points with their finite rows marked (n,) bool and float (m, 3) predicted."""
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
            cost[i, j] = reduce_norm(predicted[i], points[rows[j]])
            if cost[i, j] <= gate_m:
                row_pairs += 1
                column_pairs[j] += 1
                assignment[i] = rows[j]
                decided &= cost[i, j] < BIG / 2
        decided &= row_pairs <= 1
    for j in range(rows.size):
        decided &= column_pairs[j] <= 1
    return assignment, cost, decided
