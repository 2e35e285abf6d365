"""The state-space model tracked by both unscented filters (section II-E, eqs. 3-12, 16, 29-30).

State (eq. 3), N = 3n + 6:  x = [r^1; ...; r^n; omega; c_dot]  (marker centres in the world frame, metres;
angular velocity, rad/s, world frame; velocity of the body centre, m/s).
Measurement (eq. 4): the rows of x that were measured, i.e. any subset of the marker centres and omega.

``ell`` is the marker geometry centred on its centroid (n, 3), so that the body origin c of the paper is
the centroid of the markers and ``r^i = c + R ell^i``.
"""

from __future__ import annotations

import numba
import numpy as np

from poseintegrity.tracking.markers.kabsch import centred_cross_covariance, centred_cross_covariance_into, horn_rotation, horn_rotation_into


def state_dim(n_markers: int) -> int:
    """N = 3n + 6 (eq. 3)."""
    return 3 * n_markers + 6


def centred(points_body: np.ndarray) -> np.ndarray:
    """ell^i: the geometry (n, 3) metres, shifted so that its centroid is the origin."""
    return points_body - points_body.mean(axis=0)


@numba.njit(cache=True)
def _same_rows(X, k, rows):  # pragma: no cover - compiled
    """Whether column k of X equals column 0 in its first ``rows`` rows."""
    for i in range(rows):
        if X[i, k] != X[i, 0]:
            return False
    return True


@numba.njit(cache=True)
def process_model_kernel(X, dt, ell):  # pragma: no cover - compiled
    """Compiled :func:`process_model`; returns (X_next (N, b), R_k of column 0 (3, 3))."""
    n = ell.shape[0]
    X_next = X.copy()
    r = np.empty((n, 3))
    R_first, R_other = np.empty((3, 3)), np.empty((3, 3))
    V_first, V = np.eye(4), np.empty((4, 4))
    H, N, M = np.empty((3, 3)), np.empty((4, 4)), np.empty((4, 4))  # scratch of Alg. 4, reused by every column
    for k in range(X.shape[1]):  # one sigma point per column
        if k > 0 and _same_rows(X, k, 3 * n):  # it differs from the first only in omega or c_dot: same markers, same R_k
            R = R_first
        else:
            for i in range(n):
                r[i] = X[3 * i : 3 * i + 3, k]
            # R_k by Alg. 4, recomputed every step; the Jacobi sweeps of the other columns start from column 0's
            centred_cross_covariance_into(r, ell, H)
            R = R_first if k == 0 else R_other
            V[:] = V_first
            horn_rotation_into(H, V, N, M, R)
            if k == 0:
                V_first[:] = V
        w = X[3 * n : 3 * n + 3, k]
        v = X[3 * n + 3 : 3 * n + 6, k]
        for i in range(n):
            a0 = R[0, 0] * ell[i, 0] + R[0, 1] * ell[i, 1] + R[0, 2] * ell[i, 2]  # a = R_k ell^i
            a1 = R[1, 0] * ell[i, 0] + R[1, 1] * ell[i, 1] + R[1, 2] * ell[i, 2]
            a2 = R[2, 0] * ell[i, 0] + R[2, 1] * ell[i, 1] + R[2, 2] * ell[i, 2]
            X_next[3 * i + 0, k] += dt * (v[0] + w[1] * a2 - w[2] * a1)  # r + dt (c_dot + [w]x R ell)
            X_next[3 * i + 1, k] += dt * (v[1] + w[2] * a0 - w[0] * a2)
            X_next[3 * i + 2, k] += dt * (v[2] + w[0] * a1 - w[1] * a0)
    return X_next, R_first


