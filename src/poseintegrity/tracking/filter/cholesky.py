"""Triangular square roots for the SR-UKF: QR-based factor and rank-1 Cholesky update / downdate.

Convention: ``S`` is lower triangular with ``P = S @ S.T`` (van der Merwe and Wan 2001 write the upper
factor; the algebra is the same).  There is no rank-1 update in numpy/scipy (docs/references.md), so it is written
here after Stewart, *Matrix Algorithms I* (1998), sec. 4.3, the reference [61] of the paper.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, inline="always")
def _reflect_four_rows(W, i, k, v0, scale):  # pragma: no cover - compiled
    """Rows i..i+3 of W (N, p) times the Householder reflection of row k, in place, as :func:`lower_factor`
    reflects one row: each row's dot product is summed in the same order (same bits), but the four are
    independent, so the CPU overlaps their additions instead of waiting on one chain."""
    p = W.shape[1]
    d0, d1, d2, d3 = W[i, k] * v0, W[i + 1, k] * v0, W[i + 2, k] * v0, W[i + 3, k] * v0
    for j in range(k + 1, p):
        w = W[k, j]
        d0 += W[i, j] * w
        d1 += W[i + 1, j] * w
        d2 += W[i + 2, j] * w
        d3 += W[i + 3, j] * w
    d0, d1, d2, d3 = d0 * scale, d1 * scale, d2 * scale, d3 * scale
    W[i, k] -= d0 * v0
    W[i + 1, k] -= d1 * v0
    W[i + 2, k] -= d2 * v0
    W[i + 3, k] -= d3 * v0
    for j in range(k + 1, p):
        w = W[k, j]
        W[i, j] -= d0 * w
        W[i + 1, j] -= d1 * w
        W[i + 2, j] -= d2 * w
        W[i + 3, j] -= d3 * w


@numba.njit(cache=True)
def lower_factor(A):  # pragma: no cover - compiled
    """qr{A^T} of Alg. 5 as an LQ decomposition A = L Q by Householder reflections on the rows of A
    (Golub and Van Loan, *Matrix Computations*, alg. 5.2.1, transposed): A (N, p) -> S = L (N, N) with the
    column signs that make its diagonal non-negative (S S^T = L L^T = A A^T).  A row that is already zero
    beyond the diagonal is left as it is, as LAPACK's dgeqrf does."""
    N, p = A.shape
    W = A.copy()
    for k in range(N):
        tail2 = 0.0
        for j in range(k + 1, p):
            tail2 += W[k, j] * W[k, j]
        if not (tail2 > 0.0):  # nothing to annihilate (or non-finite: left to the health check)
            if not np.isfinite(tail2):
                W[k, k] = np.nan
            continue
        norm2 = W[k, k] * W[k, k] + tail2
        beta = -np.sqrt(norm2) if W[k, k] >= 0.0 else np.sqrt(norm2)  # new diagonal, sign as in LAPACK's dlarfg
        v0 = W[k, k] - beta  # v = [v0, W[k, k+1:]], H = I - 2 v v^T / (v^T v)
        scale = 2.0 / (v0 * v0 + tail2)
        first = k + 1
        for i in range(k + 1, N - 3, 4):  # four rows at a time: four sums in flight, each in the one-row order
            _reflect_four_rows(W, i, k, v0, scale)
            first = i + 4
        for i in range(first, N):
            dot = W[i, k] * v0
            for j in range(k + 1, p):
                dot += W[i, j] * W[k, j]
            dot *= scale
            W[i, k] -= dot * v0
            for j in range(k + 1, p):
                W[i, j] -= dot * W[k, j]
        W[k, k] = beta
    S = np.zeros((N, N))
    for j in range(N):
        sign = -1.0 if W[j, j] < 0.0 else 1.0
        for i in range(j, N):
            S[i, j] = W[i, j] * sign
    return S


@numba.njit(cache=True)
def _rank1_sweep(S, X, sign):  # pragma: no cover - compiled
    """In-place sequence of rank-1 updates (sign +1) or downdates (sign -1); False if one fails."""
    n = S.shape[0]
    for col in range(X.shape[1]):
        x = X[:, col].copy()
        for k in range(n):
            diag = S[k, k]
            r2 = diag * diag + sign * x[k] * x[k]
            if not (r2 > 0.0) or not (diag > 0.0) or not np.isfinite(r2):
                return False
            r = np.sqrt(r2)
            c = r / diag
            s = x[k] / diag
            S[k, k] = r
            for i in range(k + 1, n):
                S[i, k] = (S[i, k] + sign * s * x[i]) / c
                x[i] = c * x[i] - s * S[i, k]
    return True


@numba.njit(cache=True)
def rank1_update(S, X, gamma):  # pragma: no cover - compiled
    """Compiled :func:`cholupdate`: S (N, N), X (N, p) C-contiguous, gamma float -> (S_new, ok)."""
    if gamma == 0.0:
        return S.copy(), True
    S_new = S.copy()
    if _rank1_sweep(S_new, X * np.sqrt(abs(gamma)), 1.0 if gamma > 0 else -1.0):
        return S_new, True
    return S.copy(), False


def cholupdate(S: np.ndarray, X: np.ndarray, gamma: float) -> tuple[np.ndarray, bool]:
    """Cholesky factor of ``S S^T + gamma * X X^T`` (``cholupdate(S, x, gamma)`` of Alg. 5).

    S : (N, N) lower triangular, positive diagonal.  X : (N,) or (N, p): one rank-1 term per column.
    gamma : weight; negative means a downdate.
    Returns (S_new, ok).  A downdate that would lose positive definiteness (or any non-finite value)
    fails: then ``ok`` is False and S_new is an unchanged copy of S; the caller decides the recovery.
    """
    S = np.ascontiguousarray(S, dtype=np.float64)
    X = np.ascontiguousarray(np.asarray(X, dtype=np.float64).reshape(S.shape[0], -1))
    return rank1_update(S, X, float(gamma))
