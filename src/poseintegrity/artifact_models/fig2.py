"""The Fig. 2 experiment of Windsor et al.: which artifact model extrapolates best from the first k stops?

For every dataset and k = k_min .. all stops, each model is fitted to the images of the first k stops
(theta_deg for arcs, x_mm for lines) and its RMSE is measured over every image of the dataset; the figure
shows the mean RMSE across datasets per model and k (III-D, Fig. 2; lines as in V-C). A model that needs more
stops than k_min (``models.distinct_theta_needed``: the free-width EMG's 4 parameters) joins at its own count.

Input: the artifacts table of stage 02, one row per image and PnP method, with at least the columns
``dataset, trajectory ("arc"|"line"), stop (0-based), theta_deg, x_mm, method, n_inliers``.
"""

from __future__ import annotations

from functools import partial

import numpy as np
import pandas as pd

from poseintegrity.artifact_models.fitted import FIT_STATUSES, OK, FittedModel
from poseintegrity.artifact_models.models import fit_model
from poseintegrity.artifact_models.series import Series, dataset_series
from poseintegrity.errors import ArgumentError
from poseintegrity.params.fit import FitParams
from poseintegrity.params.model_names import distinct_theta_needed
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.seeding import keyed_rng
from poseintegrity.table_checks import check_fig2_rmse
from poseintegrity.workers import Workers

COLUMNS = ["trajectory", "dataset", "k", "model", "rmse", "status", "reason", "n_samples"]  # of fig2_rmse


def fit_first_stops(series: Series, k: int, params: FitParams) -> dict[str, FittedModel]:
    """Every model of ``params.models`` that k stops can fit (``distinct_theta_needed(model) <= k``), fitted to the
    first k stops of ``series``, checked up to its range end.

    Each fit draws from ``keyed_rng(seed, "trajectory/dataset", k, model)``:
    the same for any number of workers, any order of work, any other datasets in the table and any other models.
    """
    theta, n_inliers = series.first_stops(k)
    return {
        name: fit_model(name, theta, n_inliers, theta_end=series.theta_end, params=params,
                        rng=keyed_rng(params.seed, f"{series.trajectory}/{series.dataset}", k, name))
        for name in params.models
        if distinct_theta_needed(name) <= k
    }  # fmt: skip


def rmse(model: FittedModel, theta: np.ndarray, n_inliers: np.ndarray) -> float:
    """Root mean square error of model.predict(theta) vs n_inliers over the finite samples (Fig. 2)."""
    keep = np.isfinite(theta) & np.isfinite(n_inliers)
    return float(np.sqrt(np.mean((model.predict(theta[keep]) - n_inliers[keep]) ** 2)))


def _fig2_rows(task: tuple[Series, int], params: FitParams) -> list[dict]:
    """The rows of one (dataset, k) task: one per model."""
    series, k = task
    return [
        {
            "trajectory": series.trajectory,
            "dataset": series.dataset,
            "k": k,
            "model": name,
            "rmse": rmse(model, series.theta, series.n_inliers),
            "status": model.status,
            "reason": model.reason,
            "n_samples": model.n_samples,
        }
        for name, model in fit_first_stops(series, k, params).items()
    ]


def fig2_rmse(
    artifacts: pd.DataFrame, params: FitParams, protocol: ProtocolParams, workers: Workers, progress: bool = True
) -> pd.DataFrame:
    """The Fig. 2 experiment on the ``protocol.pnp_method`` rows: one row per (trajectory, dataset, k, model), for
    the models that k stops can fit.

    Columns: trajectory, dataset, k, model, rmse (inliers, over every image of the dataset), status ("ok",
    "at_bound", "non_physical" or "fallback", artifact_models/fitted.py), reason ("ok" or what was found; a
    "fallback" fit is scored with its fallback line, every other with its fitted curve: what a predictor would
    use), n_samples. One task per (dataset, k) on ``workers``. Raises ValueError when no dataset has k_min stops.
    """
    all_series = dataset_series(artifacts, protocol.pnp_method, protocol)
    tasks = [
        (series, k)
        for series in all_series
        for k in range(params.k_min, min(params.k_max or series.n_stops, series.n_stops) + 1)
    ]
    if not tasks:
        most = max(series.n_stops for series in all_series)
        raise ArgumentError(f"fit.k_min: no dataset has k_min = {params.k_min} stops (the longest has {most}): lower fit.k_min")
    results = workers.map(partial(_fig2_rows, params=params), tasks, desc="Fig. 2 fits (dataset, k)",
                          progress=progress)  # fmt: skip
    return pd.DataFrame([row for rows in results for row in rows], columns=COLUMNS)


def mean_rmse(table: pd.DataFrame) -> pd.DataFrame:
    """Fig. 2's curves: per (trajectory, model, k) the mean RMSE across datasets and the share of fits "ok".
    ``table`` is checked (:func:`~poseintegrity.table_checks.check_fig2_rmse`: a repeated row would shift a
    mean)."""
    check_fig2_rmse(table)
    return (
        table.assign(ok=table["status"] == OK)
        .groupby(["trajectory", "model", "k"], sort=True)
        .agg(mean_rmse=("rmse", "mean"), share_ok=("ok", "mean"), n_datasets=("dataset", "nunique"))
        .reset_index()
    )


def at_sampled_stops(means: pd.DataFrame, protocol: ProtocolParams) -> pd.DataFrame:
    """The rows of :func:`mean_rmse` at k = the stops a robot samples on their trajectory type (protocol)."""
    sampled = means["trajectory"].map(protocol.stops_sampled)
    return means[means["k"] == sampled]


def status_counts(table: pd.DataFrame) -> pd.DataFrame:
    """Fits per model and status: index model, columns :data:`FIT_STATUSES` (counts) and n_fits."""
    counts = pd.crosstab(table["model"], table["status"]).reindex(columns=list(FIT_STATUSES), fill_value=0)
    return counts.assign(n_fits=counts.sum(axis=1))


def fits_metrics(table: pd.DataFrame, params: FitParams, protocol: ProtocolParams) -> dict[str, dict]:
    """Headline figures of stage 03 for ``reports/metrics/fits.json``, at the stops a robot samples
    (``protocol.sampled_stops``: k = 4 on arcs, 5 on lines in the paper).

    rmse_k<arc stops>.<model> : mean RMSE across arc datasets at k = sampled arc stops
    line_rmse_k<line stops>.<model> : the same for line datasets
    fit_status.<model>.{ok, at_bound, non_physical, fallback} : share of all the model's fits (every dataset, every
        k) with that status;  n_fits.<model> : how many fits
    Every model of ``params.models`` has every key; the value is None where there was no fit (e.g. no
    dataset with that many stops).
    """
    at_k = at_sampled_stops(mean_rmse(table), protocol)
    counts = status_counts(table)

    def at(trajectory: str) -> dict[str, float | None]:
        rows = at_k[at_k["trajectory"] == trajectory].set_index("model")["mean_rmse"]
        return {m: float(rows[m]) if m in rows.index else None for m in params.models}

    def shares(model: str) -> dict[str, float] | None:
        if model not in counts.index:
            return None
        row = counts.loc[model]
        return {status: float(row[status] / row["n_fits"]) for status in FIT_STATUSES}

    return {
        f"rmse_k{protocol.stops_sampled('arc')}": at("arc"),
        f"line_rmse_k{protocol.stops_sampled('line')}": at("line"),
        "fit_status": {m: shares(m) for m in params.models},
        "n_fits": {m: int(counts.loc[m, "n_fits"]) if m in counts.index else 0 for m in params.models},
    }