def process_model(X: np.ndarray, dt: float, ell: np.ndarray) -> np.ndarray:
    """f of eq. 10 applied to every column of X (compiled loop over the sigma points).

    X : (N, b) states as columns; dt : seconds; ell : (n, 3) centred geometry, metres.
    R_k of each column comes from Kabsch (Alg. 4, via :func:`~poseintegrity.tracking.markers.kabsch.horn_rotation`)
    on its own marker positions, so the rigid body constraint holds:
    r^i <- r^i + dt (c_dot + [omega]x R ell^i); omega and c_dot are unchanged.
    """
    return process_model_kernel(np.ascontiguousarray(X, dtype=np.float64), float(dt), np.ascontiguousarray(ell, dtype=np.float64))[0]


def process_noise_sqrt(x: np.ndarray, dt: float, ell: np.ndarray, sigma_c: float, sigma_alpha: float) -> np.ndarray:
    """A square root B of the process covariance, ``P_proc = B @ B.T`` (eqs. 11, 17-30).

    x : (N,) state mean; dt : s; ell : (n, 3) m; sigma_c : m/s^2; sigma_alpha : rad/s^2.
    Returns B : (N, 7).  Columns 0-2 carry c_ddot ~ N(0, sigma_c^2 I) (eq. 8), columns 3-5 carry
    alpha ~ N(0, sigma_alpha^2 I) (eq. 9) through the noise vector v_k of eq. 11, and column 6 carries the
    centripetal term (dt^2 / 2) [omega]x^2 R ell^i that the paper keeps inside E_rr (eq. 29).

    Derived again from eq. 11 rather than copied from eqs. 26-28, whose text conversion is garbled:
    E{[alpha]x a_i a_j^T [alpha]x^T} = sigma_alpha^2 ((a_i . a_j) I - a_j a_i^T) with a_i = R ell^i
    (eq. 28's G^ij lacks the off-diagonal term and has a sign slip in its (2, 2) entry), and the
    marker/omega block is -(dt^3 / 2) sigma_alpha^2 [a_i]x (eq. 26 is its transpose).  P_proc has rank
    7 < N, so it has no Cholesky factor; the rectangular B feeds the QR of Alg. 5 directly.
    """
    x, ell = np.ascontiguousarray(x, dtype=np.float64), np.ascontiguousarray(ell, dtype=np.float64)
    R = horn_rotation(centred_cross_covariance(x[: 3 * ell.shape[0]].reshape(-1, 3), ell))  # Alg. 4
    return noise_sqrt_kernel(R, x, float(dt), ell, float(sigma_c), float(sigma_alpha))


@numba.njit(cache=True)
def noise_sqrt_kernel(R, x, dt, ell, sigma_c, sigma_alpha):  # pragma: no cover - compiled
    """Compiled :func:`process_noise_sqrt` given R (3, 3) of the markers of x (N,) by Alg. 4: a_i = R ell^i and
    the centripetal term (dt^2 / 2) [omega]x^2 a_i, then B (N, 7)."""
    n = ell.shape[0]
    w = x[3 * n : 3 * n + 3]
    a = np.empty((n, 3))
    centripetal = np.empty((n, 3))
    half_dt2 = 0.5 * dt * dt
    for i in range(n):
        for j in range(3):
            a[i, j] = R[j, 0] * ell[i, 0] + R[j, 1] * ell[i, 1] + R[j, 2] * ell[i, 2]
        wa = (w[1] * a[i, 2] - w[2] * a[i, 1], w[2] * a[i, 0] - w[0] * a[i, 2], w[0] * a[i, 1] - w[1] * a[i, 0])  # [omega]x a_i
        centripetal[i, 0] = half_dt2 * (w[1] * wa[2] - w[2] * wa[1])  # (dt^2 / 2) [omega]x^2 a_i
        centripetal[i, 1] = half_dt2 * (w[2] * wa[0] - w[0] * wa[2])
        centripetal[i, 2] = half_dt2 * (w[0] * wa[1] - w[1] * wa[0])
    return _noise_sqrt_kernel(a, centripetal, dt, sigma_c, sigma_alpha)


