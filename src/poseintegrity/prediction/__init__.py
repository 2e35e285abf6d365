"""Localization-envelope predictors of Windsor et al. (III-E, III-F, IV-A, IV-E, V) and what goes past them.

    predictors.py         theta_p for all n_t at once; long range, next-step (III-E) and static (IV-A) predictors
    metrics.py            SPL (eq. 3), R_i (eq. 4), SPL vs R_i curves, max mean SPL at zero incursion (Tables I-III)
    sweeps.py             the whole operating-point sweep over datasets, predictors, tolerances, PnP methods (V)
    paper_tables.py       Tables I-III and the metrics of predictors.json, per failed-frame rule of theta_a too
    intervals.py          ours: scene-clustered bootstrap and leave-one-arc-out intervals on every headline
    live_trials.py        the simulated live trials (V-C) at fixed n_t (and k), and ours chosen on other scenes
    transfer.py           operating points chosen on the main world, applied unchanged to the validation world
    loso.py               n_t from a target incursion rate by leave-one-scene-out cross-validation (VI), pooled
    model_choice.py       ours: each least squares base function as the long range predictor's model, scored
    tails.py              ours: the arcs whose long range theta_p overshoots theta_a at every n_t (eq. 1's long tail)
    error_predictors.py   ours: long range / next step on the predicted localization error, safety factor k
    hazard/               ours: the failure hazard from evidence without ground truth, and the predictors on it (h)
    ceiling.py            ours: the ceiling of any predictor's gain over static, and each predictor's share of it
    uncertainty.py        a prediction interval on theta_p (fit covariance or bootstrap) and its lower bound
    supervisor.py         NextStepSupervisor: the next-step predictor as a component of a robot loop
    predictor_figures.py  stage 04's figures: the SPL vs R_i curves (Figs. 5-8) and every predictor beside the ceiling
"""

import lazy_loader

# Names resolve on first use, so that importing one module of the package (its params schema, say) does not
# import all of them: the stage runner and every worker process import only what they run.
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "loso": ["loso", "loso_folds", "loso_summary", "pooled", "scene_of"],
        "metrics": [
            "best_operating_point", "incursion", "operating_curves", "relative_improvement", "safe_path_length",
            "with_metrics",
        ],
        "predictors": [
            "NO_FIT", "Boundaries", "boundaries", "envelope_prediction", "long_range", "next_step",
            "next_step_stops", "relative_thresholds", "static_baseline",
        ],
        "supervisor": ["Decision", "NextStepSupervisor"],
        "tails": ["TAIL_PREDICTORS", "TailFit", "overshooting_arcs", "tail_fits", "tail_metrics"],
        "ceiling": ["ceiling", "ceiling_share"],
        "error_predictors": ["ErrorGrowth", "error_long_range", "error_next_step", "fit_growth"],
        "sweeps": [
            "ERROR_PREDICTORS", "FITTED_PREDICTORS", "FREE_WIDTH_PREDICTORS", "PAPER_PREDICTORS", "RELATIVE_PREDICTORS",
            "attach_envelopes", "combined_rows", "predict_dataset", "sweep", "with_pnp_variants",
        ],
        "paper_tables": ["best_table", "fit_status_shares", "headline_metrics", "rule_metrics", "table_metrics"],
        "live_trials": [
            "heldout_interval", "heldout_live_trials", "heldout_metrics", "live_safety_factor", "live_trials",
            "trial_figures",
        ],
        "transfer": ["transfer", "transfer_metrics"],
        "uncertainty": ["Interval", "bootstrap_interval", "covariance_interval", "prediction_interval"],
    },
)
