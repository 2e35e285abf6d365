"""Square-root unscented Kalman filter of the marker model (Algorithm 5; van der Merwe and Wan 2001).

Recovery from a failed Cholesky downdate (counted in ``failed_downdates``), following section IV of the
paper ("the failed Cholesky update was simply ignored, and the value from before the update was used"):
- time update, ``cholupdate(S^-, X_0 - x^-, Wc[0])``: keep the QR factor without the Wc[0] term
  (it over-estimates the covariance when Wc[0] < 0, which is the safe side);
- innovation factor S_y: likewise keep its QR factor;
- final ``cholupdate(S^-, K S_y, -1)``: keep S^- (the state is still corrected, its covariance is not shrunk).

Both halves of Alg. 5 run as compiled kernels (sigma points, f of eq. 10, B of eq. 30, QR, downdates and
the divergence test fused), and the time update advances any number of filter-clock steps in one call:
at 400 Hz the per-step numpy call overhead was most of a run.
"""

from __future__ import annotations

import numba
import numpy as np

from poseintegrity.tracking.filter.cholesky import lower_factor, rank1_update
from poseintegrity.tracking.filter.model import noise_sqrt_kernel, process_model_kernel
from poseintegrity.tracking.filter.unscented import UnscentedMarkerFilter, _sigma_points_kernel, health_code

_NO_NOISE_SQRT = np.zeros((0, 0))  # "B of eq. 30 at the current state" for the kernels


class SquareRootUKF(UnscentedMarkerFilter):
    """SR-UKF tracking the marker positions, angular velocity and velocity (state of eq. 3).

    Carries S (N, N) lower triangular, P = S S^T.  See :class:`UnscentedMarkerFilter` for the interface.
    """

    S: np.ndarray

    def sqrt_covariance(self) -> np.ndarray:
        return self.S

    def covariance(self) -> np.ndarray:
        return self.S @ self.S.T

    def covariance_diagonal(self) -> np.ndarray:
        return np.einsum("ij,ij->i", self.S, self.S)

    def _set_covariance(self, std: np.ndarray) -> None:
        self.S = np.diag(std)

    def _predict_steps(self, n_steps: int, dt: float, noise_sqrt: np.ndarray | None) -> bool:
        s = self.settings
        B = _NO_NOISE_SQRT if noise_sqrt is None else np.ascontiguousarray(noise_sqrt, dtype=np.float64)
        self.x, self.S, code, failed = _time_update_steps(
            np.ascontiguousarray(self.x, dtype=np.float64), np.ascontiguousarray(self.S, dtype=np.float64), int(n_steps), float(dt),
            self.ell, self.Wm, self.Wc, self.gamma, B, s.sigma_c, s.sigma_alpha, s.max_position_std,
        )
        self.failed_downdates += failed
        return self._record_health(code)

    def _measurement_update(self, rows: np.ndarray, z: np.ndarray, noise_std: np.ndarray) -> int:
        self.x, self.S, code, failed = _measurement_update_kernel(
            self.x, self.S, rows, np.ascontiguousarray(z), noise_std, self.Wm, self.Wc, self.gamma, 3 * self.n, self.settings.max_position_std
        )
        self.failed_downdates += failed
        return code


@numba.njit(cache=True)
def _weighted_mean(X, w):  # pragma: no cover - compiled
    """X w (rows,) for X (rows, 2N + 1): the mean of eq. 13 / of y_k^-."""
    out = np.zeros(X.shape[0])
    for i in range(X.shape[0]):
        for j in range(X.shape[1]):
            out[i] += X[i, j] * w[j]
    return out


@numba.njit(cache=True)
def _square_root_of_spread(dev, root_weight, extra):  # pragma: no cover - compiled
    """qr{[sqrt(Wc[1]) dev[:, 1:], extra]} of Alg. 5: dev (rows, 2N + 1), extra (rows, p) -> (rows, rows)."""
    rows, L = dev.shape
    A = np.empty((rows, L - 1 + extra.shape[1]))
    for i in range(rows):
        for j in range(1, L):
            A[i, j - 1] = root_weight * dev[i, j]
        for j in range(extra.shape[1]):
            A[i, L - 1 + j] = extra[i, j]
    return lower_factor(A)