@numba.njit(cache=True)
def _noise_sqrt_kernel(a, centripetal, dt, sigma_c, sigma_alpha):  # pragma: no cover - compiled
    """B (N, 7) of :func:`process_noise_sqrt` from a_i = R ell^i (n, 3) and (dt^2 / 2) [omega]x^2 a_i (n, 3)."""
    n = a.shape[0]
    half_dt2 = 0.5 * dt * dt
    position, rotation = half_dt2 * sigma_c, -half_dt2 * sigma_alpha
    B = np.zeros((3 * n + 6, 7))
    for i in range(n):
        r = 3 * i
        for j in range(3):
            B[r + j, j] = position  # c_ddot (eq. 8)
            B[r + j, 6] = centripetal[i, j]  # [omega]x^2 a_i (eq. 29)
        # [alpha]x a_i = -[a_i]x alpha (eq. 9): rotation * skew(a_i), skew(v) = [[0, -v2, v1], [v2, 0, -v0], [-v1, v0, 0]]
        B[r, 3], B[r, 4], B[r, 5] = rotation * 0.0, rotation * -a[i, 2], rotation * a[i, 1]
        B[r + 1, 3], B[r + 1, 4], B[r + 1, 5] = rotation * a[i, 2], rotation * 0.0, rotation * -a[i, 0]
        B[r + 2, 3], B[r + 2, 4], B[r + 2, 5] = rotation * -a[i, 1], rotation * a[i, 0], rotation * 0.0
    for j in range(3):
        B[3 * n + j, 3 + j] = dt * sigma_alpha  # omega_{k+1} = omega_k + dt alpha_k
        B[3 * n + 3 + j, j] = dt * sigma_c  # c_dot_{k+1} = c_dot_k + dt c_ddot_k
    return B


def measurement_rows(observed: np.ndarray, gyro: bool) -> np.ndarray:
    """Indices of the state rows measured now (eq. 4 restricted to what arrived).

    observed : (n,) bool, markers measured in this frame; gyro : whether omega was measured.
    Returns (3 * observed.sum() + 3 * gyro,) int.
    """
    n = observed.shape[0]
    rows = (3 * np.flatnonzero(observed)[:, None] + np.arange(3)).ravel()
    return np.concatenate([rows, np.arange(3 * n, 3 * n + 3)]) if gyro else rows


def measurement_noise_std(observed: np.ndarray, gyro: bool, sigma_r: float, sigma_omega: float) -> np.ndarray:
    """Square root of the diagonal of P_mes (eq. 16) for the measured rows: sigma_r (m) or sigma_omega (rad/s)."""
    return np.concatenate([np.full(3 * int(observed.sum()), sigma_r), np.full(3 * int(gyro), sigma_omega)])


def process_model_reference(x: np.ndarray, dt: float, markers_body: np.ndarray) -> np.ndarray:
    """f of eq. 10 for one state, written plainly with the SVD Kabsch of Alg. 4 (independent of the compiled
    Horn rotation of :func:`process_model`).

    x : (N,) state; dt : s; markers_body : (n, 3) geometry, metres.  Returns (N,).
    The compiled :func:`process_model` is tested against it, and it is the ``fx`` given to filterpy.
    """
    n = markers_body.shape[0]
    r = x[: 3 * n].reshape(n, 3)
    omega, c_dot = x[3 * n : 3 * n + 3], x[3 * n + 3 :]
    ell = centred(markers_body)
    U, _, Vt = np.linalg.svd(ell.T @ (r - r.mean(axis=0)))  # H = P^T Q (Alg. 4)
    d = 1.0 if np.linalg.det(Vt.T @ U.T) >= 0 else -1.0  # handedness
    R = Vt.T @ np.diag([1.0, 1.0, d]) @ U.T  # R = V diag(1, 1, d) U^T
    a = ell @ R.T  # R ell^i
    r_next = r + dt * (c_dot + np.cross(omega, a))
    return np.concatenate([r_next.ravel(), omega, c_dot])
