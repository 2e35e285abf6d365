"""What the SR-UKF (Alg. 5) and the plain UKF share: scaled sigma points, weights, the model calls.

Sigma points and weights are those of Alg. 5 (van der Merwe's scaled unscented transform):
lambda = alpha^2 (N + kappa) - N, Wm[0] = lambda / (N + lambda), Wc[0] = Wm[0] + 1 - alpha^2 + beta,
Wm[i] = Wc[i] = 1 / (2 (N + lambda)) for i = 1..2N; X = [x, x + sqrt(N + lambda) S, x - sqrt(N + lambda) S].
A subclass decides how the covariance is carried (factor S or matrix P).
"""

from __future__ import annotations

import numba
import numpy as np

from poseintegrity.errors import ArgumentError, check_array
from poseintegrity.tracking.markers.kabsch import check_kabsch_arguments, pose_from_points_unchecked
from poseintegrity.params.track import FilterParams
from poseintegrity.tracking.filter.model import (
    centred,
    measurement_noise_std,
    measurement_rows,
    process_model,
    process_noise_sqrt,
    state_dim,
)


def unscented_weights(N: int, alpha: float, beta: float, kappa: float) -> tuple[np.ndarray, np.ndarray, float]:
    """(Wm, Wc, gamma) of Alg. 5: (2N + 1,) mean and covariance weights and gamma = sqrt(N + lambda)."""
    lam = alpha**2 * (N + kappa) - N
    Wm = np.full(2 * N + 1, 1.0 / (2.0 * (N + lam)))
    Wc = Wm.copy()
    Wm[0] = lam / (N + lam)
    Wc[0] = lam / (N + lam) + 1.0 - alpha**2 + beta
    return Wm, Wc, float(np.sqrt(N + lam))


@numba.njit(cache=True)
def _sigma_points_kernel(x, S, gamma):  # pragma: no cover - compiled
    """X = [x, x + gamma S, x - gamma S] (N, 2N + 1), element by element as numpy would compute it."""
    N = x.shape[0]
    X = np.empty((N, 2 * N + 1))
    for i in range(N):
        X[i, 0] = x[i] + gamma * 0.0
        for j in range(N):
            X[i, 1 + j] = x[i] + gamma * S[i, j]
            X[i, 1 + N + j] = x[i] + gamma * -S[i, j]
    return X


DIVERGENCE_REASONS = ("", "non-finite state or covariance", "runaway covariance")  # by health_code
MAX_ABS_MEASUREMENT = 1e6  # a measurement vector longer than this (metres, rad/s) holds no marker position or rate


@numba.njit(cache=True)
def observed_count_and_norm2(observed, z):  # pragma: no cover - compiled
    """(number of observed markers, z . z): the two numbers :meth:`UnscentedMarkerFilter.update` checks its
    arguments by, in one compiled call (cheaper per step than two numpy reductions)."""
    count = 0
    for flag in observed:
        count += flag
    norm2 = 0.0
    for value in z:
        norm2 += value * value
    return count, norm2


@numba.njit(cache=True)
def health_code(x, P_diag, n_position_rows, max_position_std):  # pragma: no cover - compiled
    """Divergence test of the filters: 0 healthy, 1 NaN/inf in x (N,) or P_diag (N,), 2 a marker standard
    deviation sqrt(max P_diag[:n_position_rows]) above max_position_std (m); see ``DIVERGENCE_REASONS``."""
    for i in range(x.shape[0]):
        if not (np.isfinite(x[i]) and np.isfinite(P_diag[i])):
            return 1
    if np.sqrt(P_diag[:n_position_rows].max()) > max_position_std:
        return 2
    return 0


