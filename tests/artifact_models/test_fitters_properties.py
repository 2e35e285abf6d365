"""Property tests: every fitter survives random decays, flat data, one distinct theta, NaN and negative counts.

Whatever the samples, a fit returns a FittedModel whose predictions are finite, whose status agrees with its
reason, which uses the fallback line exactly when its status is "fallback", and whose "ok" is physical over
[first stop, range end] (no count below zero, a decay from the first stop, no absurd level); a least squares fit
with a curve is never worse than its own starting values.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from poseintegrity.artifact_models import BASE_FUNCTIONS, FIT_STATUSES, fit_model
from poseintegrity.params.model_names import MODEL_NAMES
from poseintegrity.artifact_models.fitted import FALLBACK, OK, valid_samples

END = 45.0  # samples are drawn over an arc of 45 deg; the range end passed to every fit
GRID = np.linspace(0.0, END, 91)


@st.composite
def samples(draw) -> tuple[np.ndarray, np.ndarray]:
    """(theta, n_inliers): k stops x m images of a random decay, flat level or single theta, then corrupted."""
    k = draw(st.integers(1, 8))
    m = draw(st.integers(1, 6))
    step = draw(st.floats(0.5, END / k))  # every stop within the range end (a sample beyond it is refused, naming theta_end)
    theta = np.repeat(step * np.arange(1, k + 1), m)
    kind = draw(st.sampled_from(["decay", "flat", "zeros"]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    if kind == "decay":
        name = draw(st.sampled_from(sorted(BASE_FUNCTIONS)))
        p0, lower, upper = BASE_FUNCTIONS[name].initial_guess(np.array([0.0, 45.0]), np.array([300.0, 5.0]))
        p = rng.uniform(lower, np.minimum(upper, 10.0 * np.abs(p0) + 10.0))  # a random curve within bounds
        n = BASE_FUNCTIONS[name].f(theta, *p) + rng.normal(0.0, draw(st.floats(0.0, 20.0)), theta.size)
    elif kind == "flat":
        n = np.full(theta.size, draw(st.floats(0.0, 500.0))) + rng.normal(0.0, draw(st.floats(0.0, 5.0)), theta.size)
    else:
        n = np.zeros(theta.size)
    n = np.round(n)
    n_nan = draw(st.integers(0, theta.size))
    n[rng.choice(theta.size, n_nan, replace=False)] = np.nan
    if draw(st.booleans()):
        theta[rng.choice(theta.size, draw(st.integers(0, theta.size)), replace=False)] = np.nan
    if draw(st.booleans()):
        n[rng.choice(theta.size, draw(st.integers(0, theta.size)), replace=False)] *= -1.0
    return theta, n


def check_fitted(model, name, theta, n):
    theta_ok, n_ok = valid_samples(theta, n)
    assert model.name == name
    assert model.n_samples == theta_ok.size
    prediction = model.predict(GRID)
    assert prediction.shape == GRID.shape and np.all(np.isfinite(prediction))
    assert model.status in FIT_STATUSES and (model.status == OK) == (model.reason == "ok")
    if model.status == FALLBACK:
        np.testing.assert_array_equal(prediction, model.fallback.predict(GRID))
    if np.unique(theta_ok).size < 2:
        assert model.status == FALLBACK and ("distinct" in model.reason or "no valid" in model.reason)
    if model.status == OK:  # physical from the first sample to the range end, at the grid points of the check
        f = model.predict(np.linspace(theta_ok.min(), END, 181))
        assert f.min() >= -0.5 and (f[-1] < f[0] or f.max() < 0.5)
    return theta_ok, n_ok


@settings(deadline=None, max_examples=50)
@given(data=samples())
def test_base_function_fits_never_raise_and_flag_failures(tiny_fit, data):
    theta, n = data
    for name, base in BASE_FUNCTIONS.items():
        model = base.fit(theta, n, theta_end=END, max_nfev=tiny_fit.max_nfev)
        theta_ok, n_ok = check_fitted(model, name, theta, n)
        if model.has_curve:  # least squares never ends worse than where it started
            p0 = base.initial_guess(theta_ok, n_ok)[0]
            sse_fit = np.sum((model.predict(theta_ok) - n_ok) ** 2)
            sse_start = np.sum((base.f(theta_ok, *p0) - n_ok) ** 2)
            assert sse_fit <= sse_start * (1.0 + 1e-9) + 1e-9


@settings(deadline=None, max_examples=15)
@given(data=samples())
def test_mlp_fits_never_raise_and_flag_failures(tiny_fit, data):
    theta, n = data
    for name in ("mlp_scratch", "mlp_pretrained"):
        model = fit_model(name, theta, n, theta_end=END, params=tiny_fit, rng=np.random.default_rng(0))
        check_fitted(model, name, theta, n)


def test_every_model_name_dispatches(tiny_fit):
    theta = np.repeat(2.25 * np.arange(1, 5), 5)
    n = 300.0 * np.exp(-theta / 10.0)
    for name in MODEL_NAMES:
        assert fit_model(name, theta, n, theta_end=END, params=tiny_fit, rng=np.random.default_rng(0)).name == name
