"""Schema of the ``predict`` section of ``params.yaml`` (stage 04, localization-envelope predictors).

The artifact models themselves are configured by the ``fit`` section (:class:`poseintegrity.artifact_models.FitParams`:
curve_fit budget, MLP recipe, range ends theta_max / x_max); this section says how the predictors of
Windsor et al. III-E use them and how the operating points are swept (IV-A, V). Lengths in mm, angles in deg.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field, ValidationInfo, model_validator

from poseintegrity.artifact_models.params import ModelName
from poseintegrity.schema import KeyRule, Section

IntervalMethod = Literal["covariance", "bootstrap"]


class PredictorModels(Section):
    """Artifact model behind each predictor (a name of :data:`poseintegrity.artifact_models.MODEL_NAMES`)."""

    long_range: ModelName = Field(description="long range predictor (paper: eq. 1, the EMG)")
    next_step: ModelName = Field(description="next-step predictor (paper: the EMG)")
    mlp: ModelName = Field(description="the MLP baseline of IV-A (paper: the EMG-pretrained, fine-tuned MLP)")


class UncertaintyParams(Section):
    """Prediction interval on theta_p (beyond the paper)."""

    method: IntervalMethod = Field(
        description="covariance: delta method from the EMG fit's parameter covariance; bootstrap: refits on images"
        " resampled with replacement (any model)"
    )
    level: float = Field(gt=0, lt=1, description="two-sided coverage of the interval, e.g. 0.9")
    n_bootstrap: int = Field(ge=2, description="bootstrap refits per dataset (method bootstrap)")


class PredictParams(Section):
    """Stage 04: predictors, the n_t sweep, the static baseline, LOSO threshold choice, live-trial simulation."""

    n_t_min: int = Field(ge=1, description="smallest inlier threshold of the sweep (paper: 4)")
    n_t_max: int = Field(ge=1, description="largest inlier threshold of the sweep (paper: 100)")
    relative_min: float = Field(gt=0, lt=1, description="beyond the paper: smallest n_t / first-stop mean n_i")
    relative_max: float = Field(gt=0, lt=1, description="largest n_t / first-stop mean n_i of the sweep")
    relative_step: float = Field(gt=0, lt=1, description="step of the relative-threshold sweep")
    n_static: int = Field(ge=2, description="envelope sizes of the static sweep, 0 .. the range end of protocol")
    tolerance_fig6_fig7: str = Field(
        min_length=1, description="tolerance of the PnP (Fig. 6) and straight-line (Fig. 7) curves (paper: 2mm_3deg),"
        " one of protocol.tolerances"
    )
    n_grid: int = Field(ge=16, description="grid points of the theta_p crossing scan per fitted curve")
    models: PredictorModels
    live_n_t: int = Field(ge=1, description="fixed n_t of the simulated live trials (paper: 15, from Table III)")
    live_tolerance: str = Field(min_length=1, description="tolerance of the simulated live trials (paper: 4mm_10deg), one of"
                                                            " protocol.tolerances")
    loso_target_rates: tuple[float, ...] = Field(
        min_length=1, description="target incursion rates of the leave-one-scene-out threshold choice; first = headline"
    )
    uncertainty: UncertaintyParams
    seed: int = Field(ge=0, description="seed of every random draw of the stage (MLP weights, bootstrap)")
    n_jobs: int = Field(description="joblib workers; -1 = all cores")

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> PredictParams:
        protocol = (info.context or {}).get("protocol")
        for key in ("tolerance_fig6_fig7", "live_tolerance"):
            if protocol is not None and getattr(self, key) not in protocol.tolerance_names:
                raise KeyRule(key, f"must name one of protocol.tolerances {protocol.tolerance_names}, "
                                   f"got {getattr(self, key)!r}")
        if self.n_t_max < self.n_t_min:
            raise ValueError(f"n_t_max ({self.n_t_max}) must be >= n_t_min ({self.n_t_min})")
        if self.relative_max < self.relative_min:
            raise ValueError(f"relative_max ({self.relative_max}) must be >= relative_min ({self.relative_min})")
        if self.n_jobs == 0:
            raise ValueError("n_jobs must be a positive count or negative (joblib convention), not 0")
        bad = [r for r in self.loso_target_rates if not 0.0 <= r <= 1.0]
        if bad:
            raise ValueError(f"loso_target_rates must lie in [0, 1], got {bad}")
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
