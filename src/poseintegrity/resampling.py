"""Resampling clusters with replacement, and the percentile interval of what the draws give (issue 49).

A result resting on correlated units is resampled by the clusters they come in, never unit by unit: the arcs of a scene
share its target, layout and boards (prediction/intervals.py); the frames of a tracking recording within a few seconds
share a motion (tracking/experiments/intervals.py). :func:`cluster_weights` gives, per draw, how often each unit's
cluster was drawn, so that any weighted statistic of the units (a mean, an operating point chosen on the weighted
curve) is one matrix product per draw.

Why not ``scipy.stats.bootstrap``: it resamples the observations of one or more samples and evaluates a statistic of
each resample. Here one draw's weights are shared by every statistic of a table (paired differences need the same
draws) and the statistic is a whole selection over it; these few lines keep that visible.
"""

from __future__ import annotations

import numpy as np


def cluster_weights(clusters: np.ndarray, n_draws: int, rng: np.random.Generator) -> np.ndarray:
    """(n_draws, n) weight of each of n units in each draw: how many times its cluster was drawn when the k distinct
    clusters of ``clusters`` (n,) are resampled with replacement, k of them per draw (a cluster bootstrap)."""
    names, index = np.unique(np.asarray(clusters), return_inverse=True)
    drawn = rng.integers(0, len(names), size=(n_draws, len(names)))
    counts = np.zeros((n_draws, len(names)))
    np.add.at(counts, (np.arange(n_draws)[:, None], drawn), 1.0)
    return counts[:, index]


def percentile_interval(values: np.ndarray, level: float) -> list[float | None]:
    """[low, high] : the (1 - level) / 2 and (1 + level) / 2 quantiles of ``values`` (b,), no interpolation (each bound
    is one of the draws). NaN draws are left out, -inf ones (e.g. no operating point) rank lowest; a bound at -inf or
    +inf, or of no draw at all, is None."""
    kept = np.asarray(values, dtype=float)
    kept = kept[~np.isnan(kept)]
    if kept.size == 0:
        return [None, None]
    bounds = np.quantile(kept, [(1 - level) / 2, (1 + level) / 2], method="inverted_cdf")
    return [float(b) if np.isfinite(b) else None for b in bounds]
