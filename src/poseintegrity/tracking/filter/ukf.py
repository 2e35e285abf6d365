"""Plain (covariance-form) UKF of the same marker model: the reference the SR-UKF is checked against.

Same sigma points (S = cholesky(P), lower), weights and model as :mod:`srukf`; P is propagated directly.
"""

from __future__ import annotations

import numpy as np

from poseintegrity.tracking.filter.unscented import UnscentedMarkerFilter


class UnscentedKalmanFilter(UnscentedMarkerFilter):
    """Covariance-form UKF (P (N, N)); see :class:`UnscentedMarkerFilter` for the interface."""

    P: np.ndarray

    def sqrt_covariance(self) -> np.ndarray:
        try:
            return np.linalg.cholesky(self.P)
        except np.linalg.LinAlgError:
            return np.full_like(self.P, np.nan)  # not positive definite: the health check flags it next

    def covariance(self) -> np.ndarray:
        return self.P

    def _set_covariance(self, std: np.ndarray) -> None:
        self.P = np.diag(std**2)

    def _time_update(self, X_f: np.ndarray, x_prior: np.ndarray, B: np.ndarray) -> None:
        dev = X_f - x_prior[:, None]
        self.P = (dev * self.Wc) @ dev.T + B @ B.T  # P^- = sum Wc (X - x^-)(X - x^-)^T + P_proc

    def _measurement_update(self, rows: np.ndarray, z: np.ndarray, noise_std: np.ndarray) -> int:
        X = self.sigma_points()
        Y = X[rows]  # Y = h(X): rows of X (eq. 4)
        y_prior = Y @ self.Wm
        dy = Y - y_prior[:, None]
        P_yy = (dy * self.Wc) @ dy.T + np.diag(noise_std**2)
        P_xy = ((X - self.x[:, None]) * self.Wc) @ dy.T
        K = np.linalg.solve(P_yy, P_xy.T).T  # K = P_xy P_yy^-1 (P_yy symmetric)
        self.x = self.x + K @ (z - y_prior)
        self.P = self.P - K @ P_yy @ K.T
        self.P = 0.5 * (self.P + self.P.T)
        return self._health_code()
