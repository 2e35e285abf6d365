"""Square-root unscented Kalman filter of the marker model (Algorithm 5; van der Merwe and Wan 2001).

Recovery from a failed Cholesky downdate (counted in ``failed_downdates``), following section IV of the
paper ("the failed Cholesky update was simply ignored, and the value from before the update was used"):
- time update, ``cholupdate(S^-, X_0 - x^-, Wc[0])``: keep the QR factor without the Wc[0] term
  (it over-estimates the covariance when Wc[0] < 0, which is the safe side);
- innovation factor S_y: likewise keep its QR factor;
- final ``cholupdate(S^-, K S_y, -1)``: keep S^- (the state is still corrected, its covariance is not shrunk).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import cho_solve

from poseintegrity.tracking.cholesky import cholupdate, tril_from_qr
from poseintegrity.tracking.unscented import UnscentedMarkerFilter


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

    def _downdate(self, S: np.ndarray, X: np.ndarray, gamma: float) -> np.ndarray:
        S_new, ok = cholupdate(S, X, gamma)
        if not ok:
            self.failed_downdates += 1
        return S_new

    def _time_update(self, X_f: np.ndarray, x_prior: np.ndarray, B: np.ndarray) -> None:
        dev = X_f - x_prior[:, None]
        # S_k^- = qr{[sqrt(Wc[1]) (X_{k|k-1}[:, 1:] - x^-)  sqrt(P_proc)]}; B is the (rectangular) sqrt(P_proc)
        S = tril_from_qr(np.hstack([np.sqrt(self.Wc[1]) * dev[:, 1:], B]))
        self.S = self._downdate(S, dev[:, 0], self.Wc[0])  # S_k^- = cholupdate(S_k^-, X_0 - x^-, Wc[0])

    def _measurement_update(self, X: np.ndarray, Y: np.ndarray, z: np.ndarray, noise_std: np.ndarray) -> None:
        y_prior = Y @ self.Wm  # y_k^- = Y_{k|k-1} w_m
        dy = Y - y_prior[:, None]
        S_y = tril_from_qr(np.hstack([np.sqrt(self.Wc[1]) * dy[:, 1:], np.diag(noise_std)]))  # sqrt(P_mes), eq. 16
        S_y = self._downdate(S_y, dy[:, 0], self.Wc[0])
        P_xy = ((X - self.x[:, None]) * self.Wc) @ dy.T  # cross-covariance (N, m)
        # K = (P_xy / S_y^T) / S_y: two triangular solves of S_y S_y^T K^T = P_xy^T
        K = cho_solve((S_y, True), P_xy.T, check_finite=False).T
        self.x = self.x + K @ (z - y_prior)
        self.S = self._downdate(self.S, K @ S_y, -1.0)  # S_k = cholupdate(S_k^-, K S_y, -1)
