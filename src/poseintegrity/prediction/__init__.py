"""Localization-envelope predictors of Windsor et al. (III-E, III-F, IV-A, IV-E, V) and what goes past them.

    params.py       the ``predict`` section of params.yaml (PredictParams)
    predictors.py   theta_p for all n_t at once; long range, next-step (III-E) and static (IV-A) predictors
    metrics.py      SPL (eq. 3), R_i (eq. 4), SPL vs R_i curves, max mean SPL at zero incursion (Tables I-III)
    sweeps.py       the whole operating-point sweep over datasets, predictors, tolerances, PnP methods (V)
    loso.py         n_t from a target incursion rate by leave-one-scene-out cross-validation (VI, future work), pooled
    uncertainty.py  a prediction interval on theta_p (fit covariance or bootstrap) and its lower bound
    supervisor.py   NextStepSupervisor: the next-step predictor as a component of a robot loop
"""

from poseintegrity.prediction.loso import loso, loso_folds, loso_summary, pooled, scene_of
from poseintegrity.prediction.metrics import (
    best_operating_point,
    incursion,
    operating_curves,
    relative_improvement,
    safe_path_length,
    with_metrics,
)
from poseintegrity.prediction.params import PredictorModels, PredictParams, UncertaintyParams
from poseintegrity.prediction.predictors import (
    NO_FIT,
    Boundaries,
    boundaries,
    envelope_prediction,
    long_range,
    next_step,
    next_step_stops,
    relative_thresholds,
    static_baseline,
)
from poseintegrity.prediction.supervisor import Decision, NextStepSupervisor
from poseintegrity.prediction.sweeps import (
    FITTED_PREDICTORS,
    PAPER_PREDICTORS,
    RELATIVE_PREDICTORS,
    attach_envelopes,
    best_table,
    fit_status_shares,
    headline_metrics,
    live_trials,
    predict_dataset,
    sweep,
    with_pnp_variants,
)
from poseintegrity.prediction.uncertainty import Interval, bootstrap_interval, covariance_interval, prediction_interval

__all__ = [
    "FITTED_PREDICTORS",
    "NO_FIT",
    "PAPER_PREDICTORS",
    "RELATIVE_PREDICTORS",
    "Boundaries",
    "Decision",
    "Interval",
    "NextStepSupervisor",
    "PredictParams",
    "PredictorModels",
    "UncertaintyParams",
    "attach_envelopes",
    "best_operating_point",
    "best_table",
    "bootstrap_interval",
    "boundaries",
    "covariance_interval",
    "envelope_prediction",
    "fit_status_shares",
    "headline_metrics",
    "incursion",
    "live_trials",
    "long_range",
    "loso",
    "loso_folds",
    "loso_summary",
    "next_step",
    "next_step_stops",
    "operating_curves",
    "pooled",
    "prediction_interval",
    "predict_dataset",
    "relative_thresholds",
    "relative_improvement",
    "safe_path_length",
    "scene_of",
    "static_baseline",
    "sweep",
    "with_metrics",
    "with_pnp_variants",
]
