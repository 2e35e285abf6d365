"""Ours, beyond the paper: the artifact model chosen on the datasets at hand, the way the predictors use it.

Windsor et al. fix eq. 1 (the EMG) from Fig. 2's fitting error on their own data (III-D). On other data (another
world, a user's recorded datasets) the choice is asked again. Every least-squares base function of
``predict.model_choice`` drives the long range predictor (III-E), swept over n_t and scored by SPL (eq. 3) and
incursion (eq. 4) against the actual envelopes:

- in-sample: the maximum mean SPL at zero incursion and its n_t (Tables I-III's figure);
- held out: n_t chosen on every scene but one for R_i <= the first of ``predict.loso_target_rates`` and scored on the
  held-out scene, pooled over folds (:mod:`.loso`). A dataset named without a scene (``scene_<n>_arc...``), as a
  recorded one is, is its own scene: the folds then leave one dataset out.

Fig. 2's RMSE of each base function (stage 03, fits.json) is its fitting error beside these. ``predict.models`` then
names the model each predictor uses (the paper's EMG stays the default).
"""

from __future__ import annotations

from functools import partial

import numpy as np
import pandas as pd

from poseintegrity.artifact_models.series import Series, dataset_series
from poseintegrity.params.fit import FitParams
from poseintegrity.params.predict import PredictParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.prediction.loso import loso, pooled
from poseintegrity.prediction.metrics import best_operating_point, operating_curves
from poseintegrity.prediction.predictors import fit_rng, long_range
from poseintegrity.prediction.sweeps import fit_of, prediction_rows
from poseintegrity.workers import Workers

PREDICTOR = "long_range"  # the predictor the candidate models are compared on
CHOICE_COLUMNS = [
    "world", "model", "tolerance", "max_mean_spl_zero_incursion", "best_n_t", "heldout_incursion_rate", "heldout_mean_spl",
    "heldout_n", "n_infeasible_folds",
]  # fmt: skip


def candidate_predictions(series: Series, method: str, predict: PredictParams, fit: FitParams,
                          protocol: ProtocolParams) -> pd.DataFrame:  # fmt: skip
    """theta_p of the long range predictor on every model of ``predict.model_choice`` for one dataset (rows of
    :data:`poseintegrity.prediction.sweeps.COLUMNS`, ``model`` naming the base function). Each fit draws from the
    same generator as the sweep's long range predictor, so the rows of ``predict.models.long_range`` equal the
    sweep's."""
    n_t, n_sampled_stops = predict.thresholds, protocol.stops_sampled(series.trajectory)
    tables = []
    for model in predict.model_choice:
        answer = long_range(series, n_sampled_stops, model, n_t, fit,
                            fit_rng(predict.seed, method, series, n_sampled_stops), predict.n_grid)
        tables.append(prediction_rows(PREDICTOR, model, method, series, n_t, answer.prediction, *fit_of(answer)))
    return pd.concat(tables, ignore_index=True)


def candidate_sweep(artifacts: pd.DataFrame, predict: PredictParams, fit: FitParams, protocol: ProtocolParams,
                    workers: Workers, progress: bool = True) -> pd.DataFrame:  # fmt: skip
    """:func:`candidate_predictions` of every dataset on the paper's PnP path (``protocol.pnp_method``), one task
    per dataset on ``workers``. artifacts : the stage-02 table."""
    method = protocol.pnp_method
    series = dataset_series(artifacts, method, protocol)
    task = partial(candidate_predictions, method=method, predict=predict, fit=fit, protocol=protocol)
    results = workers.map(task, series, desc="model choice (dataset)", progress=progress)
    return pd.concat(results, ignore_index=True)


def model_choice(table: pd.DataFrame, target_rate: float, trajectory: str = "arc") -> pd.DataFrame:
    """One row per world, model and tolerance (columns :data:`CHOICE_COLUMNS`): worlds sorted, models in table
    order. Each world is scored on its own datasets (the validation world is a second opinion, nothing carried over).

    table : :func:`candidate_sweep` rows with the envelopes attached
        (:func:`poseintegrity.prediction.sweeps.attach_envelopes`: world, theta_a, spl, incursion per tolerance).
    target_rate : the held-out choice's R_i bound (predict.loso_target_rates[0]).
    """
    rows = []
    table = table[table["trajectory"] == trajectory]
    for (world, model), one in table.groupby(["world", "model"], sort=False):
        held = pooled(loso(one, (target_rate,), (PREDICTOR,), str(one["method"].iloc[0]), trajectory))
        for tolerance, curve in operating_curves(one).groupby("tolerance", sort=True):
            spl, n_t = best_operating_point(curve, 0.0, conservative_high=True)
            out = held[held["tolerance"] == tolerance]
            rows.append({
                "world": world, "model": model, "tolerance": tolerance, "max_mean_spl_zero_incursion": spl, "best_n_t": n_t,
                "heldout_incursion_rate": float(out["heldout_incursion_rate"].iloc[0]) if len(out) else np.nan,
                "heldout_mean_spl": float(out["heldout_mean_spl"].iloc[0]) if len(out) else np.nan,
                "heldout_n": int(out["heldout_n"].iloc[0]) if len(out) else 0,
                "n_infeasible_folds": int(out["n_infeasible_folds"].iloc[0]) if len(out) else 0,
            })  # fmt: skip
    return pd.DataFrame(rows, columns=CHOICE_COLUMNS).sort_values("world", kind="stable", ignore_index=True)


def model_choice_metrics(choice: pd.DataFrame) -> dict:
    """<world>.<model>.<tolerance>.{max_mean_spl_zero_incursion, best_n_t, heldout_incursion_rate,
    heldout_mean_spl, heldout_n, n_infeasible_folds} of a :func:`model_choice` table (predictors.json,
    ``model_choice``)."""
    metrics: dict = {}
    for row in choice.itertuples(index=False):
        entry = row._asdict()
        world, model, tolerance = entry.pop("world"), entry.pop("model"), entry.pop("tolerance")
        metrics.setdefault(str(world), {}).setdefault(str(model), {})[str(tolerance)] = entry
    return metrics
