"""The SR-UKF of Alg. 5 one numpy / LAPACK call at a time (the implementation before the fused kernels), as the
reference that benchmarks/bench_tracking.py times a whole filter run against.  Same algorithm, same recovery
from failed downdates, same divergence test; only how each step is computed differs (and so the rounding)."""

import numpy as np
from scipy.linalg import cho_solve
from scipy.linalg.lapack import dgeqrf

from poseintegrity.poses import pose_matrix
from poseintegrity.tracking.filter.cholesky import cholupdate
from poseintegrity.tracking.filter.model import process_model, process_noise_sqrt
from poseintegrity.tracking.filter.srukf import SquareRootUKF


def tril_from_lapack_qr(A):
    """Lower S with S S^T = A A^T from LAPACK's QR of A^T (A (N, p)), non-negative diagonal."""
    qr = dgeqrf(A.T)[0]
    R = np.triu(qr[: A.shape[0]])
    return R.T * np.where(np.diag(R) < 0, -1.0, 1.0)


def svd_pose(points_world, points_body):
    """T (4, 4) by the SVD Kabsch of Alg. 4."""
    r_bar, y_bar = points_world.mean(axis=0), points_body.mean(axis=0)
    U, _, Vt = np.linalg.svd((points_body - y_bar).T @ (points_world - r_bar))
    d = 1.0 if np.linalg.det(Vt.T @ U.T) >= 0 else -1.0
    R = Vt.T @ np.diag([1.0, 1.0, d]) @ U.T
    return pose_matrix(R, r_bar - R @ y_bar)


class StepwiseSquareRootUKF(SquareRootUKF):
    """SR-UKF with every step of Alg. 5 as separate numpy / scipy calls."""

    def _downdate(self, S, X, gamma):
        S_new, ok = cholupdate(S, X, gamma)
        self.failed_downdates += not ok
        return S_new

    def predict_steps(self, n_steps, dt, noise_sqrt=None):
        for _ in range(n_steps):
            X_f = process_model(self.sigma_points(), dt, self.ell)
            B = process_noise_sqrt(self.x, dt, self.ell, self.settings.sigma_c, self.settings.sigma_alpha) if noise_sqrt is None else noise_sqrt
            self.x = X_f @ self.Wm
            dev = X_f - self.x[:, None]
            S = tril_from_lapack_qr(np.hstack([np.sqrt(self.Wc[1]) * dev[:, 1:], B]))
            self.S = self._downdate(S, dev[:, 0], self.Wc[0])
            if not self._check_health():
                return False
        return True

    def _measurement_update(self, rows, z, noise_std):
        X = self.sigma_points()
        Y = X[rows]
        y_prior = Y @ self.Wm
        dy = Y - y_prior[:, None]
        S_y = self._downdate(tril_from_lapack_qr(np.hstack([np.sqrt(self.Wc[1]) * dy[:, 1:], np.diag(noise_std)])), dy[:, 0], self.Wc[0])
        P_xy = ((X - self.x[:, None]) * self.Wc) @ dy.T
        K = cho_solve((S_y, True), P_xy.T, check_finite=False).T
        self.x = self.x + K @ (z - y_prior)
        self.S = self._downdate(self.S, K @ S_y, -1.0)
        return self._health_code()

    def pose(self):
        return svd_pose(self.markers(), self.markers_body)
