"""Speed of stage 04 (predictor sweeps), as ratios against references measured in the same run.

    1. theta_p for all 97 thresholds from one fitted EMG             (vectorized scan + bisection)
       reference: tests/scalar_boundary.py: envelope_boundary called once per threshold (scan + brentq each)
    2. the whole n_t sweep at paper scale                             target: <= 60 s on this machine
       (21 arcs + 4 lines of synthetic eq. 1 data x 10 images per stop, 6 PnP methods; long range,
       its lower-bound variant, MLP and next-step on the paper's path, long range + static on the others)
       reference: the same datasets' long range predictor with the per-threshold reference of 1.
       Prints the fit statuses of the sweep's rows (predictors.json shares them).
    3. leave-one-scene-out folds (stage 04's LOSO) on a random prediction table of the paper's shape
       (7 scenes x 3 arcs, 97 thresholds, 6 predictors, 2 tolerances, 2 target rates)
       reference: loso_folds once per target rate (each rate recomputing the training curves, as before)

Usage: PYTHONPATH=src .venv/bin/python benchmarks/bench_prediction.py [--params params.yaml]
(the ``fit``, ``predict``, ``protocol`` and ``parallel`` sections of --params)
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from poseintegrity.artifact_models import emg, fit_model
from poseintegrity.artifact_models.series import dataset_series
from poseintegrity.artifact_models.synthetic import synthetic_artifacts
from poseintegrity.config import load_section
from poseintegrity.prediction import boundaries, fit_status_shares, loso, loso_folds, sweep
from poseintegrity.prediction.metrics import with_metrics
from poseintegrity.workers import Workers, worker_count
from paired_timing import paired_medians  # benchmarks/paired_timing.py

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from scalar_boundary import envelope_boundary  # noqa: E402 (the scalar reference of the tests)

METHODS = ("usac_magsac", "epnp", "p3p", "ap3p", "sqpnp", "iterative")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--params", type=Path, default=Path("params.yaml"))
    parser.add_argument("--save", type=Path, help="write the sweep's table to this parquet file")
    args = parser.parse_args()
    fit, predict, protocol, parallel = (load_section(args.params, s) for s in ("fit", "predict", "protocol", "parallel"))
    n_t = predict.thresholds
    arc_end = protocol.range_end("arc")

    print(f"1. theta_p for {n_t.size} thresholds from one fitted EMG")
    theta = np.repeat(2.25 * np.arange(1, 5), 10)
    rng = np.random.default_rng(0)
    n = np.maximum(np.round(emg(theta, 3000.0, 9.0, 1.0) + rng.normal(0.0, 4.0, theta.size)), 0.0)
    fitted = fit_model("emg", theta, n, theta_end=arc_end, params=fit, rng=rng)

    def per_threshold() -> list:
        return [envelope_boundary(fitted.predict, t, 2.25, arc_end, n_scan=predict.n_grid) for t in n_t]

    def vectorized() -> object:
        return boundaries(fitted.predict, n_t, 2.25, arc_end, predict.n_grid)

    reference, subject = paired_medians(per_threshold, vectorized, repeats=15)
    print(f"   per-threshold envelope_boundary (reference) {reference * 1e3:8.2f} ms")
    ratio = subject / reference
    print(f"   vectorized boundaries                       {subject * 1e3:8.2f} ms   {ratio:6.3f} x reference")

    print("2. the whole n_t sweep at paper scale (21 arcs + 4 lines, 10 images per stop, 6 PnP methods)")
    artifacts, _ = synthetic_artifacts(np.random.default_rng(1), n_arcs=21, n_lines=4, methods=METHODS)
    start = time.perf_counter()
    for method in METHODS:
        for series in dataset_series(artifacts, method, protocol):
            k = protocol.stops_sampled(series.trajectory)
            model = fit_model("emg", *series.first_stops(k), theta_end=series.theta_end, params=fit, rng=rng)
            first = float(np.min(series.theta))
            [envelope_boundary(model.predict, t, first, series.theta_end, predict.n_grid) for t in n_t]
    reference = time.perf_counter() - start
    start = time.perf_counter()
    with Workers(parallel) as workers:
        table = sweep(artifacts, predict, fit, protocol, workers, progress=False)
    seconds = time.perf_counter() - start
    verdict = "meets" if seconds <= 60.0 else "MISSES"
    print(f"   reference: long range only, per-threshold root finding {reference:7.2f} s")
    print(f"   whole sweep ({len(table)} rows, {worker_count(parallel)} workers)     {seconds:7.2f} s   "
          f"{seconds / reference:6.2f} x reference   [{verdict} target 60 s]")  # fmt: skip
    print("   share of rows per fit status:")
    for predictor, entry in fit_status_shares(table).items():
        print(f"     {predictor:<20s} " + "  ".join(f"{k} {v:.4g}" for k, v in entry.items()))
    if args.save:
        table.to_parquet(args.save, index=False)

    print("3. leave-one-scene-out folds")
    predictions = random_predictions(np.random.default_rng(2), n_t)
    predictors = tuple(predictions["predictor"].unique())

    def per_rate() -> pd.DataFrame:
        return pd.concat([loso_folds(group, (rate,), conservative_high=predictor != "static")
                          for (predictor, _), group in predictions.groupby(["predictor", "tolerance"])
                          for rate in predict.loso_target_rates], ignore_index=True)  # fmt: skip

    def all_rates() -> pd.DataFrame:
        return loso(predictions, predict.loso_target_rates, predictors, "usac_magsac")

    reference, subject = paired_medians(per_rate, all_rates, repeats=3)
    print(f"   loso_folds per target rate (reference)      {reference * 1e3:8.1f} ms")
    print(f"   loso (one training curve for all rates)     {subject * 1e3:8.1f} ms   {subject / reference:6.3f} x reference")


def random_predictions(rng: np.random.Generator, n_t: np.ndarray) -> pd.DataFrame:
    """A prediction table of stage 04's shape for one method and the arcs: theta_p falling with n_t, theta_a fixed."""
    rows = []
    for predictor in ("long_range", "mlp", "next_step", "static", "long_range_relative", "next_step_relative"):
        for tolerance in ("2mm_3deg", "4mm_10deg"):
            for dataset in (f"scene_{s}_arc{a}" for s in range(7) for a in range(3)):
                theta_p = np.sort(rng.uniform(0.0, 45.0, n_t.size))[::-1]
                rows.append(pd.DataFrame({"predictor": predictor, "method": "usac_magsac", "trajectory": "arc",
                                          "tolerance": tolerance, "dataset": dataset, "operating_point": n_t,
                                          "theta_p": theta_p, "theta_a": rng.uniform(10.0, 45.0)}))  # fmt: skip
    return with_metrics(pd.concat(rows, ignore_index=True))


if __name__ == "__main__":
    main()
