"""Intervals on the tracking's headline figures (ours, issue 49): the success rates (III-C) and the UKF's accuracy
(III-A) resampled by blocks of their recording.

Consecutive frames share a motion (a turn lasts 2-4 s), an occlusion and the phantoms of the moment, so a frame is not
an independent trial: the recording is cut into blocks of ``evaluation.interval_block_s`` seconds (5 s: about one turn
and its pause of motion (a)) and the blocks are resampled with replacement (:func:`~poseintegrity.resampling.
cluster_weights`), every figure recomputed on each draw's weighted frames. The summary's verdicts read these intervals
against the paper's values.  The lag is resampled the same way, by the blocks of its reference samples
(:func:`lag_interval`); a mean over several recordings draws the blocks of the same seconds of all of them together
(:func:`mean_rate_interval`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from poseintegrity.params.track import TrackParams
from poseintegrity.resampling import cluster_weights, percentile_interval
from poseintegrity.tracking.experiments.filter_runs import experiment_rng
from poseintegrity.tracking.experiments.lag import block_lag_sums, common_grid, lag_from_ncc, lag_signals, ncc_from_sums

AXES = {"axis_mm": ("dx_mm", "dy_mm", "dz_mm"), "euler_deg": ("dyaw_deg", "dpitch_deg", "droll_deg")}


def block_draws(blocks: np.ndarray, params: TrackParams, name: str) -> np.ndarray:
    """(n_draws, n) weights of n units in blocks ``blocks`` (n,): the distinct blocks resampled with replacement
    (draws of the experiment ``name``'s own generator); distinct blocks give each block's weight."""
    return cluster_weights(blocks, params.evaluation.interval_draws, experiment_rng(params, f"interval {name}"))


def block_weights(t: np.ndarray, params: TrackParams, name: str) -> np.ndarray:
    """(n_draws, n) weights of n frames at times ``t`` (s): blocks of interval_block_s resampled (:func:`block_draws`)."""
    return block_draws(np.floor(np.asarray(t, float) / params.evaluation.interval_block_s), params, name)


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


def mean_rate_interval(tables: Sequence[pd.DataFrame], params: TrackParams, name: str) -> list[float | None]:
    """[low, high] of the mean over recordings of the share of frames with the correct pose (``tables``: columns t,
    correct, one per recording): each draw resamples the blocks once, block b standing for the same interval_block_s
    seconds of every recording, and recomputes every recording's share and their mean."""
    blocks = [np.floor(df["t"].to_numpy(float) / params.evaluation.interval_block_s) for df in tables]
    names, index = np.unique(np.concatenate(blocks), return_inverse=True)
    weights = block_draws(names, params, name)  # (n_draws, k), one column per distinct block
    rates = []
    for df, at in zip(tables, np.split(index, np.cumsum([len(b) for b in blocks])[:-1])):
        counts = np.zeros((len(names), 2))  # per block: frames, correct frames
        np.add.at(counts, at, np.column_stack([np.ones(len(df)), df["correct"].to_numpy(float)]))
        drawn = weights @ counts
        rates.append(drawn[:, 1] / drawn[:, 0])
    return percentile_interval(np.mean(rates, axis=0), params.evaluation.interval_level)


def lag_interval(no_filter: pd.DataFrame, filtered: pd.DataFrame, params: TrackParams, name: str) -> list[float | None]:
    """[low, high] of the filter's lag (ms, :func:`~.lag.filter_lag_ms`, the mean over x, y, z) behind the
    unfiltered chain: the 1 ms grid's samples in blocks of interval_block_s by their reference time, each draw's lag
    the largest correlation of its weighted per-block sums (:func:`~.lag.block_lag_sums`); the same draws for the
    three axes."""
    evaluation, per_axis = params.evaluation, []
    for signals in lag_signals(no_filter, filtered):
        common = common_grid(*signals)
        n_lags = 0 if common is None else min(int(evaluation.lag_max_ms), len(common[0]) // 2)
        if n_lags <= 0:  # nothing to correlate, as normalized_lag_ms
            per_axis.append(np.full(evaluation.interval_draws, np.nan))
            continue
        grid, a, b = common
        names, block = np.unique(np.floor(grid / evaluation.interval_block_s), return_inverse=True)
        sums = block_lag_sums(a, b, block, n_lags)
        weights = block_draws(names, params, name)  # (n_draws, k)
        per_axis.append(lag_from_ncc(ncc_from_sums(np.einsum("dk,kst->dst", weights, sums))))
    return percentile_interval(np.mean(per_axis, axis=0), evaluation.interval_level)
