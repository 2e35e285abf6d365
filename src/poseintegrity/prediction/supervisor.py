"""The next-step predictor as a component of a robot loop (Windsor et al. III-E; the live trials of V-C).

    params = load_params()                          # the published defaults, or load_params("mine.yaml")
    supervisor = NextStepSupervisor.from_params(params, "arc", n_t=15, theta_b=2.25, rng=rng)
    for theta, n_inliers in stops:                  # the robot pauses at each stop and localizes
        decision = supervisor.update(theta, n_inliers)
        if not decision.proceed:
            break                                   # failure predicted before the next step: stop here

The first stop is the model view (theta = 0, IV-D). Until ``first_stops`` stops are seen the supervisor lets the
robot move on (it cannot fit yet: the robot starts inside the envelope, III-E). From then on it refits the
artifact model on every stop so far and stops the robot where it is when theta_p < theta_i + theta_b (or, with
``stop_on_lower_bound``, when the lower end of the prediction interval on theta_p is): the robot's safe path ends
at that stop, as in the offline evaluation :func:`poseintegrity.prediction.next_step` (V-B).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from poseintegrity.errors import ArgumentError, check_array, check_scalar
from poseintegrity.artifact_models import fit_model
from poseintegrity.params.fit import FitParams
from poseintegrity.artifact_models.fitted import MAX_THETA
from poseintegrity.params.predict import PredictParams, UncertaintyParams
from poseintegrity.prediction.predictors import NO_FIT, envelope_prediction, next_step_stops
from poseintegrity.prediction.uncertainty import prediction_interval


MAX_COUNT = 1e7  # inlier counts: more matches than a 100-megapixel image has keypoints is not a count


@dataclass(frozen=True)
class Decision:
    """What the supervisor says after a stop.

    proceed : True: move on to the next step;  theta_p : predicted envelope boundary (NaN before the first fit)
    interval : (lower, upper) on theta_p (NaN without one);  status : theta_p's status ("collecting" before the
    first fit);  fit_status : the fit's ok / at_bound / non_physical / fallback (artifact_models/fitted.py; "no_fit"
    while collecting): a flagged fit is still used, as the robot has no other;  reason : the fit's "ok" or what
    was found
    """

    proceed: bool
    theta_p: float
    interval: tuple[float, float]
    status: str
    fit_status: str
    reason: str


@dataclass
class NextStepSupervisor:
    """Next-step supervision over one trajectory; theta in deg (arcs) or mm (lines), increasing.

    n_t : inlier threshold;  theta_b : step size (the distance to the next stop);  theta_end : end of the range
    model : artifact model name (``predict.models.next_step``);  first_stops : stops needed before the first fit
    (``protocol.sampled_stops``);  n_grid : grid of the theta_p scan (``predict.n_grid``); :meth:`from_params` reads
    all three from the params
    uncertainty : how to put an interval on theta_p (None: no interval);  stop_on_lower_bound : use its lower end
    """

    n_t: float
    theta_b: float
    theta_end: float
    fit: FitParams
    rng: np.random.Generator
    model: str
    first_stops: int
    n_grid: int
    uncertainty: UncertaintyParams | None = None
    stop_on_lower_bound: bool = False
    theta: list[float] = field(default_factory=list, init=False)  # every image's theta so far
    n_inliers: list[float] = field(default_factory=list, init=False)

    def __post_init__(self) -> None:
        if self.stop_on_lower_bound and self.uncertainty is None:
            raise ArgumentError("stop_on_lower_bound needs an uncertainty method (uncertainty=None)")
        if not (np.isfinite(self.n_t) and self.theta_b > 0 and np.isfinite(self.theta_end)):
            raise ArgumentError(f"need a finite n_t, theta_b > 0 and a finite theta_end; got {self.n_t}, "
                             f"{self.theta_b}, {self.theta_end}")  # fmt: skip

    @classmethod
    def from_params(cls, params, trajectory: str, *, n_t: float, theta_b: float, rng: np.random.Generator,
                    with_interval: bool = False, stop_on_lower_bound: bool = False) -> NextStepSupervisor:  # fmt: skip
        """The supervisor of params.yaml (:class:`poseintegrity.config.Params`) on a trajectory type ("arc" or
        "line"): its range end and sampled stops from ``protocol``, model and scan grid from ``predict``, the fit from
        ``fit``; ``with_interval`` (or ``stop_on_lower_bound``) adds ``predict.uncertainty``'s interval."""
        predict: PredictParams = params.predict
        return cls(
            n_t=n_t, theta_b=theta_b, theta_end=params.protocol.range_end(trajectory), fit=params.fit, rng=rng,
            model=predict.models.next_step, first_stops=params.protocol.stops_sampled(trajectory),
            n_grid=predict.n_grid, uncertainty=predict.uncertainty if with_interval or stop_on_lower_bound else None,
            stop_on_lower_bound=stop_on_lower_bound,
        )  # fmt: skip

    def update(self, theta: float, n_inliers: float | np.ndarray) -> Decision:
        """Add the inlier counts of the images taken at stop ``theta`` and decide (III-E).

        theta : float, the current stop (>= the previous one; equal = more images at the same stop)
        n_inliers : float or (m,) counts of the images at this stop (0 for a frame that failed to localize)
        Raises :class:`~poseintegrity.errors.ArgumentError` on a theta that is not a finite number within 1e6, on
        counts that are not one or more finite numbers in [0, 1e7], or on a theta smaller than the previous stop.
        """
        theta = check_scalar("theta", theta, low=-MAX_THETA, high=MAX_THETA)
        counts = np.atleast_1d(check_array("n_inliers", n_inliers, max_abs=MAX_COUNT))
        if counts.ndim != 1 or counts.size == 0 or (counts < 0).any():
            raise ArgumentError(f"n_inliers: expected one or more counts >= 0 (0 for a failed frame), got {n_inliers!r:.80}")
        if self.theta and theta < self.theta[-1]:
            raise ArgumentError(f"theta must not decrease: {theta} after {self.theta[-1]}")
        self.theta.extend([float(theta)] * counts.size)
        self.n_inliers.extend(counts.tolist())
        samples_theta, samples_n = np.asarray(self.theta), np.asarray(self.n_inliers)
        nan2 = (float("nan"), float("nan"))
        if np.unique(samples_theta).size < self.first_stops:
            return Decision(True, float("nan"), nan2, "collecting", NO_FIT, "collecting the first stops")
        fitted = fit_model(
            self.model, samples_theta, samples_n, theta_end=self.theta_end, params=self.fit, rng=self.rng
        )
        n_t = np.array([float(self.n_t)])
        found = envelope_prediction(fitted.predict, n_t, samples_theta[0], self.theta_end, self.n_grid)
        theta_p, interval = float(found.theta_p[0]), nan2
        if self.uncertainty is not None:
            bounds = prediction_interval(
                self.model, fitted, samples_theta, samples_n, n_t, theta_end=self.theta_end, fit=self.fit,
                uncertainty=self.uncertainty, rng=self.rng, n_grid=self.n_grid,
            )  # fmt: skip
            interval = (float(bounds.lower[0]), float(bounds.upper[0]))
        # a NaN lower bound (no interval) never lets the robot on: NaN < x is False, so compare the negation
        guard = interval[0] if self.stop_on_lower_bound else theta_p
        proceed = not bool(next_step_stops(np.array([guard]), float(theta), self.theta_b)[0]) and np.isfinite(guard)
        return Decision(bool(proceed), theta_p, interval, str(found.status[0]), fitted.status, fitted.reason)