class UnscentedMarkerFilter:
    """Base of the marker-position filters; use :class:`SquareRootUKF` or :class:`UnscentedKalmanFilter`.

    markers_body : (n, 3) marker geometry, metres (any origin; it is centred internally).
    settings : alpha, beta, kappa (None: 3 - N); sigma_r (m) and sigma_omega (rad/s) of eq. 16; sigma_c
    (m/s^2) and sigma_alpha (rad/s^2) of eqs. 8-9; init_std_omega / init_std_velocity, the initial
    uncertainty of the unmeasured states; max_position_std (m): a larger marker std counts as divergence.
    Attributes: x (N,) state of eq. 3; initialized; failed_downdates (count of failed Cholesky
    downdates, see the subclass for the recovery); n_divergences; last_reason (why the last step failed).
    """

    def __init__(self, markers_body: np.ndarray, settings: FilterParams):
        self.markers_body = check_kabsch_arguments(markers_body, markers_body)[1]  # >= 3 finite markers, not on one line
        self.ell = centred(self.markers_body)
        self.n = self.ell.shape[0]
        self.N = state_dim(self.n)
        self.settings = settings
        kappa = 3.0 - self.N if settings.kappa is None else settings.kappa
        self.Wm, self.Wc, self.gamma = unscented_weights(self.N, settings.alpha, settings.beta, kappa)
        self.x = np.zeros(self.N)
        self.initialized = False
        self.failed_downdates = 0
        self.n_divergences = 0
        self.last_reason = ""
        self._measured: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}  # (rows, noise std) by (observed mask, gyro, sigma_r, sigma_omega)

    # -- covariance representation, provided by the subclass -------------------------------------
    def sqrt_covariance(self) -> np.ndarray:
        """A lower-triangular S with P = S S^T, (N, N)."""
        raise NotImplementedError

    def covariance(self) -> np.ndarray:
        """P, (N, N)."""
        raise NotImplementedError

    def covariance_diagonal(self) -> np.ndarray:
        """Variances diag(P), (N,)."""
        return np.diag(self.covariance())

    def _set_covariance(self, std: np.ndarray) -> None:
        raise NotImplementedError

    def _time_update(self, X_f: np.ndarray, x_prior: np.ndarray, B: np.ndarray) -> None:
        raise NotImplementedError

    def _measurement_update(self, rows: np.ndarray, z: np.ndarray, noise_std: np.ndarray) -> int:
        """Fuse z (m,) measuring the state rows (m,) int (Y = h(X): rows of X, eq. 4) with noise std (m,);
        returns the :func:`health_code` of the result."""
        raise NotImplementedError

    # -- the filter ------------------------------------------------------------------------------
    def initialize(self, markers: np.ndarray, omega: np.ndarray | None = None) -> None:
        """Start from a good measurement (Alg. 5): markers (n, 3) m in geometry order, omega (3,) rad/s or None."""
        s = self.settings
        markers = check_array("markers", markers, shape=(self.n, 3))
        omega = np.zeros(3) if omega is None else check_array("omega", omega, shape=(3,))
        self.x = np.concatenate([markers.ravel(), omega, np.zeros(3)])
        std = np.concatenate([np.full(3 * self.n, s.sigma_r), np.full(3, s.init_std_omega), np.full(3, s.init_std_velocity)])
        self._set_covariance(std)
        self.initialized = True
        self.last_reason = ""

    def sigma_points(self) -> np.ndarray:
        """X_{k-1} of Alg. 5: (N, 2N + 1), the state and x +/- gamma S as columns."""
        return _sigma_points_kernel(self.x, np.ascontiguousarray(self.sqrt_covariance()), self.gamma)

    def predict(self, dt: float, noise_sqrt: np.ndarray | None = None) -> bool:
        """Time update over dt seconds (Alg. 5, "State Update").  Returns False if the filter diverged.

        noise_sqrt : (N, p) a square root B of the process covariance, P_proc = B B^T; None: eq. 30 at the
        current state (:func:`~poseintegrity.tracking.filter.model.process_noise_sqrt`).  A fixed B is how the filter
        runs an additive-noise model for the comparison with pykalman.
        """
        return self.predict_steps(1, dt, noise_sqrt)

    def predict_steps(self, n_steps: int, dt: float, noise_sqrt: np.ndarray | None = None) -> bool:
        """n_steps time updates of dt seconds each (see :meth:`predict`); stops at the first divergence.

        Refused with :class:`~poseintegrity.errors.ArgumentError` (checked here, once per call, never in the
        compiled steps): n_steps not a non-negative integer; dt not a finite number > 0 when n_steps > 0 (a
        filter does not run backwards or stand still); noise_sqrt not a finite (N, p) array.
        """
        if isinstance(n_steps, (bool, np.bool_)) or not isinstance(n_steps, (int, np.integer)) or n_steps < 0:
            raise ArgumentError(f"n_steps: expected a non-negative integer, got {type(n_steps).__name__} {n_steps!r:.40}")
        if n_steps:
            ok = isinstance(dt, (int, float, np.integer, np.floating)) and not isinstance(dt, (bool, np.bool_)) and 0.0 < dt < np.inf
            if not ok:
                raise ArgumentError(f"dt: expected a finite time step > 0 s, got {type(dt).__name__} {dt!r:.40}")
        if noise_sqrt is not None:
            noise_sqrt = check_array("noise_sqrt", noise_sqrt, shape=(self.N, None))
        return self._predict_steps(int(n_steps), float(dt), noise_sqrt)

    def _predict_steps(self, n_steps: int, dt: float, noise_sqrt: np.ndarray | None) -> bool:
        """:meth:`predict_steps` on checked arguments."""
        for _ in range(n_steps):
            X_f = process_model(self.sigma_points(), dt, self.ell)  # X_{k|k-1} = f(X_{k-1})
            B = process_noise_sqrt(self.x, dt, self.ell, self.settings.sigma_c, self.settings.sigma_alpha) if noise_sqrt is None else noise_sqrt
            self.x = X_f @ self.Wm  # x_k^- = X_{k|k-1} w_m
            self._time_update(X_f, self.x, B)
            if not self._check_health():
                return False
        return True

    def update(self, z: np.ndarray, observed: np.ndarray, gyro: bool) -> bool:
        """Measurement update with whatever arrived (Alg. 5, "Measurement Update"; partial updates).

        The sigma points are redrawn from (x^-, S^-) instead of reusing X_{k|k-1} as Alg. 5 writes: then
        P_yy and P_xy include P_proc (with the reused points they miss it), updates may follow each other
        without a predict between them, and the filter is the one filterpy implements.

        z : measured rows in state order: the observed markers (3 each, metres) then omega (3, rad/s)
        if gyro.  observed : (n,) bool.  With nothing measured the call is a no-op.
        Returns False if the filter diverged (then ``initialized`` is False and it must be restarted).
        Refused with :class:`~poseintegrity.errors.ArgumentError` (checked here, before the compiled update):
        observed not a boolean (n,) mask, gyro not a bool, z not finite (or of norm above 1e6) or not of length
        3 * observed.sum() + 3 * gyro.
        """
        if type(observed) is not np.ndarray or observed.dtype.char != "?" or observed.shape != (self.n,):
            observed = np.asarray(observed)
            if observed.shape != (self.n,) or observed.dtype != np.bool_:
                raise ArgumentError(f"observed: expected a boolean mask of shape ({self.n},) (one per marker), "
                                    f"got shape {observed.shape} and dtype {observed.dtype}")
        if gyro is not True and gyro is not False and not isinstance(gyro, np.bool_):
            raise ArgumentError(f"gyro: expected True or False, got {type(gyro).__name__} {gyro!r:.40}")
        if type(z) is not np.ndarray or z.dtype.char != "d":
            try:
                z = np.asarray(z)
                if z.dtype.kind not in "iuf":  # text, objects and True are not measurements
                    raise TypeError
                z = z.astype(np.float64)
            except (TypeError, ValueError):
                raise ArgumentError(f"z: expected real numbers, got {type(z).__name__} {z!r:.60}") from None
        if z.ndim != 1:
            raise ArgumentError(f"z: expected a vector of measured rows, got shape {z.shape}")
        count, norm2 = observed_count_and_norm2(observed, z)
        m = 3 * count + 3 * bool(gyro)
        if z.shape[0] != m:
            raise ArgumentError(f"z: expected shape ({m},) (3 per observed marker{' + 3 gyro rates' if gyro else ''}), got {z.shape}")
        if not norm2 <= MAX_ABS_MEASUREMENT**2:  # False for NaN, inf and 1e300
            raise ArgumentError(f"z: must be finite with a norm of at most {MAX_ABS_MEASUREMENT:g} (m, rad/s), "
                                f"got norm {float(np.sqrt(norm2))!r}")
        return self._update(z, observed, bool(gyro))

    def _update(self, z: np.ndarray, observed: np.ndarray, gyro: bool) -> bool:
        """:meth:`update` on checked arguments (z float64 of the right length, observed (n,) bool)."""
        key = (observed.tobytes(), gyro, self.settings.sigma_r, self.settings.sigma_omega)
        if key not in self._measured:  # the rows and noise of each combination of measured markers and gyro, made once
            self._measured[key] = (measurement_rows(observed, gyro),
                                   measurement_noise_std(observed, gyro, self.settings.sigma_r, self.settings.sigma_omega))
        rows, noise_std = self._measured[key]
        if rows.size == 0:
            return True
        return self._record_health(self._measurement_update(rows, z, noise_std))

    def markers(self) -> np.ndarray:
        """Estimated marker centres (n, 3), metres, world frame."""
        return self.x[: 3 * self.n].reshape(self.n, 3).copy()

    def pose(self) -> np.ndarray:
        """T_world_body (4, 4) of the marker geometry, from the estimated markers by Kabsch (Alg. 4)."""
        return pose_from_points_unchecked(self.markers(), self.markers_body)

    def _health_code(self) -> int:
        """:func:`health_code` of the current state and covariance."""
        return health_code(self.x, self.covariance_diagonal(), 3 * self.n, self.settings.max_position_std)

    def _check_health(self) -> bool:
        """Divergence test: NaN/inf anywhere or a marker standard deviation above max_position_std."""
        return self._record_health(self._health_code())

    def _record_health(self, code: int) -> bool:
        """False and the filter stopped (``initialized`` False, counted, ``last_reason``) if code is not 0."""
        if code:
            self.initialized = False
            self.n_divergences += 1
            self.last_reason = DIVERGENCE_REASONS[code]
            return False
        return True
