"""Tiny ``predict`` / ``fit`` sections and synthetic stage-02 tables for the predictor tests.

The tables are eq. 1 + noise with scene-style dataset ids and known envelopes.

The actual envelope theta_a of a dataset is set where its *true* EMG falls to a failure count (one per
tolerance), so a predictor with n_t near that count is right on average and the answers are known.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from scalar_boundary import envelope_boundary
from poseintegrity.artifact_models.base_functions import emg
from poseintegrity.artifact_models.synthetic import synthetic_artifacts

FAILURE_COUNT = {"2mm_3deg": 60.0, "4mm_10deg": 40.0}  # true inlier count at which localization fails
RANGE_END = {"arc": 45.0, "line": 150.0}


def scene_tables(seed: int = 0, n_arcs: int = 6, n_lines: int = 2, images_per_stop: int = 3,
                 methods: tuple[str, ...] = ("usac_magsac", "epnp")) -> tuple[pd.DataFrame, pd.DataFrame]:  # fmt: skip
    """(artifacts, envelopes) with datasets ``scene_<s>_arc<i>`` (s = 1, 2, 3 in turn) and ``scene_<s>_line<i>``."""
    artifacts, truth = synthetic_artifacts(
        np.random.default_rng(seed), n_arcs=n_arcs, n_lines=n_lines, images_per_stop=images_per_stop, methods=methods
    )
    names = {}
    for i in range(n_arcs):
        names[f"arc_{i:02d}"] = f"scene_{i % 3 + 1}_arc{i:02d}"
    for i in range(n_lines):
        names[f"line_{i:02d}"] = f"scene_{i % 3 + 1}_line{i:02d}"
    artifacts = artifacts.assign(dataset=artifacts["dataset"].map(names))
    truth = truth.assign(dataset=truth["dataset"].map(names))
    rows = []
    for t in truth.itertuples():
        f = lambda theta, t=t: emg(theta, t.alpha, t.K, t.mu)  # noqa: E731
        first = 0.0  # IV-D: the first stop is the trajectory start
        for tolerance, count in FAILURE_COUNT.items():
            found = envelope_boundary(f, count, first, RANGE_END[t.trajectory])
            theta_a = found.theta_p if found.status == "root" else (first if found.status == "below_at_start"
                                                                    else RANGE_END[t.trajectory])  # fmt: skip
            rows.append(dict(dataset=t.dataset, trajectory=t.trajectory, tolerance=tolerance, method=t.method,
                             theta_a=theta_a, censored=found.status == "censored"))  # fmt: skip
    return artifacts, pd.DataFrame(rows)


# The tiny ``predict`` section used by the tests (and, in YAML, by the notebook test).
TINY_PREDICT = {
    "pnp_method": "usac_magsac",
    "n_t_min": 4,
    "n_t_max": 100,
    "relative_min": 0.02,
    "relative_max": 0.5,
    "relative_step": 0.04,
    "long_range_stops_arc": 4,
    "long_range_stops_line": 5,
    "next_step_first_stops": 4,
    "static_max_deg": 45.0,
    "static_max_mm": 150.0,
    "n_static": 91,
    "tolerance_fig6_fig7": "2mm_3deg",
    "n_grid": 256,
    "models": {"long_range": "emg", "next_step": "emg", "mlp": "mlp_pretrained"},
    "live_n_t": 15,
    "live_tolerance": "4mm_10deg",
    "loso_target_rates": [0.0, 0.05],
    "uncertainty": {"method": "covariance", "level": 0.9, "n_bootstrap": 20},
    "seed": 11,
    "n_jobs": 1,
}
TINY_FIT = {
    "pnp_method": "usac_magsac",
    "models": ["emg", "mlp_pretrained"],
    "k_min": 3, "k_max": 6, "k_report_arc": 4, "k_report_line": 5,
    "theta_max_deg": 45.0, "x_max_mm": 150.0, "max_nfev": 400, "seed": 7, "n_jobs": 1,
    "mlp": {"hidden_layers": 3, "hidden_units": 10, "max_iter_scratch": 20, "max_iter_pretrain": 20,
            "max_iter_finetune": 10, "tolerance_change": 1e-12, "n_pretrain_points": 20, "n_artificial": 10},
}  # fmt: skip
