"""The discrete-time hazard's training rows: which stops were at risk, and which failed (issue 50).

The failure hazard at stop j is the probability that stop j fails (its mean error beyond the tolerance, or too few
poses: theta_a <= theta_j, IV-E) given that the arc has not failed before it (theta_a > theta_{j-1}). An arc is in
the risk set up to and including the stop where it fails, and leaves it then; an arc censored at its last stop
(it never failed: theta_a is its last stop, ``censored``) contributes only stops that did not fail. theta_a comes from stage 02's envelopes of the paper's
failed-frame rule (the ground truth: used to label the training worlds' rows, never read by a prediction).

    next_step_rows   at every stop i from the last sampled one on: the evidence of stop i, and whether stop i + 1
                     fails
    long_range_rows  for every stop j after the first: the evidence of the last sampled stop, how far ahead
                     of it j lies (``ahead_deg``, negative for a sampled stop), and whether stop j fails. The sampled
                     stops are in it as the paper's long range predictor's fit is: it may put the envelope's end
                     among them (theta_p from theta_1, III-E), and on the population 2 of 12 worlds have an arc that
                     fails there at 2 mm / 3 deg (w01: 3.9 deg, w07: 6.7 deg, before the 4th stop's 6.75)
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.prediction.hazard.stop_evidence import EVIDENCE, KEYS

AHEAD = ("ahead_deg", "ahead_deg_squared")  # the long range model's extra columns: the turn from the last sample
INTERACTED = ("log_inliers", "predicted_error", "model_coverage", "bootstrap_spread")  # x ahead_deg, per stop ahead
LONG_RANGE = (*EVIDENCE, *AHEAD, *(f"{level}_x_ahead" for level in INTERACTED))  # the long range model's columns


def _with_envelopes(evidence: pd.DataFrame, envelopes: pd.DataFrame) -> pd.DataFrame:
    """``evidence`` joined to each arc's theta_a (deg) and censored flag; arcs without a read theta_a dropped."""
    known = envelopes[["world", "dataset", "theta_a", "censored"]].dropna(subset=["theta_a"])
    return evidence.merge(known, on=["world", "dataset"], how="inner")


def next_step_rows(evidence: pd.DataFrame, envelopes: pd.DataFrame, n_sampled_stops: int) -> pd.DataFrame:
    """One row per arc and stop i >= n_sampled_stops - 1 (0-based) at risk with a next stop: EVIDENCE of stop i,
    ``theta_deg``, ``theta_next`` and ``failed`` (stop i + 1 fails: theta_a <= theta_{i+1}). evidence :
    :func:`~.stop_evidence.stop_evidence`; envelopes : one tolerance's envelopes (world, dataset, theta_a, censored),
    deg."""
    table = _with_envelopes(evidence, envelopes).sort_values(KEYS, kind="stable")
    by_arc = table.groupby(["world", "dataset"], sort=False)
    table = table.assign(theta_next=by_arc["theta_deg"].shift(-1), position=by_arc.cumcount())
    at_risk = ((table["position"] >= n_sampled_stops - 1) & table["theta_next"].notna()
               & (table["theta_a"] > table["theta_deg"]))
    rows = table[at_risk]
    failed = (rows["theta_a"] <= rows["theta_next"]) & ~rows["censored"].astype(bool)
    return rows.assign(failed=failed.astype(int)).drop(
        columns="position").reset_index(drop=True)


def long_range_features(sampled: pd.DataFrame, theta: np.ndarray) -> pd.DataFrame:
    """The long range model's columns for stops at ``theta`` (deg) ahead of one arc's last sampled stop.
    sampled : that stop's evidence row (a Series with EVIDENCE and theta_deg); theta : (J,) deg -> (J, LONG_RANGE)."""
    ahead = np.asarray(theta, dtype=float) - float(sampled["theta_deg"])
    columns = {name: np.full(ahead.shape, float(sampled[name])) for name in EVIDENCE}
    columns |= {"ahead_deg": ahead, "ahead_deg_squared": ahead**2}
    columns |= {f"{level}_x_ahead": columns[level] * ahead for level in INTERACTED}
    return pd.DataFrame(columns, columns=list(LONG_RANGE))


def long_range_rows(evidence: pd.DataFrame, envelopes: pd.DataFrame, n_sampled_stops: int) -> pd.DataFrame:
    """One row per arc and stop j >= 1 (0-based) at risk (theta_a > theta_{j-1}): the LONG_RANGE columns from the
    last sampled stop's evidence (stop ``n_sampled_stops`` - 1), world, dataset, ``theta_deg`` (of stop j) and
    ``failed`` (stop j fails: theta_a <= theta_j). An arc with fewer than ``n_sampled_stops`` stops gives none."""
    table = _with_envelopes(evidence, envelopes).sort_values(KEYS, kind="stable")
    rows = []
    for (world, dataset), arc in table.groupby(["world", "dataset"], sort=True):
        if len(arc) < max(n_sampled_stops, 2):
            continue
        theta = arc["theta_deg"].to_numpy()
        theta_a = float(arc["theta_a"].iloc[0]) if not bool(arc["censored"].iloc[0]) else np.inf
        at_risk = np.flatnonzero(theta_a > theta[:-1]) + 1  # stops j whose previous stop had not failed
        features = long_range_features(arc.iloc[n_sampled_stops - 1], theta[at_risk])
        rows.append(features.assign(world=world, dataset=dataset, theta_deg=theta[at_risk],
                                    failed=(theta_a <= theta[at_risk]).astype(int)))
    columns = [*LONG_RANGE, "world", "dataset", "theta_deg", "failed"]
    return pd.concat(rows, ignore_index=True)[columns] if rows else pd.DataFrame(columns=columns)
