"""Intervals on the tracking's headline figures (ours, issue 49): the success rates (III-C) and the UKF's accuracy
(III-A) resampled by blocks of their recording.

Consecutive frames share a motion (a turn lasts 2-4 s), an occlusion and the phantoms of the moment, so a frame is not
an independent trial: the recording is cut into blocks of ``evaluation.interval_block_s`` seconds (5 s: about one turn
and its pause of motion (a)) and the blocks are resampled with replacement (:func:`~poseintegrity.resampling.
cluster_weights`), every figure recomputed on each draw's weighted frames. The summary's verdicts read these intervals
against the paper's values.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.params.track import TrackParams
from poseintegrity.resampling import cluster_weights, percentile_interval
from poseintegrity.tracking.experiments.filter_runs import experiment_rng

AXES = {"axis_mm": ("dx_mm", "dy_mm", "dz_mm"), "euler_deg": ("dyaw_deg", "dpitch_deg", "droll_deg")}


def block_weights(t: np.ndarray, params: TrackParams, name: str) -> np.ndarray:
    """(n_draws, n) weights of n frames at times ``t`` (s): blocks of interval_block_s resampled (draws of the
    experiment ``name``'s own generator)."""
    evaluation = params.evaluation
    return cluster_weights(np.floor(np.asarray(t, float) / evaluation.interval_block_s), evaluation.interval_draws,
                           experiment_rng(params, f"interval {name}"))


def rate_interval(frames: pd.DataFrame, params: TrackParams, name: str) -> list[float | None]:
    """[low, high] of the share of frames with the correct pose (``frames``: columns t, correct)."""
    weights = block_weights(frames["t"], params, name)
    rates = (weights @ frames["correct"].to_numpy(float)) / weights.sum(axis=1)
    return percentile_interval(rates, params.evaluation.interval_level)


def rms_interval(rows: pd.DataFrame, figure: str, params: TrackParams, name: str) -> list[float | None]:
    """[low, high] of the paper's mean of per-axis RMS errors (``figure``: "axis_mm" over dx, dy, dz or "euler_deg"
    over the three Euler angles, :func:`~poseintegrity.tracking.simulation.errors.rms_summary`) of ``rows`` (columns
    t and those errors; non-finite values left out, as there)."""
    weights = block_weights(rows["t"], params, name)
    per_axis = []
    for column in AXES[figure]:
        values = rows[column].to_numpy(float)
        finite = np.isfinite(values)
        with np.errstate(invalid="ignore", divide="ignore"):
            per_axis.append(np.sqrt((weights @ np.where(finite, values, 0.0) ** 2) / (weights @ finite)))
    return percentile_interval(np.mean(per_axis, axis=0), params.evaluation.interval_level)
