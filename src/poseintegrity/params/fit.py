"""Schema of the ``fit`` section of ``params.yaml`` (stage 03, artifact models).

Every value is explicit in ``params.yaml`` (no default here): none of these choices were published by Windsor et al.
(docs/references.md, "Camera of the Windsor et al. experiments"), so each is ours and documented here. The stops a
robot samples and the range ends come from the ``protocol`` section; the workers from ``parallel``.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, ValidationInfo, model_validator

from poseintegrity.params.model_names import distinct_theta_needed
from poseintegrity.schema import KeyRule, Seed, Section, distinct

ModelName = Literal[
    "emg", "exponential", "gaussian", "logistic", "power_law", "emg_free_width", "mlp_scratch", "mlp_pretrained"
]  # emg_free_width: ours, eq. 1 with a fitted Gaussian width (base_functions.py)
ITERATIONS = 100_000  # upper bound of every iteration / evaluation budget: a typo, not a budget, beyond it


class MLPParams(Section):
    """The MLP of Windsor et al. IV-E and its training (full batch, L-BFGS with strong Wolfe line search)."""

    hidden_layers: int = Field(ge=1, le=10, description="hidden layers (paper: 3)")
    hidden_units: int = Field(ge=1, le=1000, description="neurons per hidden layer (paper: 10)")
    max_iter_scratch: int = Field(ge=1, le=ITERATIONS, description="L-BFGS iterations of the scratch recipe (samples"
                                                                   " only)")
    max_iter_pretrain: int = Field(ge=1, le=ITERATIONS, description="L-BFGS iterations on the EMG starting curve")
    max_iter_finetune: int = Field(
        ge=1, le=ITERATIONS, description="L-BFGS iterations on samples + artificial points after pretraining (few: a"
        " longer fine-tune forgets the pretrained shape between the last stop and the range end)"
    )
    tolerance_change: float = Field(
        gt=0, lt=1, description="early stop: L-BFGS stops when the loss or the step changes by less (scaled units, in"
        " which the counts are at most 1)"
    )
    n_pretrain_points: int = Field(ge=2, le=ITERATIONS, description="grid points of the EMG curve used for pretraining")
    n_artificial: int = Field(ge=1, le=1000, description="copies of the artificial sample (range end, 0)")


class FitParams(Section):
    """Stage 03: fit artifact models f: theta -> n_inliers and run the Fig. 2 experiment."""

    models: distinct(ModelName) = Field(min_length=1, description="artifact models compared in Fig. 2")
    k_min: int = Field(ge=2, le=100, description="fewest stops (from the start) used for a fit; a model needing more"
                                                 " (model_names.distinct_theta_needed) joins Fig. 2 at its own count")
    k_max: int | None = Field(ge=2, le=100, description="most stops used for a fit; null = all stops")
    max_nfev: int = Field(ge=10, le=ITERATIONS, description="least squares evaluation budget per base-function fit")
    seed: Seed = Field(description="seed of every random draw of the stage (MLP initial weights)")
    mlp: MLPParams

    @model_validator(mode="after")
    def _check_ranges(self, info: ValidationInfo) -> FitParams:
        if self.k_max is not None and self.k_max < self.k_min:
            raise KeyRule("k_max", f"must be null or >= k_min ({self.k_min}), got {self.k_max}")
        needs = {name: distinct_theta_needed(name) for name in self.models}
        easiest = min(needs, key=needs.get)
        if self.k_min < needs[easiest]:
            raise KeyRule("k_min", f"must be >= {needs[easiest]}: no model can be fitted to fewer stops (model "
                                   f"{easiest!r} needs the fewest), got {self.k_min}")
        protocol = (info.context or {}).get("protocol")  # the headline RMSE is taken at its sampled stops
        stops = (protocol.sampled_stops.arc, protocol.sampled_stops.line) if protocol else (self.k_min,)
        if min(stops) < self.k_min:
            raise KeyRule("k_min", f"must be <= protocol.sampled_stops ({min(stops)}), got {self.k_min}")
        for index, name in enumerate(self.models):
            if protocol is not None and needs[name] > min(stops):
                raise KeyRule(f"models.{index}", f"model {name!r} needs {needs[name]} stops, more than "
                                                 f"protocol.sampled_stops gives ({min(stops)}): it would have no "
                                                 f"headline RMSE")
        if self.k_max is not None and max(stops) > self.k_max:
            raise KeyRule("k_max", f"must be null or >= protocol.sampled_stops ({max(stops)}), got {self.k_max}")
        return self
