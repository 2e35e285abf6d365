"""NextStepSupervisor: bad input raises clearly; collecting, continuing and stopping as III-E says."""

from __future__ import annotations

import numpy as np
import pytest

from poseintegrity import PoseIntegrityError
from poseintegrity.artifact_models.base_functions import emg
from poseintegrity.artifact_models.fitted import FIT_STATUSES
from poseintegrity.prediction import NO_FIT, NextStepSupervisor

STOPS = 2.25 * np.arange(20)  # IV-D: the first stop is the model view


def counts(theta: float, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng([seed, int(theta * 100)])
    return np.maximum(emg(np.full(4, theta), 3000.0, 8.0, -1.0) + rng.normal(0.0, 5.0, 4), 0.0)


def make(tiny, **kwargs) -> NextStepSupervisor:
    return NextStepSupervisor.from_params(tiny, "arc", n_t=30.0, theta_b=2.25, rng=np.random.default_rng(0), **kwargs)


def test_the_supervisor_of_the_params(tiny):
    supervisor = make(tiny)
    assert (supervisor.theta_end, supervisor.first_stops) == (tiny.protocol.range_end("arc"),
                                                              tiny.protocol.stops_sampled("arc"))  # fmt: skip
    assert (supervisor.model, supervisor.n_grid) == (tiny.predict.models.next_step, tiny.predict.n_grid)
    assert supervisor.fit == tiny.fit and supervisor.uncertainty is None
    assert make(tiny, with_interval=True).uncertainty == tiny.predict.uncertainty


def test_bad_input_raises_with_a_clear_message(tiny):
    supervisor = make(tiny)
    with pytest.raises(PoseIntegrityError, match="theta: expected a finite number"):
        supervisor.update(float("nan"), 100.0)
    with pytest.raises(PoseIntegrityError, match="n_inliers: entries must be finite"):
        supervisor.update(2.25, [100.0, np.nan])
    with pytest.raises(PoseIntegrityError, match="n_inliers: expected one or more counts >= 0"):
        supervisor.update(2.25, [100.0, -1.0])
    supervisor.update(4.5, 100.0)
    with pytest.raises(PoseIntegrityError, match="theta must not decrease"):
        supervisor.update(2.25, 100.0)
    with pytest.raises(ValueError, match="needs an uncertainty method"):
        NextStepSupervisor(n_t=30.0, theta_b=2.25, theta_end=45.0, fit=tiny.fit, rng=np.random.default_rng(0),
                           model="emg", first_stops=4, n_grid=64, stop_on_lower_bound=True)  # fmt: skip


def test_collects_first_then_stops_before_the_envelope_edge(tiny):
    supervisor = make(tiny)
    first = tiny.protocol.stops_sampled("arc")
    decisions = [supervisor.update(theta, counts(theta)) for theta in STOPS[: first - 1]]
    assert all(d.proceed and d.status == "collecting" and np.isnan(d.theta_p) for d in decisions)
    assert {d.fit_status for d in decisions} == {NO_FIT}
    for theta in STOPS[first - 1:]:
        decision = supervisor.update(theta, counts(theta))
        assert np.isfinite(decision.theta_p) and decision.fit_status in FIT_STATUSES
        if not decision.proceed:
            assert decision.theta_p < theta + 2.25  # III-E's stop rule
            break
    else:
        pytest.fail("the supervisor never stopped although the counts fall below n_t = 30 near 27 deg")


def test_stopping_on_the_lower_bound_is_never_later(tiny):
    def stop_angle(**kwargs) -> float:
        supervisor = make(tiny, **kwargs)
        for theta in STOPS:
            decision = supervisor.update(theta, counts(theta, seed=3))
            if not decision.proceed:
                return theta
        return STOPS[-1]

    plain = stop_angle(with_interval=True)
    assert stop_angle(stop_on_lower_bound=True) <= plain