@numba.njit(cache=True)
def _time_update_steps(x, S, n_steps, dt, ell, Wm, Wc, gamma, B_fixed, sigma_c, sigma_alpha, max_position_std):  # pragma: no cover - compiled
    """n_steps of Alg. 5's "State Update" from (x (N,), S (N, N)); stops after a step that fails
    :func:`health_code`.  B_fixed (N, p) is the noise square root, or (0, 0) for B of eq. 30 at each step's x.
    Returns (x, S, health code, number of failed downdates)."""
    N = x.shape[0]
    failed = 0
    root_weight = np.sqrt(Wc[1])
    for _ in range(n_steps):
        X_f, R = process_model_kernel(_sigma_points_kernel(x, S, gamma), dt, ell)  # X_{k|k-1} = f(X_{k-1}), eq. 10
        B = noise_sqrt_kernel(R, x, dt, ell, sigma_c, sigma_alpha) if B_fixed.shape[0] == 0 else B_fixed  # eq. 30 (R of x: column 0)
        x = _weighted_mean(X_f, Wm)  # x_k^- = X_{k|k-1} w_m
        dev = X_f - x.reshape(N, 1)
        # S_k^- = qr{[sqrt(Wc[1]) (X_{k|k-1}[:, 1:] - x^-)  sqrt(P_proc)]}; B is the (rectangular) sqrt(P_proc)
        S_qr = _square_root_of_spread(dev, root_weight, B)
        S, ok = rank1_update(S_qr, dev[:, :1].copy(), Wc[0])  # S_k^- = cholupdate(S_k^-, X_0 - x^-, Wc[0])
        failed += not ok
        code = health_code(x, (S * S).sum(axis=1), 3 * ell.shape[0], max_position_std)
        if code:
            return x, S, code, failed
    return x, S, 0, failed


@numba.njit(cache=True)
def _measurement_update_kernel(x, S, rows, z, noise_std, Wm, Wc, gamma, n_position_rows, max_position_std):  # pragma: no cover - compiled
    """Alg. 5's "Measurement Update" of (x (N,), S (N, N)) with z (m,) measuring the state rows (m,) int with
    noise std (m,) (eq. 16).  Returns (x, S, health code, number of failed downdates)."""
    N, m = x.shape[0], rows.shape[0]
    X = _sigma_points_kernel(x, S, gamma)
    Y = np.empty((m, X.shape[1]))  # Y = h(X): rows of X (eq. 4)
    for r in range(m):
        Y[r] = X[rows[r]]
    y_prior = _weighted_mean(Y, Wm)  # y_k^- = Y_{k|k-1} w_m
    dy = Y - y_prior.reshape(m, 1)
    S_y = _square_root_of_spread(dy, np.sqrt(Wc[1]), np.diag(noise_std))  # sqrt(P_mes) of eq. 16
    S_y, ok_y = rank1_update(S_y, dy[:, :1].copy(), Wc[0])
    P_xy = ((X - x.reshape(N, 1)) * Wc) @ dy.T  # cross-covariance (N, m)
    # K = (P_xy / S_y^T) / S_y: S_y S_y^T K^T = P_xy^T by forward then back substitution
    Kt = np.ascontiguousarray(P_xy.T)
    for i in range(m):
        for k in range(i):
            Kt[i] -= S_y[i, k] * Kt[k]
        Kt[i] /= S_y[i, i]
    for i in range(m - 1, -1, -1):
        for k in range(i + 1, m):
            Kt[i] -= S_y[k, i] * Kt[k]
        Kt[i] /= S_y[i, i]
    K = Kt.T
    x_new = x + K @ (z - y_prior)
    S_new, ok = rank1_update(S, np.ascontiguousarray(K @ S_y), -1.0)  # S_k = cholupdate(S_k^-, K S_y, -1)
    code = health_code(x_new, (S_new * S_new).sum(axis=1), n_position_rows, max_position_std)
    return x_new, S_new, code, (not ok_y) + (not ok)
