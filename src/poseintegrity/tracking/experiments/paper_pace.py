"""Accuracy at the paper's pace (III-A on motion (c)): the published sigmas, ours and the no-filter chain measured as
the accuracy figures are, on the accuracy recording's motion slowed to the pace the paper's own numbers allow
(:mod:`~poseintegrity.tracking.simulation.pace`: 0.132 rad/s per Euler angle, 8.9 mm/s per position axis).

The published sigmas trail a hand turning as fast as motion (a) (params.yaml, ``filter``); at this pace a lag of 199.5 ms
alone would give the paper's 1.77 mm / 1.51 deg, so here the claim is tested at the fastest pace the paper's numbers
allow.  The position's lag (Fig. 9's) need not be the orientation's: both are reported."""

from __future__ import annotations

import pandas as pd

from poseintegrity.params.track import TrackParams
from poseintegrity.tracking.experiments.accuracy import accuracy_frames
from poseintegrity.tracking.experiments.filter_runs import FilterResults, experiment_rng, pace_runs
from poseintegrity.tracking.experiments.intervals import lag_interval, rms_interval
from poseintegrity.tracking.experiments.lag import euler_lag_ms, filter_lag_ms
from poseintegrity.tracking.simulation.errors import rms_summary
from poseintegrity.tracking.simulation.pace import paced_motion, trajectory_pace
from poseintegrity.tracking.simulation.simulate import Simulation, run_no_filter, simulate


def pace_recording(params: TrackParams) -> tuple[Simulation, pd.DataFrame, dict]:
    """Motion (c): the accuracy recording (params.motion: its frames, detector, deliberate occlusion) with the OU
    spreads of :func:`~poseintegrity.tracking.simulation.pace.paced_motion`, its no-filter table, and its pace: the
    truth's RMS rates (:func:`~poseintegrity.tracking.simulation.pace.trajectory_pace`), the targets and the spreads."""
    rng = experiment_rng(params, "paper_pace")
    motion = paced_motion(params.motion, params.pace, rng)
    [sim] = simulate(params.model_copy(update={"motion": motion}), rng)
    pace = {"target": {"euler_rad_s": params.pace.euler_rate_rms, "velocity_mm_s": params.pace.velocity_rms * 1000.0},
            **trajectory_pace(sim.trajectory), "omega_std": motion.omega_std, "accel_std": motion.accel_std}
    return sim, run_no_filter(sim, params), pace


def _accuracy(rows: pd.DataFrame, params: TrackParams, name: str) -> dict:
    """The paper's RMS errors of ``rows`` (and ours, :func:`rms_summary`) with the intervals of the paper's two."""
    return {**rms_summary(rows), "intervals": {figure: rms_interval(rows, figure, params, f"paper_pace {name} {figure}")
                                               for figure in ("axis_mm", "euler_deg")}}


def paper_pace(sim: Simulation, no_filter: pd.DataFrame, pace: dict, params: TrackParams, runs: FilterResults) -> tuple[pd.DataFrame, dict]:
    """On motion (c) (sim, no_filter, pace : of :func:`pace_recording`; runs : the results of
    :func:`~.filter_runs.pace_runs`): per run the accuracy figures' measures on the accuracy frames
    (:func:`~.accuracy.accuracy_frames`), the lag behind the no-filter chain (:func:`~.lag.filter_lag_ms`), each
    figure with its block-resampled interval; the orientation's lag (:func:`~.lag.euler_lag_ms`, ours: the error
    w tau of the pace's derivation is the Euler angles' lag times their rate), restarts and gated markers.
    Returns (one row per run, tracking.json's ``paper_pace``)."""
    frames = accuracy_frames(no_filter)
    metrics = {"pace": pace, "no_filter": _accuracy(no_filter[no_filter.frame.isin(frames)], params, "no_filter")}
    for name, run in pace_runs(params).items():
        df, tracker = runs[run]
        out = _accuracy(df[(df.kind == "frame") & df.frame.isin(frames)], params, name)
        out["lag_ms"] = filter_lag_ms(no_filter, df, params.evaluation.lag_max_ms)
        out["intervals"]["lag_ms"] = lag_interval(no_filter, df, params, f"paper_pace {name} lag_ms")
        out["euler_lag_ms"] = euler_lag_ms(sim.trajectory, no_filter, df, params.evaluation.lag_max_ms)
        metrics[name] = {**out, "restarts": tracker.n_restarts, "gated_markers": tracker.n_gated,
                         "share_ok": float((df[df.kind == "frame"].flag == "ok").mean())}
    metrics["n_frames"], metrics["n_accuracy_frames"] = len(no_filter), len(frames)
    rows = [{"run": name, **{k: v for k, v in metrics[name].items() if k != "intervals"}} for name in ("no_filter", *pace_runs(params))]
    return pd.DataFrame(rows), metrics
