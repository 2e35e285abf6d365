"""theta_p where the artifact model falls to n_t: known roots, the documented edge answers, invariants."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poseintegrity.artifact_models import EMG, emg
from scalar_boundary import envelope_boundary
from poseintegrity.artifact_models.base_functions import exponential


def test_exponential_decay_root_is_analytic():
    a, tau, n_t = 240.0, 9.0, 15.0
    boundary = envelope_boundary(lambda t: exponential(t, a, tau), n_t, 0.0, 45.0)
    assert boundary.status == "root"
    assert boundary.theta_p == pytest.approx(tau * np.log(a / n_t), abs=1e-8)


def test_never_reaching_n_t_is_censored_at_the_range_end():
    boundary = envelope_boundary(lambda t: exponential(t, 240.0, 100.0), 15.0, 0.0, 45.0)
    assert (boundary.theta_p, boundary.status) == (45.0, "censored")


def test_already_below_at_the_start():
    boundary = envelope_boundary(lambda t: exponential(t, 10.0, 5.0), 15.0, 2.25, 45.0)
    assert (boundary.theta_p, boundary.status) == (2.25, "below_at_start")


def test_the_first_downward_crossing_is_the_boundary():
    # 20 + (theta - 10)^2 - 25 crosses n_t = 20 at 5 and at 15 (dips, then rises): the robot meets 5 first
    boundary = envelope_boundary(lambda t: (t - 10.0) ** 2 - 5.0, 20.0, 0.0, 45.0)
    assert boundary.status == "root"
    assert boundary.theta_p == pytest.approx(5.0, abs=1e-8)


def test_non_finite_model_stops_at_the_last_finite_point():
    def predict(t):
        return np.where(t < 20.0, 100.0, np.nan)

    boundary = envelope_boundary(predict, 15.0, 0.0, 45.0, n_scan=91)  # grid step 0.5 deg
    assert boundary.status == "non_finite"
    assert boundary.theta_p == pytest.approx(19.5)


def test_empty_range_is_a_programming_error():
    with pytest.raises(ValueError, match="empty search range"):
        envelope_boundary(lambda t: t, 1.0, 10.0, 10.0)


def test_boundary_of_a_fitted_emg_model(tiny_fit):
    theta = np.repeat(2.25 * np.arange(1, 5), 10)  # the long range predictor's 4 stops
    model = EMG.fit(theta, emg(theta, 3000.0, 8.0, 1.0), theta_end=45.0, max_nfev=tiny_fit.max_nfev)
    boundary = envelope_boundary(model.predict, 15.0, 0.0, 45.0)
    assert boundary.status == "root"
    assert model.predict(np.array([boundary.theta_p]))[0] == pytest.approx(15.0, abs=1e-6)
    assert boundary.theta_p == pytest.approx(
        envelope_boundary(lambda t: emg(t, 3000.0, 8.0, 1.0), 15.0, 0.0, 45.0).theta_p, abs=1e-4
    )


@settings(deadline=None, max_examples=50)
@given(
    alpha=st.floats(100.0, 1e5),
    K=st.floats(0.05, 100.0),
    mu=st.floats(-20.0, 40.0),
    n_t=st.floats(0.5, 100.0),
)
def test_boundary_invariants_on_random_emg_curves(alpha, K, mu, n_t):
    n_scan = 256

    def f(t):
        return emg(t, alpha, K, mu)

    boundary = envelope_boundary(f, n_t, 0.0, 45.0, n_scan=n_scan)
    grid = np.linspace(0.0, 45.0, n_scan)
    before = grid[grid < boundary.theta_p]
    assert 0.0 <= boundary.theta_p <= 45.0
    assert np.all(f(before) > n_t)  # no grid point before theta_p is outside the envelope
    if boundary.status == "root":  # brentq's root is within 1e-9: f - n_t changes sign across it
        assert f(np.array([boundary.theta_p - 1e-6]))[0] > n_t >= f(np.array([boundary.theta_p + 1e-6]))[0]
    elif boundary.status == "censored":
        assert np.all(f(grid) > n_t)
    else:
        assert boundary.status == "below_at_start" and f(np.array([0.0]))[0] <= n_t
