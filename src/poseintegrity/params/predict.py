"""Schema of the ``predict`` section of ``params.yaml`` (stage 04, localization-envelope predictors).

The artifact models themselves are configured by the ``fit`` section (:class:`poseintegrity.params.fit.FitParams`:
least squares budget, MLP recipe); the range ends, the stops sampled before predicting and the tolerances by
``protocol``; the workers by ``parallel``. This section says how the predictors of Windsor et al. III-E use the
models and how the operating points are swept (IV-A, V). Every value is explicit in ``params.yaml`` (no default
here). Lengths in mm, angles in deg.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field, ValidationInfo, model_validator

from poseintegrity.params.fit import ModelName
from poseintegrity.params.model_names import LEAST_SQUARES_PARAMETERS as LEAST_SQUARES
from poseintegrity.params.model_names import distinct_theta_needed
from poseintegrity.schema import KeyRule, Seed, Section, distinct

IntervalMethod = Literal["covariance", "bootstrap"]
Rate = Annotated[float, Field(ge=0, le=1)]
GRID = 100_000  # upper bound of every sweep or scan size: a typo, not a grid, beyond it


class PredictorModels(Section):
    """Artifact model behind each predictor (a name of :data:`poseintegrity.params.model_names.MODEL_NAMES`)."""

    long_range: ModelName = Field(description="long range predictor (paper: eq. 1, the EMG)")
    next_step: ModelName = Field(description="next-step predictor (paper: the EMG)")
    mlp: ModelName = Field(description="the MLP baseline of IV-A (paper: the EMG-pretrained, fine-tuned MLP)")
    long_range_free_width: ModelName = Field(
        description="ours, beside the paper's: the long range predictor on a second model (the free-width EMG)"
    )
    next_step_free_width: ModelName = Field(
        description="ours, beside the paper's: the next-step predictor on a second model (the free-width EMG)"
    )


class UncertaintyParams(Section):
    """Prediction interval on theta_p (beyond the paper)."""

    method: IntervalMethod = Field(
        description="covariance: delta method from the EMG fit's parameter covariance; bootstrap: refits on images"
        " resampled with replacement (any model)"
    )
    level: float = Field(gt=0, lt=1, description="two-sided coverage of the interval, e.g. 0.9")
    n_bootstrap: int = Field(ge=2, le=10_000, description="bootstrap refits per dataset (method bootstrap)")


class HeadlineIntervalParams(Section):
    """Ours (issue 49): the interval of every headline (max mean SPL at zero incursion, its gain over static, its share
    of the ceiling), from a scene-clustered bootstrap that chooses the operating point again in each draw
    (prediction/intervals.py)."""

    n_draws: int = Field(ge=100, le=GRID, description="bootstrap draws (scenes resampled with replacement), e.g. 2000")
    level: float = Field(gt=0, lt=1, description="two-sided coverage of the percentile interval, e.g. 0.9: 5-95 %")


class ErrorPredictorParams(Section):
    """Ours (issue 38): the predictors that stop where k x the predicted localization error reaches the tolerance
    (prediction/error_predictors.py). The operating point is the safety factor k, swept geometrically."""

    k_min: float = Field(gt=0, le=1e3, description="smallest safety factor of the sweep")
    k_max: float = Field(gt=0, le=1e3, description="largest safety factor of the sweep")
    n_k: int = Field(ge=2, le=GRID, description="safety factors swept, k_min .. k_max in geometric steps")
    live_k: Annotated[float, Field(gt=0, le=1e3)] | None = Field(
        description="fixed k of the simulated live trials of error_next_step (as live_n_t of the paper's); null: the "
                    "k of the main world's Table III at live_tolerance (prediction/live_trials.py, "
                    "live_safety_factor)")

    @model_validator(mode="after")
    def _check(self) -> ErrorPredictorParams:
        if self.k_max <= self.k_min:
            raise KeyRule("k_max", f"must be > k_min ({self.k_min}), got {self.k_max}")
        return self

    @property
    def safety_factors(self) -> np.ndarray:
        """The swept safety factors k : (n_k,) float, geometric from k_min to k_max (rounded to 1e-9, so that the
        grids of two worlds agree exactly)."""
        return np.round(np.geomspace(self.k_min, self.k_max, self.n_k), 9)


class HazardPredictorParams(Section):
    """Ours (issue 50): the predictors that stop where the failure hazard reaches h (prediction/hazard). The models are
    trained on the population's worlds (population/hazard.py); stage 04 applies the file ``model``."""

    model: str = Field(min_length=1, description="the hazard models stage 04 applies, a path from the project's root "
                                                 "(written by `make population`); a missing file runs no hazard rows")
    h_min: float = Field(gt=0, lt=1, description="smallest hazard h of the sweep")
    h_max: float = Field(gt=0, lt=1, description="largest hazard h of the sweep")
    n_h: int = Field(ge=2, le=GRID, description="hazards swept, h_min .. h_max in geometric steps")

    @model_validator(mode="after")
    def _check(self) -> HazardPredictorParams:
        if self.h_max <= self.h_min:
            raise KeyRule("h_max", f"must be > h_min ({self.h_min}), got {self.h_max}")
        return self

    @property
    def levels(self) -> np.ndarray:
        """The swept hazards h : (n_h,) float, geometric from h_min to h_max (rounded to 1e-9 as the k grid)."""
        return np.round(np.geomspace(self.h_min, self.h_max, self.n_h), 9)


