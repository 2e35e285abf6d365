"""Triangular square roots for the SR-UKF: QR-based factor and rank-1 Cholesky update / downdate.

Convention: ``S`` is lower triangular with ``P = S @ S.T`` (van der Merwe and Wan 2001 write the upper
factor; the algebra is the same).  There is no rank-1 update in numpy/scipy (docs/references.md), so it is written
here after Stewart, *Matrix Algorithms I* (1998), sec. 4.3, the reference [61] of the paper.
"""

from __future__ import annotations

import numba
import numpy as np
from scipy.linalg.lapack import dgeqrf


def tril_from_qr(A: np.ndarray) -> np.ndarray:
    """Lower-triangular S with ``S @ S.T == A @ A.T`` from a QR decomposition of ``A.T``.

    A : (N, p) float, p >= N, full row rank.  Returns (N, N) float with a non-negative diagonal
    (column signs of the QR factor are flipped, which leaves ``S @ S.T`` unchanged).
    """
    qr, _, _, info = dgeqrf(A.T)  # qr{[...]} of Alg. 5: LAPACK's Householder QR, R in the upper triangle
    if info != 0:
        raise np.linalg.LinAlgError(f"QR factorisation failed (LAPACK dgeqrf info {info})")
    return _signed_transpose_of_r(qr, A.shape[0])


@numba.njit(cache=True)
def _signed_transpose_of_r(qr, N):  # pragma: no cover - compiled
    """S = R^T diag(signs) (N, N) from the upper triangle R of qr[:N], signs = -1 where R's diagonal is negative.
    Every entry is R^T's times its column's sign, so the zeros above the diagonal keep that sign (-0.0), as
    ``triu(qr)[:N].T * signs`` gives them."""
    S = np.empty((N, N))
    for j in range(N):
        sign = -1.0 if qr[j, j] < 0 else 1.0
        for i in range(N):
            S[i, j] = (qr[j, i] if i >= j else 0.0) * sign
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


def cholupdate(S: np.ndarray, X: np.ndarray, gamma: float) -> tuple[np.ndarray, bool]:
    """Cholesky factor of ``S S^T + gamma * X X^T`` (``cholupdate(S, x, gamma)`` of Alg. 5).

    S : (N, N) lower triangular, positive diagonal.  X : (N,) or (N, p): one rank-1 term per column.
    gamma : weight; negative means a downdate.
    Returns (S_new, ok).  A downdate that would lose positive definiteness (or any non-finite value)
    fails: then ``ok`` is False and S_new is an unchanged copy of S; the caller decides the recovery.
    """
    S_new = np.array(S, dtype=np.float64, order="C", copy=True)
    X = np.asarray(X, dtype=np.float64).reshape(S.shape[0], -1) * np.sqrt(abs(gamma))
    if gamma == 0.0:
        return S_new, True
    ok = _rank1_sweep(S_new, np.ascontiguousarray(X), 1.0 if gamma > 0 else -1.0)
    if not ok:
        return np.array(S, dtype=np.float64, copy=True), False
    return S_new, True
