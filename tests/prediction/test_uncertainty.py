"""Prediction intervals on theta_p: the fit covariance against scipy's curve_fit, the bootstrap, failed fits."""

from __future__ import annotations

import numpy as np
import pytest

from poseintegrity.artifact_models import fit_model
from poseintegrity.artifact_models.base_functions import emg, emg_jacobian
from poseintegrity.prediction import bootstrap_interval, covariance_interval, envelope_prediction
from poseintegrity.prediction.uncertainty import parameter_covariance

N_T = np.arange(4.0, 101.0, 8.0)
THETA = np.repeat(2.25 * np.arange(1, 7), 5)


def noisy(seed: int = 0, scale: float = 8.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.maximum(emg(THETA, 3000.0, 8.0, -1.0) + rng.normal(0.0, scale, THETA.size), 0.0)


def test_parameter_covariance_is_the_least_squares_one(tiny_fit):
    # J P J^T / s^2 at the samples is the hat matrix J (J^T J)^+ J^T: a projection whose trace is the rank of J,
    # with the analytic eq. (1) Jacobian (independent of our finite differences). On the exponential tail of
    # eq. 1 alpha and mu trade off (rank 2): the pseudo-inverse keeps the band finite along that valley.
    n = noisy()
    fitted = fit_model("emg", THETA, n, theta_end=45.0, params=tiny_fit, rng=np.random.default_rng(0))
    p = [fitted.params[name] for name in ("alpha", "K", "mu")]
    J = emg_jacobian(THETA, *p)
    s2 = np.sum((n - emg(THETA, *p)) ** 2) / (THETA.size - 3)
    H = J @ parameter_covariance(fitted, THETA, n) @ J.T / s2
    assert np.trace(H) == pytest.approx(np.linalg.matrix_rank(J), rel=1e-3)
    np.testing.assert_allclose(H @ H, H, atol=1e-3)


def test_covariance_interval_brackets_theta_p_and_collapses_on_exact_data(tiny_fit):
    for n, collapsed in ((noisy(), False), (emg(THETA, 3000.0, 8.0, -1.0), True)):
        fitted = fit_model("emg", THETA, n, theta_end=45.0, params=tiny_fit, rng=np.random.default_rng(0))
        theta_p = envelope_prediction(fitted.predict, N_T, 2.25, 45.0, 256).theta_p
        interval = covariance_interval(fitted, THETA, n, N_T, 2.25, 45.0, 0.9, 256)
        assert interval.reason == "ok"
        assert np.all(interval.lower <= theta_p + 1e-9) and np.all(theta_p <= interval.upper + 1e-9)
        if collapsed:
            np.testing.assert_allclose(interval.lower, theta_p, atol=1e-4)
        else:
            assert np.any(interval.upper - interval.lower > 0.1)


def test_bootstrap_interval_is_ordered_and_reproducible(tiny_fit):
    n = noisy()

    def run(seed: int):
        return bootstrap_interval("emg", THETA, n, N_T, theta_end=45.0, fit=tiny_fit, level=0.9, n_bootstrap=10,
                                  rng=np.random.default_rng(seed), n_grid=128)  # fmt: skip

    first, again = run(1), run(1)
    assert first.reason == "ok" and np.all(first.lower <= first.upper)
    np.testing.assert_array_equal(first.lower, again.lower)


def test_failed_fits_give_no_interval_and_say_why(tiny_fit):
    theta, n = np.full(5, 2.25), np.full(5, 100.0)  # one distinct theta: the EMG cannot be fitted
    fitted = fit_model("emg", theta, n, theta_end=45.0, params=tiny_fit, rng=np.random.default_rng(0))
    interval = covariance_interval(fitted, theta, n, N_T, 2.25, 45.0, 0.9, 64)
    assert np.all(np.isnan(interval.lower)) and "no covariance" in interval.reason
    boot = bootstrap_interval("emg", theta, n, N_T, theta_end=45.0, fit=tiny_fit, level=0.9, n_bootstrap=3,
                              rng=np.random.default_rng(0), n_grid=64)  # fmt: skip
    assert np.all(np.isnan(boot.upper)) and "bootstrap refits fitted a curve" in boot.reason
