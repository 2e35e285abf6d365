"""What can the robot forecast one stop ahead? The choices of the next-step error predictors (issue 38), measured
against what the robot then sees, with no predictor score involved (prediction/error_predictors.py).

**The count** (the error predictors divide the propagated error by a count forecast n(theta)). For every dataset of
the artifacts table (the paper's PnP path) and every stop i from the protocol's sampled stops on, the mean count of
stop i + 1 is forecast from stops 0..i by

    eq1    the paper's artifact model (eq. 1, ``predict.models.next_step``) fitted to stops 0..i, as next step fits it
    trend  CountTrend: the log-linear trend of the last three stops' mean counts
    last   the last stop's mean count (no change)

Printed per world, over the forecasts whose last count lay in ``--counts`` (where the count runs out): the median and
mean |log error| of (n + 1), how many forecast fewer than 4 inliers (no pose) where the stop kept most of its poses
(a false loss), and how many stops that lost most of their poses (more than protocol.envelope's max_failed_fraction
without one) were forecast so.

**The observed scale** (``error_next_step_observed`` scales the predicted error by how much the robot's kinematics
have seen it exceeded: :func:`~poseintegrity.prediction.error_predictors.observed_scale`). For every stop i + 1
before theta_a (per tolerance), the next stop's median predicted sigma_t scaled by the scale of stops 0..i over the
last w stops (w = 1, 2, 3, 5, all; and unscaled) is compared with the next stop's mean observed error: the mean and
median log error, and the share of stops whose observed error lies within 2 x the scaled prediction.

    .venv/bin/python studies/next_stop_forecasts.py [--counts 6 40] [--params params.yaml] [--data data]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import poseintegrity  # noqa: F401  (first: it pins the CPU dispatch before numpy loads)
import numpy as np
import pandas as pd

from poseintegrity.artifact_models.series import Series, dataset_series
from poseintegrity.config import load_params
from poseintegrity.params.fit import FitParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.pose_correspondences import MIN_CORRESPONDENCES
from poseintegrity.prediction.error_predictors import CountTrend, observed_scale
from poseintegrity.prediction.predictors import fit_rng, fit_stops, stop_positions

COUNT_FORECASTS = ("eq1", "trend", "last")
WINDOWS = {"unscaled": 0, "last 1": 1, "last 2": 2, "last 3": 3, "last 5": 5, "all": None}  # observed-scale windows


def count_forecasts(artifacts: pd.DataFrame, protocol: ProtocolParams, fit: FitParams, model: str, seed: int
                    ) -> pd.DataFrame:
    """One row per (dataset, stop i): world, dataset, trajectory, stop, last (mean count of stop i: also the "last"
    forecast), observed (of stop i + 1), posed (share of stop i + 1's images with a pose's 4 inliers) and the "eq1"
    and "trend" forecasts of stop i + 1."""
    method, worlds, rows = protocol.pnp_method, _worlds(artifacts), []
    for series in dataset_series(artifacts, method, protocol):
        stops, theta = stop_positions(series)
        counts = [series.n_inliers[(series.stop == s) & np.isfinite(series.n_inliers)] for s in stops]
        for i in range(protocol.stops_sampled(series.trajectory) - 1, stops.size - 1):
            seen = stops[: i + 1]
            fitted, _, _ = fit_stops(series, seen, model, fit, fit_rng(seed, method, series, seen.size))
            ahead = np.array([theta[i + 1]])
            rows.append({"world": worlds[series.dataset], "dataset": series.dataset, "trajectory": series.trajectory,
                         "stop": int(stops[i]), "last": counts[i].mean(), "observed": counts[i + 1].mean(),
                         "posed": float((counts[i + 1] >= MIN_CORRESPONDENCES).mean()),
                         "eq1": float(fitted.predict(ahead)[0]),
                         "trend": float(CountTrend.of(series, seen).predict(ahead)[0])})
    return pd.DataFrame(rows)


def count_summary(table: pd.DataFrame, counts: tuple[float, float], max_failed_fraction: float) -> pd.DataFrame:
    """Per world and forecast, over the rows whose last count lies in ``counts``: n, median and mean |log error| of
    (n + 1), false losses (forecast < 4 where the stop kept more than 1 - max_failed_fraction of its poses), losses and
    the losses forecast."""
    within = table[table["last"].between(*counts)]
    lost = within["posed"] < 1.0 - max_failed_fraction
    rows = []
    for forecast in COUNT_FORECASTS:
        error = np.log((within[forecast].clip(lower=0.0) + 1.0) / (within["observed"] + 1.0))
        no_pose = within[forecast] < MIN_CORRESPONDENCES
        frame = pd.DataFrame({"world": within["world"], "error": error, "no_pose": no_pose, "lost": lost})
        for world, one in frame.groupby("world", sort=True):
            rows.append({"world": world, "forecast": forecast, "n": len(one), "median_log_error": one.error.median(),
                         "mean_abs_log_error": one.error.abs().mean(),
                         "false_losses": int((one.no_pose & ~one.lost).sum()), "losses": int(one.lost.sum()),
                         "losses_forecast": int((one.no_pose & one.lost).sum())})
    return pd.DataFrame(rows).set_index(["world", "forecast"]).sort_index()


def scale_forecasts(artifacts: pd.DataFrame, envelopes: pd.DataFrame, protocol: ProtocolParams) -> pd.DataFrame:
    """One row per (dataset with observed errors, tolerance, stop i + 1 before theta_a with a predicted and an
    observed error): world, dataset, tolerance, stop, observed (mean observed E_t of stop i + 1, mm), and per
    window of :data:`WINDOWS` the median predicted sigma_t of stop i + 1 times the scale of stops 0..i (mm).

    envelopes : stage 02's theta_a table (world, dataset, tolerance, method, rule, theta_a); the protocol's rule
    """
    method, worlds, rows = protocol.pnp_method, _worlds(artifacts), []
    ends = envelopes[(envelopes["method"] == method) & (envelopes["rule"] == protocol.envelope.failed_frames)]
    for series in dataset_series(artifacts, method, protocol):
        if series.observed_t is None or series.sigma_t is None:
            continue
        stops, theta = stop_positions(series)
        for tolerance, theta_a in ends[ends["dataset"] == series.dataset][["tolerance", "theta_a"]].itertuples(
                index=False):
            for i in range(protocol.stops_sampled(series.trajectory) - 1, stops.size - 1):
                ahead = series.stop == stops[i + 1]
                predicted, observed = _median(series.sigma_t[ahead]), _mean(series.observed_t[ahead])
                if not (theta[i + 1] <= theta_a and np.isfinite(predicted) and observed > 0):
                    continue  # NaN theta_a (no envelope): no stop is known to lie before it
                row = {"world": worlds[series.dataset], "dataset": series.dataset, "tolerance": tolerance,
                       "stop": int(stops[i + 1]), "observed": observed}
                for name, window in WINDOWS.items():
                    scale = 1.0 if window == 0 else observed_scale(series, stops[: i + 1], window)[0]
                    row[name] = scale * predicted
                rows.append(row)
    return pd.DataFrame(rows)


def scale_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per world, tolerance and window: n, mean |log error| and median log error of the scaled prediction against
    the observed error, and the share of observed errors within 2 x the scaled prediction."""
    rows = []
    for (world, tolerance), one in table.groupby(["world", "tolerance"], sort=True):
        for window in WINDOWS:
            error = np.log(one[window] / one["observed"])
            rows.append({"world": world, "tolerance": tolerance, "window": window, "n": len(one),
                         "mean_abs_log_error": error.abs().mean(), "median_log_error": error.median(),
                         "within_2x": float((one["observed"] <= 2.0 * one[window]).mean())})
    return pd.DataFrame(rows).set_index(["world", "tolerance", "window"])


