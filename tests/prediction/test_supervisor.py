"""NextStepSupervisor: bad input raises clearly; collecting, continuing and stopping as III-E says."""

from __future__ import annotations

import numpy as np
import pytest

from poseintegrity.artifact_models.base_functions import emg
from poseintegrity.prediction import NextStepSupervisor, UncertaintyParams

STOPS = 2.25 * np.arange(20)  # IV-D: the first stop is the model view


def counts(theta: float, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng([seed, int(theta * 100)])
    return np.maximum(emg(np.full(4, theta), 3000.0, 8.0, -1.0) + rng.normal(0.0, 5.0, 4), 0.0)


def make(tiny_fit, **kwargs) -> NextStepSupervisor:
    return NextStepSupervisor(n_t=30.0, theta_b=2.25, theta_end=45.0, fit=tiny_fit, rng=np.random.default_rng(0),
                              **kwargs)  # fmt: skip


def test_bad_input_raises_with_a_clear_message(tiny_fit):
    supervisor = make(tiny_fit)
    with pytest.raises(ValueError, match="theta must be finite"):
        supervisor.update(float("nan"), 100.0)
    with pytest.raises(ValueError, match="n_inliers must be finite"):
        supervisor.update(2.25, [100.0, np.nan])
    supervisor.update(4.5, 100.0)
    with pytest.raises(ValueError, match="theta must not decrease"):
        supervisor.update(2.25, 100.0)
    with pytest.raises(ValueError, match="needs an uncertainty method"):
        make(tiny_fit, stop_on_lower_bound=True)


def test_collects_first_then_stops_before_the_envelope_edge(tiny_fit):
    supervisor = make(tiny_fit)
    decisions = [supervisor.update(theta, counts(theta)) for theta in STOPS[:3]]
    assert all(d.proceed and d.status == "collecting" and np.isnan(d.theta_p) for d in decisions)
    for theta in STOPS[3:]:
        decision = supervisor.update(theta, counts(theta))
        assert np.isfinite(decision.theta_p)
        if not decision.proceed:
            assert decision.theta_p < theta + 2.25  # III-E's stop rule
            break
    else:
        pytest.fail("the supervisor never stopped although the counts fall below n_t = 30 near 27 deg")


def test_stopping_on_the_lower_bound_is_never_later(tiny_fit):
    def stop_angle(**kwargs) -> float:
        supervisor = make(tiny_fit, **kwargs)
        for theta in STOPS:
            decision = supervisor.update(theta, counts(theta, seed=3))
            if not decision.proceed:
                return theta
        return STOPS[-1]

    uncertainty = UncertaintyParams(method="covariance", level=0.9, n_bootstrap=2)
    plain = stop_angle(uncertainty=uncertainty)
    assert stop_angle(uncertainty=uncertainty, stop_on_lower_bound=True) <= plain
