"""Accuracy and occlusion (III-A, III-B): errors of the no-filter chain and of the filters against ground truth, the
paper's way and ours, the occluded frames, noise against lag, and the published sigmas against ours."""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.tracking.simulation.errors import rms, rms_summary
from poseintegrity.params.track import PAPER_SIGMAS, TrackParams
from poseintegrity.tracking.simulation.simulate import Simulation, run_no_filter, simulate
from poseintegrity.tracking.experiments.filter_runs import (
    experiment_rng, FilterResults, accuracy_runs, agreement_runs, sweep_runs, sigma_runs, filter_agreement,
)
from poseintegrity.tracking.experiments.lag import filter_lag_ms


def accuracy_frames(no_filter: pd.DataFrame) -> np.ndarray:
    """Frames on which accuracy is compared: correct unfiltered pose, outside deliberate occlusions."""
    return no_filter.frame[no_filter.correct & ~no_filter.in_occlusion].to_numpy()


def summarize_accuracy(no_filter: pd.DataFrame, runs: dict[str, pd.DataFrame]) -> dict[str, dict[str, float]]:
    """Per run (no_filter and every filter run) the RMS errors of :func:`~poseintegrity.tracking.simulation.errors.rms_summary`
    on the frames of :func:`accuracy_frames` (the filter rows of those marker frames)."""
    frames = accuracy_frames(no_filter)
    out = {"no_filter": rms_summary(no_filter[no_filter.frame.isin(frames)])}
    for name, df in runs.items():
        out[name] = rms_summary(df[(df.kind == "frame") & df.frame.isin(frames)])
    return out


def occlusion_summary(runs: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """Orientation held through the deliberate occlusions (Fig. 8): per run, the RMS rotation error inside
    the occlusion windows and the share of their events with a running filter."""
    rows = []
    for name, df in runs.items():
        inside = df[df.in_occlusion]
        share = float(np.isfinite(inside.rot_err_deg).mean()) if len(inside) else float("nan")
        rows.append({"run": name, "rms_deg": rms(inside.rot_err_deg), "share_tracked": share})
    return pd.DataFrame(rows)


# -- experiments ---------------------------------------------------------------------------------------------


def accuracy_recording(params: TrackParams) -> tuple[Simulation, pd.DataFrame]:
    """The accuracy recording (params.motion, with its deliberate occlusion) and its no-filter table."""
    [sim] = simulate(params, experiment_rng(params, "accuracy"))
    return sim, run_no_filter(sim, params)


def accuracy_and_occlusion(sim: Simulation, no_filter: pd.DataFrame, params: TrackParams, runs: FilterResults) -> tuple[dict[str, pd.DataFrame], dict]:
    """On the accuracy recording: no filter, UKF, UKF + gyro; RMS errors both ways, lag, orientation through
    the occlusion, restarts, failed downdates, SR-UKF vs plain UKF.  runs : the results of :func:`~.filter_runs.accuracy_runs`
    and :func:`~.filter_runs.agreement_runs`."""
    named = {name: runs[run] for name, run in accuracy_runs(params).items()}
    frames, trackers = {name: df for name, (df, _) in named.items()}, {name: t for name, (_, t) in named.items()}
    occlusion = occlusion_summary(frames)
    metrics = {
        "rms": summarize_accuracy(no_filter, frames),
        "lag_ms": {name: filter_lag_ms(no_filter, df, params.evaluation.lag_max_ms) for name, df in frames.items()},
        "occlusion_rms_deg": dict(zip(occlusion.run, occlusion.rms_deg)),
        "occlusion_share_tracked": dict(zip(occlusion.run, occlusion.share_tracked)),
        "failed_downdates": int(sum(t.filter.failed_downdates for t in trackers.values())),
        "filter_steps": {name: int((df.flag == "ok").sum()) for name, df in frames.items()},
        "divergences": {name: t.filter.n_divergences for name, t in trackers.items()},
        "restarts": {name: t.n_restarts for name, t in trackers.items()},
        "gated_markers": {name: t.n_gated for name, t in trackers.items()},
        "srukf_vs_ukf_max_rel_diff": {name: filter_agreement(runs, pair) for name, pair in agreement_runs(params).items()},
        "n_frames": int(len(sim.t)),
    }
    return {"no_filter": no_filter, **frames, "occlusion": occlusion}, metrics


def noise_against_lag(no_filter: pd.DataFrame, params: TrackParams, runs: FilterResults) -> pd.DataFrame:
    """Noise-vs-lag trade-off (Figs. 6, 9) from the runs of :func:`~.filter_runs.sweep_runs`: sigma_c and sigma_alpha scaled
    by evaluation.sigma_scales.  One row per scale: RMS position (mm) and rotation (deg) error and lag (ms) of
    the UKF without gyro."""
    rows, frames = [], accuracy_frames(no_filter)
    for scale, run in sweep_runs(params).items():
        df, _ = runs[run]
        at_frames = df[(df.kind == "frame") & df.frame.isin(frames)]
        rows.append({"scale": scale, "rms_mm": rms(at_frames.pos_err_mm), "rms_deg": rms(at_frames.rot_err_deg),
                     "lag_ms": filter_lag_ms(no_filter, df, params.evaluation.lag_max_ms)})
    return pd.DataFrame(rows)


def published_against_our_sigmas(no_filter: pd.DataFrame, params: TrackParams, runs: FilterResults) -> tuple[pd.DataFrame, dict]:
    """On motion (a) (4 markers; no_filter : its no-filter table): the UKF with the published sigmas and with
    ours, no gyro; the two halves swapped (published measurement sigma_r with our process sigmas, and the
    reverse) to see which half makes the difference; and the published process sigmas read as per-second
    intensities (:func:`~.filter_runs.sigma_variants`, run as :func:`~.filter_runs.sigma_runs`).  Eq. 30 adds dt^2 sigma^2 to omega's
    variance at every filter step, so over one second the variance grows by dt sigma^2: the published
    sigma_alpha = 0.71 rad/s^2 at the 400 Hz clock lets omega drift 0.035 rad/s in a second.  Read as a
    per-second intensity (variance sigma^2 per second, clock-independent) it is sigma / sqrt(dt / 1 s) per
    step.  RMS both ways on the correct no-filter frames, lag behind the no-filter signal, and how often the
    filter was gated or restarted."""
    frames = accuracy_frames(no_filter)
    rows, metrics = [], {}
    for name, run in sigma_runs(params).items():
        df, tracker = runs[run]
        summary = rms_summary(df[(df.kind == "frame") & df.frame.isin(frames)])
        lag = filter_lag_ms(no_filter, df, params.evaluation.lag_max_ms)
        frames_df = df[df.kind == "frame"]
        metrics[name] = {**summary, "lag_ms": lag, "restarts": tracker.n_restarts, "gated_markers": tracker.n_gated,
                         "share_ok": float((frames_df.flag == "ok").mean()), **{k: getattr(run.settings, k) for k in PAPER_SIGMAS}}
        rows.append({"sigmas": name, **metrics[name]})
    metrics["no_filter"] = rms_summary(no_filter[no_filter.frame.isin(frames)])
    return pd.DataFrame(rows), metrics
