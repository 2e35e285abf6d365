"""The Fig. 2 experiment of Windsor et al.: which artifact model extrapolates best from the first k stops?

For every dataset and k = k_min .. all stops, each model is fitted to the images of the first k stops
(theta_deg for arcs, x_mm for lines) and its RMSE is measured over every image of the dataset; the figure
shows the mean RMSE across datasets per model and k (III-D, Fig. 2; lines as in V-C).

Input: the artifacts table of stage 02, one row per image and PnP method, with at least the columns
``dataset, trajectory ("arc"|"line"), stop (0-based), theta_deg, x_mm, method, n_inliers``.
"""

from __future__ import annotations

import zlib

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from tqdm import tqdm

from poseintegrity.artifact_models.fitted import FittedModel
from poseintegrity.artifact_models.models import fit_model
from poseintegrity.artifact_models.params import FitParams
from poseintegrity.artifact_models.series import Series, dataset_series
from poseintegrity.protocol import ProtocolParams

COLUMNS = ["trajectory", "dataset", "k", "model", "rmse", "converged", "reason", "n_samples"]  # of fig2_rmse


def fit_first_stops(series: Series, k: int, params: FitParams) -> dict[str, FittedModel]:
    """Every model of ``params.models`` fitted to the first k stops of ``series``.

    Each fit draws from ``np.random.default_rng([seed, crc32(trajectory/dataset), k, crc32(model)])``:
    the same for any n_jobs, any order of work, any other datasets in the table and any other models.
    """
    theta, n_inliers = series.first_stops(k)
    key = [params.seed, _crc32(f"{series.trajectory}/{series.dataset}"), k]
    return {
        name: fit_model(
            name, theta, n_inliers, theta_max=series.theta_end, params=params, rng=np.random.default_rng([*key, _crc32(name)])
        )
        for name in params.models
    }


def _crc32(text: str) -> int:
    return zlib.crc32(text.encode())


def rmse(model: FittedModel, theta: np.ndarray, n_inliers: np.ndarray) -> float:
    """Root mean square error of model.predict(theta) vs n_inliers over the finite samples (Fig. 2)."""
    keep = np.isfinite(theta) & np.isfinite(n_inliers)
    return float(np.sqrt(np.mean((model.predict(theta[keep]) - n_inliers[keep]) ** 2)))


def _fig2_rows(series: Series, k: int, params: FitParams) -> list[dict]:
    return [
        {
            "trajectory": series.trajectory,
            "dataset": series.dataset,
            "k": k,
            "model": name,
            "rmse": rmse(model, series.theta, series.n_inliers),
            "converged": model.converged,
            "reason": model.reason,
            "n_samples": model.n_samples,
        }
        for name, model in fit_first_stops(series, k, params).items()
    ]


def fig2_rmse(artifacts: pd.DataFrame, params: FitParams, protocol: ProtocolParams, progress: bool = True) -> pd.DataFrame:
    """The Fig. 2 experiment on the ``protocol.pnp_method`` rows: one row per (trajectory, dataset, k, model).

    Columns: trajectory, dataset, k, model, rmse (inliers, over every image of the dataset), converged,
    reason ("ok" or why the fit failed; the RMSE is then that of the fallback line), n_samples.
    Runs on ``params.n_jobs`` joblib workers. Raises ValueError when no dataset has k_min stops.
    """
    all_series = dataset_series(artifacts, protocol.pnp_method, protocol)
    tasks = [
        (series, k)
        for series in all_series
        for k in range(params.k_min, min(params.k_max or series.n_stops, series.n_stops) + 1)
    ]
    if not tasks:
        most = max(series.n_stops for series in all_series)
        raise ValueError(f"no dataset has k_min = {params.k_min} stops (the longest has {most}): lower fit.k_min")
    results = Parallel(n_jobs=params.n_jobs, return_as="generator")(
        delayed(_fig2_rows)(series, k, params) for series, k in tasks
    )
    rows = [row for result in tqdm(results, total=len(tasks), disable=not progress) for row in result]
    return pd.DataFrame(rows, columns=COLUMNS)


def mean_rmse(table: pd.DataFrame) -> pd.DataFrame:
    """Fig. 2's curves: per (trajectory, model, k) the mean RMSE across datasets and the converged fraction."""
    return (
        table.groupby(["trajectory", "model", "k"], sort=True)
        .agg(mean_rmse=("rmse", "mean"), converged=("converged", "mean"), n_datasets=("dataset", "nunique"))
        .reset_index()
    )


def fits_metrics(table: pd.DataFrame, params: FitParams, protocol: ProtocolParams) -> dict[str, dict[str, float]]:
    """Headline figures of stage 03 for ``reports/metrics/fits.json``, at the stops a robot samples
    (``protocol.sampled_stops``: k = 4 on arcs, 5 on lines in the paper).

    rmse_k<arc stops>.<model> : mean RMSE across arc datasets at k = sampled arc stops
    line_rmse_k<line stops>.<model> : the same for line datasets
    converged.<model> : fraction of all fits (every dataset, every k) that converged
    Every model of ``params.models`` has every key; the value is None where there was no fit (e.g. no
    dataset with that many stops).
    """
    means = mean_rmse(table)
    converged = table.groupby("model")["converged"].mean()

    def at(trajectory: str, k: int) -> dict[str, float | None]:
        rows = means[(means["trajectory"] == trajectory) & (means["k"] == k)].set_index("model")["mean_rmse"]
        return {m: float(rows[m]) if m in rows.index else None for m in params.models}

    return {
        f"rmse_k{protocol.sampled_stops.arc}": at("arc", protocol.sampled_stops.arc),
        f"line_rmse_k{protocol.sampled_stops.line}": at("line", protocol.sampled_stops.line),
        "converged": {m: float(converged[m]) if m in converged.index else None for m in params.models},
    }
