"""Peer filters on our marker model, for agreement and speed: filterpy's UKF and pykalman's square-root UKF.

- filterpy.kalman.UnscentedKalmanFilter (covariance form) with MerweScaledSigmaPoints: eq. 10 per sigma
  point with the SVD Kabsch of Alg. 4, P_proc of eq. 30 set before every predict.
- pykalman.sqrt.AdditiveUnscentedKalmanFilter (van der Merwe's SR-UKF, additive noise only).  Its sigma
  points always use alpha 1, beta 0, kappa 3 - N (``filter_update`` passes no constants), its process noise
  must be a full-rank Q (it takes a Cholesky factor of Q, while our P_proc of eq. 30 has rank 7), and its QR
  weights the centre point by |Wc[0]| where Alg. 5 downdates by Wc[0] < 0 (docs/references.md).  So the
  comparison runs both filters on the additive-noise model x_{k+1} = f(x_k) + N(0, Q), y = x[rows] + N(0, R)
  with a fixed full-rank Q and those constants.  The time updates agree (means to rounding, covariances to
  1e-11, to rounding once the centre-point term is accounted for) when pykalman's predict is given the lower
  factor of Q; its ``filter_update`` gives it scipy's upper factor U and so adds U U^T, which is not Q.
  pykalman's measurement update does not agree: it solves the gain with
  the transposed triangular factor, K = P_xy (S S^T)^-1 where P_yy = S^T S, and downdates by K S instead of
  K S^T, so on correlated innovations (markers sharing one rotation) its downdate loses positive
  definiteness within a few steps.  Its speed is timed from one fixed state per repeat for that reason.
"""

from __future__ import annotations

from time import perf_counter

import numpy as np
from filterpy.kalman import MerweScaledSigmaPoints
from filterpy.kalman import UnscentedKalmanFilter as FilterpyUKF
from pykalman.sqrt import AdditiveUnscentedKalmanFilter
from pykalman.sqrt.unscented import Moments, moments2points, unscented_filter_predict

from poseintegrity.tracking.filter.model import (
    centred, process_model, process_model_reference, process_noise_sqrt, state_dim,
)
from poseintegrity.params.track import FilterParams
from poseintegrity.tracking.filter.srukf import SquareRootUKF
from poseintegrity.tracking.filter.ukf import UnscentedKalmanFilter


def filterpy_filter(markers_body: np.ndarray, fp: FilterParams):
    """filterpy's UnscentedKalmanFilter on our model, all markers and the gyro measured.

    Returns (ukf, step) where step(z, dt) runs one predict + update.
    """
    n = len(markers_body)
    N = state_dim(n)
    kappa = 3.0 - N if fp.kappa is None else fp.kappa
    points = MerweScaledSigmaPoints(N, fp.alpha, fp.beta, kappa)
    ukf = FilterpyUKF(N, 3 * n + 3, fp.dt, lambda x: x[: 3 * n + 3], lambda x, dt: process_model_reference(x, dt, markers_body), points)
    ukf.R = np.diag(np.r_[np.full(3 * n, fp.sigma_r**2), np.full(3, fp.sigma_omega**2)])
    ell = centred(markers_body)

    def step(z: np.ndarray, dt: float) -> None:
        B = process_noise_sqrt(ukf.x, dt, ell, fp.sigma_c, fp.sigma_alpha)
        ukf.Q = B @ B.T
        ukf.predict(dt=dt)
        ukf.update(z)

    return ukf, step


def additive_model(markers_body: np.ndarray, fp: FilterParams, q_std: float) -> tuple[FilterParams, np.ndarray, np.ndarray]:
    """The additive-noise comparison model: (constants alpha 1, beta 0, kappa 3 - N as pykalman uses them,
    Q (N, N) = eq. 30 at rest + q_std^2 I (full rank), R (3n + 3, 3n + 3) of eq. 16)."""
    n = len(markers_body)
    N = state_dim(n)
    settings = fp.model_copy(update={"alpha": 1.0, "beta": 0.0, "kappa": None})
    x0 = np.r_[(markers_body + [0.0, 0.0, 0.45]).ravel(), np.zeros(6)]
    B = process_noise_sqrt(x0, fp.dt, centred(markers_body), fp.sigma_c, fp.sigma_alpha)
    Q = B @ B.T + q_std**2 * np.eye(N)
    R = np.diag(np.r_[np.full(3 * n, fp.sigma_r**2), np.full(3, fp.sigma_omega**2)])
    return settings, Q, R


def pykalman_step(markers_body: np.ndarray, dt: float, Q: np.ndarray, R: np.ndarray):
    """step(mean, cov, z) -> (mean, cov): one predict + update (``filter_update``) of pykalman's SR-UKF."""
    n = len(markers_body)
    ell = centred(markers_body)
    kf = AdditiveUnscentedKalmanFilter(
        transition_functions=lambda x: process_model(x[:, None], dt, ell)[:, 0],
        observation_functions=lambda x: x[: 3 * n + 3],
        transition_covariance=Q,
        observation_covariance=R,
    )
    return lambda mean, cov, z: kf.filter_update(mean, cov, z)


