"""theta_p for all thresholds at once (predictors.boundaries) against the scalar reference envelope_boundary and analytic crossings."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from scalar_boundary import envelope_boundary
from poseintegrity.artifact_models.base_functions import emg
from poseintegrity.prediction import boundaries

THRESHOLDS = np.arange(4.0, 101.0)
N_GRID = 256  # scan points of these tests (any n_grid finds these crossings; the property test varies it)


@settings(deadline=None, max_examples=30)
@given(
    alpha=st.floats(500.0, 5000.0), K=st.floats(2.0, 20.0), mu=st.floats(-4.0, 4.0),
    n_grid=st.sampled_from([64, 256]),
)  # fmt: skip
def test_same_answers_as_envelope_boundary_on_emg_curves(alpha, K, mu, n_grid):
    def f(theta):
        return emg(theta, alpha, K, mu)

    found = boundaries(f, THRESHOLDS, 2.25, 45.0, n_grid)
    for n_t, theta_p, status in zip(THRESHOLDS, found.theta_p, found.status, strict=True):
        reference = envelope_boundary(f, n_t, 2.25, 45.0, n_scan=n_grid)
        assert status == reference.status
        assert theta_p == pytest.approx(reference.theta_p, abs=1e-7)


def test_exponential_decay_crosses_where_the_logarithm_says():
    a, tau = 200.0, 15.0  # n = a exp(-theta / tau) = n_t at theta = tau ln(a / n_t)
    found = boundaries(lambda t: a * np.exp(-t / tau), THRESHOLDS, 0.0, 45.0, N_GRID)
    inside = tau * np.log(a / THRESHOLDS) <= 45.0
    np.testing.assert_allclose(found.theta_p[inside], tau * np.log(a / THRESHOLDS[inside]), atol=1e-8)
    assert set(found.status[inside]) == {"root"} and set(found.status[~inside]) == {"censored"}
    assert np.all(found.theta_p[~inside] == 45.0)


def test_first_crossing_of_a_non_monotone_curve_matches_brentq_on_its_first_bracket():
    def f(t):
        return 60.0 + 40.0 * np.cos(t / 3.0)  # falls to 20 at 3 pi, back up to 100 at 6 pi

    found = boundaries(f, np.array([50.0]), 0.0, 30.0, N_GRID)
    assert found.theta_p[0] == pytest.approx(brentq(lambda t: f(t) - 50.0, 0.0, 3.0 * np.pi), abs=1e-8)


def test_statuses_below_at_start_censored_non_finite_and_bad_threshold():
    def f(t):
        return np.where(t < 30.0, 100.0 - t, np.nan)  # falls to 70 at 30, then NaN

    found = boundaries(f, np.array([120.0, 80.0, 50.0, np.nan]), 0.0, 45.0, N_GRID)
    assert list(found.status) == ["below_at_start", "root", "non_finite", "bad_threshold"]
    assert found.theta_p[0] == 0.0 and found.theta_p[1] == pytest.approx(20.0, abs=1e-8)
    assert found.theta_p[2] == envelope_boundary(f, 50.0, 0.0, 45.0).theta_p and np.isnan(found.theta_p[3])
    assert boundaries(lambda t: 100.0 - t, np.array([10.0]), 0.0, 45.0, N_GRID).status[0] == "censored"


def test_empty_range_raises():
    with pytest.raises(ValueError, match="empty search range"):
        boundaries(lambda t: t, THRESHOLDS, 5.0, 5.0, N_GRID)
