"""A synthetic artifacts table drawn from eq. 1 + noise, with the schema of stage 02's ``artifacts.parquet``.

For tests and benchmarks of stage 03 without rendered datasets; the true EMG parameters of every dataset
are returned so that fits can be checked against them.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.artifact_models.base_functions import emg, emg_pdf

# The datasets of Windsor et al. IV-D: arcs stop every 2.25 deg from the model view (0 .. 42.75 deg), lines every
# 10 mm from their start (0 .. 140 mm).
ARC_THETA_DEG = 2.25 * np.arange(20)
LINE_X_MM = 10.0 * np.arange(15)
# Ranges of the true eq. 1 parameters (K, mu in the trajectory's unit) and of the peak count. The counts peak at
# the trajectory start (the model view, where the images match the model best), so mu lies before the first stop.
TRUTH_RANGES = {"arc": {"K": (6.0, 14.0), "mu": (-4.0, 0.0)}, "line": {"K": (30.0, 60.0), "mu": (-10.0, 0.0)}}
PEAK_RANGE = (150.0, 400.0)
MIN_INLIERS_OK = 6  # below this a frame is reported failed ("too_few_inliers")


def synthetic_artifacts(
    rng: np.random.Generator,
    n_arcs: int = 21,
    n_lines: int = 4,
    images_per_stop: int = 10,
    methods: tuple[str, ...] = ("usac_magsac", "epnp"),
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Draw (artifacts, truth).

    artifacts : one row per image and method: world ("main"), dataset, trajectory, stop, image, theta_deg, x_mm, method,
        n_inliers (round(f + N(0, (2 + 0.1 f)^2)), clipped at 0), status
    truth : one row per (dataset, method): trajectory, method, alpha, K, mu of eq. 1 in the unit of the
        trajectory's variable (deg for arcs, mm for lines)
    """
    rows, truth = [], []
    datasets = [("arc", f"arc_{i:02d}") for i in range(n_arcs)] + [("line", f"line_{i:02d}") for i in range(n_lines)]
    for trajectory, dataset in datasets:
        stops = ARC_THETA_DEG if trajectory == "arc" else LINE_X_MM
        variable = np.repeat(stops, images_per_stop)
        for method in methods:
            K, mu = (rng.uniform(*TRUTH_RANGES[trajectory][key]) for key in ("K", "mu"))
            peak_pdf = emg_pdf(np.linspace(-5.0, 5.0 * K, 2001), K).max()
            alpha = rng.uniform(*PEAK_RANGE) / peak_pdf
            f = emg(variable, alpha, K, mu)
            n_inliers = np.maximum(np.round(f + rng.normal(0.0, 2.0 + 0.1 * f)), 0).astype(int)
            truth.append(
                {"dataset": dataset, "trajectory": trajectory, "method": method, "alpha": alpha, "K": K, "mu": mu}
            )
            rows.append(
                pd.DataFrame(
                    {
                        "world": "main",
                        "dataset": dataset,
                        "trajectory": trajectory,
                        "stop": np.repeat(np.arange(stops.size), images_per_stop),
                        "image": np.arange(variable.size),
                        "theta_deg": variable if trajectory == "arc" else 0.0,
                        "x_mm": variable if trajectory == "line" else 0.0,
                        "method": method,
                        "n_inliers": n_inliers,
                        "status": np.where(n_inliers >= MIN_INLIERS_OK, "ok", "too_few_inliers"),
                    }
                )
            )
    return pd.concat(rows, ignore_index=True), pd.DataFrame(truth)