def correlated_state(markers_body: np.ndarray, settings: FilterParams, rng: np.random.Generator) -> SquareRootUKF:
    """An SR-UKF at a turning state (omega (0.5, -0.3, 0.8) rad/s) with a full, correlated covariance."""
    f = SquareRootUKF(markers_body, settings)
    f.initialize(markers_body + [0.0, 0.0, 0.45], omega=np.array([0.5, -0.3, 0.8]))
    A = rng.normal(0.0, 1e-3, (f.N, f.N))
    f.S = np.linalg.cholesky(f.covariance() + A @ A.T)
    return f


def pykalman_time_update(markers_body: np.ndarray, fp: FilterParams, rng: np.random.Generator, q_std: float = 1e-3) -> dict[str, float]:
    """One time update (Alg. 5, "State Update") of our SR-UKF and of pykalman's on the additive model.

    Returns the largest difference of the means, of the covariances, and of the covariances once pykalman's
    centre-point term is accounted for: its QR weights X_0 - x^- by |Wc[0]| where Alg. 5 downdates by
    Wc[0] < 0, so its covariance is ours + 2 |Wc[0]| d d^T with d = f(x) - x^-.
    """
    settings, Q, R = additive_model(markers_body, fp, q_std)
    ours = correlated_state(markers_body, settings, rng)
    x0, S0 = ours.x.copy(), ours.S.copy()
    B = np.linalg.cholesky(Q)
    ours.predict(fp.dt, noise_sqrt=B)
    points = moments2points(Moments(x0, S0.T))  # pykalman carries the upper factor: P = S2^T S2
    # the noise factor goes in as the lower B: pykalman appends its columns, adding B B^T (filter_update passes
    # scipy's upper Cholesky factor U of Q instead and so adds U U^T, which is not Q)
    _, moments = unscented_filter_predict(lambda x: process_model(x[:, None], fp.dt, ours.ell)[:, 0], points, sigma2_transition=B)
    theirs = moments.covariance.T @ moments.covariance
    d = process_model(x0[:, None], fp.dt, ours.ell)[:, 0] - ours.x
    return {
        "mean": float(np.abs(moments.mean - ours.x).max()),
        "covariance": float(np.abs(theirs - ours.covariance()).max()),
        "covariance_after_centre_term": float(np.abs(theirs - 2 * abs(ours.Wc[0]) * np.outer(d, d) - ours.covariance()).max()),
    }


def _mean_time_ms(fn, repeats: int) -> float:
    fn()  # warm-up (numba compilation, caches)
    start = perf_counter()
    for _ in range(repeats):
        fn()
    return (perf_counter() - start) / repeats * 1000.0


def filter_speed(markers_body: np.ndarray, fp: FilterParams, repeats: int, rng: np.random.Generator) -> dict[str, float]:
    """Mean time (ms) of one predict + update (all markers + gyro) of the SR-UKF, the plain UKF, filterpy and
    pykalman (on the additive model) measured in the same run, and the SR-UKF's speed-up over each peer."""
    n = len(markers_body)
    markers = markers_body + np.array([0.0, 0.0, 0.45])
    z = np.r_[(markers + rng.normal(0, 0.001, markers.shape)).ravel(), rng.normal(0, 0.5, 3)]
    observed = np.ones(n, dtype=bool)
    times = {}
    for name, cls in [("srukf", SquareRootUKF), ("ukf", UnscentedKalmanFilter)]:
        f = cls(markers_body, fp)
        f.initialize(markers)
        times[name] = _mean_time_ms(lambda f=f: (f.predict(fp.dt), f.update(z, observed, True)), repeats)
    ukf, step = filterpy_filter(markers_body, fp)
    ukf.x = np.r_[markers.ravel(), np.zeros(6)]
    ukf.P = np.diag(np.r_[np.full(3 * n, fp.sigma_r**2), np.full(3, fp.init_std_omega**2), np.full(3, fp.init_std_velocity**2)])
    times["filterpy"] = _mean_time_ms(lambda: step(z, fp.dt), max(repeats // 5, 1))
    _, Q, R = additive_model(markers_body, fp, 1e-3)
    pk = pykalman_step(markers_body, fp.dt, Q, R)
    start = correlated_state(markers_body, fp, rng)  # every repeat from the same state: pykalman's update is unstable

    def pykalman_once():
        with np.errstate(all="ignore"):  # its downdate fails on this model (see the module docstring); same work
            pk(start.x, start.covariance(), z)

    times["pykalman"] = _mean_time_ms(pykalman_once, max(repeats // 5, 1))
    times["speedup_vs_filterpy"] = times["filterpy"] / times["srukf"]
    times["speedup_vs_pykalman"] = times["pykalman"] / times["srukf"]
    return times
