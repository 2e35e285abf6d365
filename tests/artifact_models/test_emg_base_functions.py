"""Eq. 1 against scipy and mpmath, its Jacobian, the least squares fits of every base function and their status."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
from scipy.optimize import curve_fit
from scipy.stats import exponnorm

from poseintegrity.artifact_models import BASE_FUNCTIONS, EMG, FallbackLine, emg, emg_pdf
from poseintegrity.artifact_models.base_functions import LONGEST_DECAY, emg_jacobian
from poseintegrity.artifact_models.fitted import AT_BOUND, FALLBACK, NON_PHYSICAL, OK
from poseintegrity.artifact_models.series import dataset_series

THETA = np.repeat(2.25 * np.arange(1, 21), 10)  # an arc dataset: 20 stops x 10 images, deg
FIRST4 = np.repeat(2.25 * np.arange(4), 10)  # the 4 stops an arc robot samples (IV-A), from the model view


@pytest.mark.parametrize("K", [0.01, 0.05, 0.3, 1.0, 3.0, 10.0, 100.0, 1000.0])
def test_emg_pdf_matches_scipy_exponnorm(K):
    x = np.linspace(-8.0, 60.0, 1361)
    reference = exponnorm.pdf(x, K)
    assert np.all(np.isfinite(emg_pdf(x, K)))
    resolved = reference > 1e-290  # compare where the reference is a normal float
    np.testing.assert_allclose(emg_pdf(x, K)[resolved], reference[resolved], rtol=1e-9, atol=0.0)


@pytest.mark.parametrize("K", [1e-3, 0.01, 0.05])
def test_emg_pdf_matches_eq1_in_high_precision_at_small_K(K):
    mpmath.mp.dps = 60

    def eq1(x: float) -> float:  # eq. (1) with alpha = 1, mu = 0; erfc of eq. (2)
        x, k = mpmath.mpf(x), mpmath.mpf(K)
        return float(1 / (2 * k) * mpmath.exp(1 / (2 * k**2) - x / k) * mpmath.erfc(-(x - 1 / k) / mpmath.sqrt(2)))

    x = np.linspace(-6.0, 8.0, 29)
    np.testing.assert_allclose(emg_pdf(x, K), [eq1(v) for v in x], rtol=1e-12)


def test_scaled_emg_is_alpha_times_shifted_exponnorm():
    np.testing.assert_allclose(emg(THETA, 2500.0, 7.5, 3.0), 2500.0 * exponnorm.pdf(THETA - 3.0, 7.5), rtol=1e-9)


@pytest.mark.parametrize("p", [(2500.0, 7.5, 3.0), (40.0, 0.2, 10.0), (1e4, 60.0, -20.0)])
def test_emg_jacobian_matches_finite_differences(p):
    h = 1e-6 * np.abs(p)  # central differences, one parameter at a time
    numeric = np.stack(
        [(emg(THETA, *(p + h[j] * e)) - emg(THETA, *(p - h[j] * e))) / (2 * h[j]) for j, e in enumerate(np.eye(3))],
        axis=1,
    )
    np.testing.assert_allclose(emg_jacobian(THETA, *p), numeric, rtol=1e-6, atol=1e-9 * np.abs(numeric).max())


def test_emg_fit_recovers_noiseless_parameters(fit_base):
    n = emg(THETA, 3000.0, 8.0, 2.5)
    fit = fit_base(EMG, THETA, n)
    assert fit.status == OK and fit.reason == "ok"
    np.testing.assert_allclose([fit.params[k] for k in ("alpha", "K", "mu")], [3000.0, 8.0, 2.5], rtol=1e-6)


def test_emg_fit_recovers_parameters_from_noisy_samples(fit_base):
    rng = np.random.default_rng(11)
    f = emg(THETA, 3000.0, 8.0, 10.0)  # peak inside the sampled range: alpha, K, mu all identifiable
    n = np.maximum(np.round(f + rng.normal(0.0, 2.0 + 0.1 * f)), 0.0)
    fit = fit_base(EMG, THETA, n)
    assert fit.params["alpha"] == pytest.approx(3000.0, rel=0.05)
    assert fit.params["K"] == pytest.approx(8.0, rel=0.05)
    assert fit.params["mu"] == pytest.approx(10.0, abs=0.5)
    # ... but counts that rise from ~0 at the first stop to a peak at 10 deg are no decay from the first stop (III-D)
    assert fit.status == NON_PHYSICAL and fit.reason.startswith("no decay")
    assert fit.predict(np.array([45.0]))[0] >= fit.predict(np.array([2.25]))[0]


@pytest.mark.filterwarnings("ignore::scipy.optimize.OptimizeWarning")  # curve_fit's covariance, not used
def test_least_squares_fit_is_scipys_curve_fit(fit_base):
    """The fit calls least_squares directly for its active_mask; it must land where curve_fit(trf) lands."""
    rng = np.random.default_rng(3)
    n = np.maximum(np.round(emg(FIRST4, 3000.0, 9.0, -1.0) + rng.normal(0.0, 4.0, FIRST4.size)), 0.0)
    for base in BASE_FUNCTIONS.values():
        p0, lower, upper = base.initial_guess(FIRST4, n)
        reference, _ = curve_fit(base.f, FIRST4, n, p0=p0, bounds=(lower, upper), method="trf",
                                 jac=base.jac or "2-point", x_scale="jac", max_nfev=400)  # fmt: skip
        np.testing.assert_array_equal(list(fit_base(base, FIRST4, n, max_nfev=400).params.values()), reference)


def test_emg_fit_recovers_the_curves_of_the_synthetic_datasets(artifacts_table, fit_base, protocol):
    """With the peak before the first stop only alpha * exp(mu / K) is identifiable: check K and the curve."""
    artifacts, truth = artifacts_table
    truth = truth.set_index(["dataset", "method"])
    for series in dataset_series(artifacts, "usac_magsac", protocol):
        fit = fit_base(EMG, series.theta, series.n_inliers, theta_end=series.theta_end)
        true = truth.loc[(series.dataset, "usac_magsac")]
        assert fit.status == OK, fit.reason
        assert fit.params["K"] == pytest.approx(true["K"], rel=0.1)
        f = emg(series.theta, true["alpha"], true["K"], true["mu"])
        rms_noise = np.sqrt(np.mean((2.0 + 0.1 * f) ** 2))  # the noise drawn: sd = 2 + 0.1 f
        assert np.sqrt(np.mean((fit.predict(series.theta) - f) ** 2)) < 0.3 * rms_noise


# (base function, true parameters inside the bounds its starting rule gives for THETA)
TRUE_PARAMS = {
    "emg": (3000.0, 8.0, 2.5),
    "exponential": (250.0, 12.0),
    "gaussian": (220.0, 3.0, 14.0),
    "logistic": (200.0, 18.0, 4.0),
    "power_law": (210.0, 15.0, 3.0),
}


@pytest.mark.parametrize("name", sorted(BASE_FUNCTIONS))
def test_each_base_function_recovers_its_own_noiseless_curve(name, fit_base):
    base = BASE_FUNCTIONS[name]
    p_true = TRUE_PARAMS[name]
    n = base.f(THETA, *p_true)
    p0, lower, upper = base.initial_guess(THETA, n)
    assert np.all(lower <= p0) and np.all(p0 <= upper) and np.all(lower < upper)
    assert np.all((lower <= p_true) & (p_true <= upper)), "test curve outside the bounds"
    fit = fit_base(base, THETA, n)
    assert fit.status == OK, fit.reason
    assert tuple(fit.params) == base.param_names
    np.testing.assert_allclose(list(fit.params.values()), p_true, rtol=1e-4)
    np.testing.assert_allclose(fit.predict(THETA), n, rtol=1e-6, atol=1e-6)


def test_fallback_line_is_the_least_squares_line_clipped_at_zero():
    theta = np.array([1.0, 2.0, 3.0, 4.0, 4.0])
    n = np.array([50.0, 41.0, 29.0, 22.0, 18.0])
    line = FallbackLine.fit(theta, n)
    slope, intercept = np.polyfit(theta, n, 1)
    assert (line.slope, line.intercept) == pytest.approx((slope, intercept), rel=1e-12)
    far = np.array([0.0, 100.0])
    np.testing.assert_allclose(line.predict(far), [intercept, 0.0])


def test_failed_fit_is_flagged_and_predicts_with_the_fallback(fit_base):
    theta = np.full(10, 4.5)
    n = np.arange(100.0, 110.0)
    fit = fit_base(EMG, theta, n)
    assert fit.status == FALLBACK and not fit.has_curve
    assert "1 distinct theta" in fit.reason
    assert np.isnan(fit.params["K"])
    np.testing.assert_allclose(fit.predict(np.array([0.0, 45.0])), [104.5, 104.5])


def test_invalid_samples_are_dropped_not_fitted(fit_base):
    n = emg(THETA, 3000.0, 8.0, 2.5)
    theta_bad = np.concatenate([THETA, [np.nan, 10.0, np.inf]])
    n_bad = np.concatenate([n, [100.0, -5.0, 3.0]])
    clean, dirty = fit_base(EMG, THETA, n), fit_base(EMG, theta_bad, n_bad)
    assert dirty.n_samples == THETA.size
    assert dirty.params == pytest.approx(clean.params, rel=1e-9)


def test_optimizer_budget_exhausted_is_flagged_with_the_optimizer_message(fit_base):
    n = emg(THETA, 3000.0, 8.0, 10.0)
    fit = fit_base(EMG, THETA, n, max_nfev=2)
    assert fit.status == FALLBACK
    assert fit.reason.startswith("least squares:") and "function evaluations" in fit.reason
    np.testing.assert_array_equal(fit.predict(THETA), fit.fallback.predict(THETA))


# Honest status: known answers on the 4 stops an arc robot samples


def test_a_clean_eq1_series_is_ok(fit_base):
    n = emg(FIRST4, 3000.0, 8.0, -2.0)  # decays from the model view (the EMG's mode ~1 deg before the first stop)
    for name in ("emg", "exponential", "logistic", "power_law"):
        fit = fit_base(BASE_FUNCTIONS[name], FIRST4, n)
        assert (fit.status, fit.reason) == (OK, "ok"), name


def test_a_fit_pushed_to_a_bound_is_flagged(fit_base):
    """Flat counts have no decay length: the exponential's tau runs to its cap, LONGEST_DECAY sampled spans."""
    n = np.full(FIRST4.size, 200.0) + np.tile([-2.0, 2.0], FIRST4.size // 2)
    fit = fit_base(BASE_FUNCTIONS["exponential"], FIRST4, n)
    span = FIRST4.max() - FIRST4.min()
    assert fit.status == AT_BOUND and "tau" in fit.reason and "(upper)" in fit.reason
    assert fit.params["tau"] == pytest.approx(LONGEST_DECAY * span, rel=1e-9)
    assert fit.has_curve  # a fit at a bound still predicts with its curve (what the predictor would act on)
    np.testing.assert_array_equal(fit.predict(THETA), fit.curve(THETA))


@pytest.mark.parametrize(("name", "status"), [("emg", AT_BOUND), ("exponential", AT_BOUND),
                                              ("gaussian", NON_PHYSICAL)])  # fmt: skip
def test_an_increasing_series_is_flagged(fit_base, name, status):
    """Counts growing with the viewing angle: eq. 1 and the exponential can only follow them by an ever longer decay
    (at its cap), the Gaussian by a peak past the range end (its count at 45 deg above the first stop's)."""
    n = 100.0 + 5.0 * FIRST4 + np.tile([-3.0, 3.0], FIRST4.size // 2)
    fit = fit_base(BASE_FUNCTIONS[name], FIRST4, n)
    assert fit.status == status, fit.reason
    if status == NON_PHYSICAL:
        assert "no decay" in fit.reason
        assert fit.predict(np.array([45.0]))[0] >= fit.predict(np.array([0.0]))[0]