class PredictParams(Section):
    """Stage 04: predictors, the n_t sweep, the static baseline, LOSO threshold choice, live-trial simulation."""

    n_t_min: int = Field(ge=1, le=GRID, description="smallest inlier threshold of the sweep (paper: 4)")
    n_t_max: int = Field(ge=1, le=GRID, description="largest inlier threshold of the sweep (paper: 100)")
    relative_min: float = Field(gt=0, lt=1, description="beyond the paper: smallest n_t / first-stop mean n_i")
    relative_max: float = Field(gt=0, lt=1, description="largest n_t / first-stop mean n_i of the sweep")
    relative_step: float = Field(gt=0, lt=1, description="step of the relative-threshold sweep")
    n_static: int = Field(ge=2, le=GRID, description="envelope sizes of the static sweep, 0 .. the range end of protocol")
    tolerance_fig6_fig7: str = Field(
        min_length=1, description="tolerance of the PnP (Fig. 6) and straight-line (Fig. 7) curves (paper: 2mm_3deg),"
        " one of protocol.tolerances"
    )
    n_grid: int = Field(ge=16, le=GRID, description="grid points of the theta_p crossing scan per fitted curve")
    models: PredictorModels
    model_choice: distinct(ModelName) = Field(
        min_length=1, description="ours: least squares base functions compared as the long range predictor's model "
        "(model_choice.py), in-sample and held out, so that a user picks predict.models from their own data"
    )
    live_n_t: int = Field(ge=1, le=GRID, description="fixed n_t of the simulated live trials (paper: 15, from Table III), one of"
                                            " the swept n_t_min .. n_t_max")
    live_tolerance: str = Field(min_length=1, description="tolerance of the simulated live trials (paper: 4mm_10deg), one of"
                                                            " protocol.tolerances")
    loso_target_rates: distinct(Rate) = Field(
        min_length=1, description="target incursion rates (distinct, in [0, 1]) of the leave-one-scene-out threshold"
        " choice; first = headline"
    )
    uncertainty: UncertaintyParams
    intervals: HeadlineIntervalParams
    error: ErrorPredictorParams
    hazard: HazardPredictorParams
    tail_n_t_max: int = Field(
        ge=1, le=GRID, description="the tail diagnosis: an arc whose long range theta_p exceeds theta_a at every swept n_t up"
        " to this one, one of n_t_min .. n_t_max"
    )
    tail_n_t_shown: distinct(Annotated[int, Field(ge=1, le=GRID)]) = Field(
        min_length=1, description="thresholds at which the tail diagnosis shows theta_p, each one of n_t_min .."
        " n_t_max"
    )
    seed: Seed = Field(description="seed of every random draw of the stage (MLP weights, bootstrap)")

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> PredictParams:
        protocol = (info.context or {}).get("protocol")
        for key in ("tolerance_fig6_fig7", "live_tolerance"):
            if protocol is not None and getattr(self, key) not in protocol.tolerance_names:
                raise KeyRule(key, f"must name one of protocol.tolerances {protocol.tolerance_names}, "
                                   f"got {getattr(self, key)!r}")
        if self.n_t_max < self.n_t_min:
            raise KeyRule("n_t_max", f"must be >= n_t_min ({self.n_t_min}), got {self.n_t_max}")
        if not self.n_t_min <= self.live_n_t <= self.n_t_max:
            raise KeyRule("live_n_t", f"must be one of the swept thresholds n_t_min .. n_t_max ({self.n_t_min} .. "
                                      f"{self.n_t_max}), got {self.live_n_t}")
        if not self.n_t_min <= self.tail_n_t_max <= self.n_t_max:
            raise KeyRule("tail_n_t_max", f"must be one of the swept thresholds n_t_min .. n_t_max ({self.n_t_min} "
                                          f".. {self.n_t_max}), got {self.tail_n_t_max}")
        for index, n_t in enumerate(self.tail_n_t_shown):
            if not self.n_t_min <= n_t <= self.n_t_max:
                raise KeyRule(f"tail_n_t_shown.{index}", f"must be one of the swept thresholds n_t_min .. n_t_max "
                                                         f"({self.n_t_min} .. {self.n_t_max}), got {n_t}")
        if self.relative_max < self.relative_min:
            raise KeyRule("relative_max", f"must be >= relative_min ({self.relative_min}), got {self.relative_max}")
        steps = (self.relative_max - self.relative_min) / self.relative_step
        if abs(steps - round(steps)) > 1e-6:
            raise KeyRule("relative_step", f"must divide relative_max - relative_min ({self.relative_max} - "
                                           f"{self.relative_min}) into whole steps, so that the sweep ends at "
                                           f"relative_max; got {self.relative_step}")
        fewest = min((protocol.sampled_stops.arc, protocol.sampled_stops.line)) if protocol else None
        for predictor, model in self.models:
            if fewest is not None and distinct_theta_needed(model) > fewest:
                raise KeyRule(f"models.{predictor}", f"model {model!r} needs {distinct_theta_needed(model)} stops, "
                                                     f"more than protocol.sampled_stops gives ({fewest})")
        for index, model in enumerate(self.model_choice):
            if model not in LEAST_SQUARES:
                raise KeyRule(f"model_choice.{index}", f"must name a least squares base function (one of "
                                                       f"{sorted(LEAST_SQUARES)}), got {model!r}")
            if fewest is not None and distinct_theta_needed(model) > fewest:
                raise KeyRule(f"model_choice.{index}", f"model {model!r} needs {distinct_theta_needed(model)} stops, "
                                                       f"more than protocol.sampled_stops gives ({fewest})")
        if self.uncertainty.method == "covariance" and self.models.long_range not in LEAST_SQUARES:
            raise KeyRule("uncertainty.method", f"covariance needs a least squares long_range model (one of "
                                                f"{sorted(LEAST_SQUARES)}), got {self.models.long_range!r}: use "
                                                f"bootstrap")
        return self

    @property
    def thresholds(self) -> np.ndarray:
        """The swept inlier thresholds n_t : (T,) float, n_t_min .. n_t_max in steps of 1."""
        return np.arange(self.n_t_min, self.n_t_max + 1, dtype=float)

    @property
    def relative_thresholds(self) -> np.ndarray:
        """The swept relative thresholds n_t / (mean n_i at the first stop) : (R,) float, relative_min ..
        relative_max in steps of relative_step (rounded to 1e-9 so that the grid is exact)."""
        n = int(np.floor((self.relative_max - self.relative_min) / self.relative_step + 1e-9)) + 1
        return np.round(self.relative_min + self.relative_step * np.arange(n), 9)

    def static_sizes(self, theta_end: float) -> np.ndarray:
        """Static baseline envelope sizes 0 .. theta_end : (n_static,) float, deg (arcs) or mm (lines)."""
        return np.linspace(0.0, theta_end, self.n_static)
