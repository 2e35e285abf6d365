"""Synthetic stage-02 tables for the predictor tests: eq. 1 + noise with scene-style dataset ids and known envelopes.

The actual envelope theta_a of a dataset is set where its *true* EMG falls to a failure count (one per
tolerance of the protocol), so a predictor with n_t near that count is right on average and the answers are known.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from scalar_boundary import envelope_boundary
from poseintegrity.artifact_models.base_functions import emg
from poseintegrity.artifact_models.synthetic import synthetic_artifacts
from poseintegrity.params.protocol import FAILED_FRAME_RULES, ProtocolParams

FAILURE_COUNTS = (60.0, 40.0)  # true inlier count at which localization fails, per tolerance (tighter first)


def scene_tables(protocol: ProtocolParams, seed: int = 0, n_arcs: int = 6, n_lines: int = 2, images_per_stop: int = 3,
                 methods: tuple[str, ...] = ("usac_magsac", "epnp"), world: str = "main",
                 ) -> tuple[pd.DataFrame, pd.DataFrame]:  # fmt: skip
    """(artifacts, envelopes) of ``world`` with datasets ``scene_<s>_arc<i>`` (s = 1, 2, 3 in turn) and
    ``scene_<s>_line<i>`` (another world's prefixed ``<world>_``); envelopes for each tolerance of ``protocol`` (two),
    up to its range ends, the same under every failed-frame rule (stage 02 writes one row per rule)."""
    failure_count = dict(zip(protocol.tolerance_names, FAILURE_COUNTS, strict=True))
    artifacts, truth = synthetic_artifacts(
        np.random.default_rng(seed), n_arcs=n_arcs, n_lines=n_lines, images_per_stop=images_per_stop, methods=methods
    )
    names = {}
    prefix = "" if world == "main" else f"{world}_"
    for i in range(n_arcs):
        names[f"arc_{i:02d}"] = f"{prefix}scene_{i % 3 + 1}_arc{i:02d}"
    for i in range(n_lines):
        names[f"line_{i:02d}"] = f"{prefix}scene_{i % 3 + 1}_line{i:02d}"
    artifacts = artifacts.assign(dataset=artifacts["dataset"].map(names), world=world)
    truth = truth.assign(dataset=truth["dataset"].map(names))
    rows = []
    for t in truth.itertuples():
        f = lambda theta, t=t: emg(theta, t.alpha, t.K, t.mu)  # noqa: E731
        first = 0.0  # IV-D: the first stop is the trajectory start
        end = protocol.range_end(t.trajectory)
        for tolerance, count in failure_count.items():
            found = envelope_boundary(f, count, first, end)
            theta_a = found.theta_p if found.status == "root" else (first if found.status == "below_at_start"
                                                                    else end)  # fmt: skip
            rows += [dict(world=world, dataset=t.dataset, trajectory=t.trajectory, tolerance=tolerance, method=t.method,
                          rule=rule, theta_a=theta_a, censored=found.status == "censored")
                     for rule in FAILED_FRAME_RULES]  # fmt: skip
    return artifacts, pd.DataFrame(rows)


def headline_rows(envelopes: pd.DataFrame, protocol: ProtocolParams) -> pd.DataFrame:
    """The envelopes of the headline failed-frame rule, as stage 04 scores them."""
    return envelopes[envelopes["rule"] == protocol.envelope.failed_frames].drop(columns="rule")