def _worlds(artifacts: pd.DataFrame) -> pd.Series:
    return artifacts.drop_duplicates("dataset").set_index("dataset")["world"]


def _median(values: np.ndarray) -> float:
    values = values[np.isfinite(values)]
    return float(np.median(values)) if values.size else float("nan")


def _mean(values: np.ndarray) -> float:
    values = values[np.isfinite(values)]
    return float(values.mean()) if values.size else float("nan")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--counts", type=float, nargs=2, default=(6.0, 40.0), metavar=("LOW", "HIGH"))
    parser.add_argument("--params", type=Path, default=None)
    parser.add_argument("--data", type=Path, default=Path("data"))
    args = parser.parse_args()
    params = load_params(args.params)
    artifacts = pd.read_parquet(args.data / "artifacts" / "artifacts.parquet")
    envelopes = pd.read_parquet(args.data / "artifacts" / "envelopes.parquet")
    counts = count_forecasts(artifacts, params.protocol, params.fit, params.predict.models.next_step,
                             params.predict.seed)
    scales = scale_forecasts(artifacts, envelopes, params.protocol)
    with pd.option_context("display.width", 200, "display.max_columns", None, "display.float_format", "{:.3f}".format):
        print("The count, one stop ahead:")
        print(count_summary(counts, tuple(args.counts), params.protocol.envelope.max_failed_fraction))
        print("\nThe observed scale, one stop ahead (before theta_a):")
        print(scale_summary(scales))


if __name__ == "__main__":
    main()
