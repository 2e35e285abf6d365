"""Section III on our simulation: :func:`run_study` runs every experiment of this package (one module each).

Each experiment draws from its own generator, ``keyed_rng(params.seed, name)`` (:mod:`poseintegrity.seeding`), so the
experiments do not depend on each other's order and the per-frame tables are bit-identical for one seed
(timings are the only non-deterministic outputs and are kept apart).  That lets :func:`run_study` run them as
independent tasks on :class:`~poseintegrity.workers.Workers`: first the recordings (render + detect + the
no-filter chain) and the self-contained scenes, then every distinct filter run over those recordings once
(:class:`~.filter_runs.FilterRun`; an experiment that needs a run another already made reuses it), then the timings
in the calling process, alone on the machine.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd

from poseintegrity.paper_results import BLACK_RESULTS
from poseintegrity.params.track import TrackParams
from poseintegrity.tracking.experiments.filter_runs import experiment_rng, study_filter_runs, run_filter_task
from poseintegrity.tracking.experiments.peers import filter_speed, pykalman_time_update
from poseintegrity.tracking.experiments.small_blobs import small_blob_sweep, sweep_summary
from poseintegrity.workers import Workers
from poseintegrity.tracking.experiments.accuracy import (
    accuracy_frames, accuracy_recording, accuracy_and_occlusion, noise_against_lag, published_against_our_sigmas,
)
from poseintegrity.tracking.experiments.success import (
    SuccessRun, success_runs, success_recording, success_rates, two_tools_success,
)
from poseintegrity.tracking.experiments.compute_time import timing_table
from poseintegrity.tracking.experiments.intervals import mean_rate_interval, rate_interval, rms_interval
from poseintegrity.tracking.experiments.paper_pace import pace_recording, paper_pace
from poseintegrity.tracking.experiments.robustness import ten_metre_jump, recording_replay
from poseintegrity.tracking.simulation.pace import trajectory_pace


@dataclass(frozen=True)
class Study:
    """Everything section III reports, on our simulation (see :func:`run_study`).

    tables : per-frame / per-event results to write as parquet (bit-identical for one seed);
    metrics : the tracking.json content (the same for one seed, on any machine);
    timing : Table I-like timings (ms); speed : the SR-UKF's step times (ms) and its speed-ups over filterpy and
    pykalman, with the timing table's means (``subroutine_ms``): machine-dependent, so never in a metrics file
    (notebook 06 writes them under ``reports/metrics/timing/subroutines/``).
    """

    tables: dict[str, pd.DataFrame]
    timing: pd.DataFrame
    metrics: dict
    speed: dict


def call(task: Callable[[], object]) -> object:
    """task(): what :meth:`~poseintegrity.workers.Workers.map` runs for a list of heterogeneous tasks
    (``functools.partial`` of module-level functions)."""
    return task()


def run_study(params: TrackParams, recording_folder: Path, workers: Workers) -> Study:
    """Section III on our simulation: every experiment above, their tables and the metrics of tracking.json.

    recording_folder : where :func:`~.robustness.recording_replay` writes the replayed recording.  workers : where the
    recordings, scenes and filter runs run (tasks of their own generators, so the tables do not depend on
    the number of workers); the timings run in this process afterwards, with no task of ours beside them.
    Two rounds of tasks, each listed longest first so that the workers finish together: first the recordings
    the filter runs need (accuracy; motion (a), 4 markers; motion (c), the paper's pace) beside one stress recording (rendered once,
    detected twice: the longest) and the small scenes; then the filter runs beside the other recordings.
    """
    ev, hand = params.evaluation, SuccessRun("a", "markers4", -1)
    others = sorted((run for run in success_runs(params) if run != hand), key=lambda run: run.motion != "b")  # (b) first
    first = [partial(success_recording, params, others[0]), partial(success_recording, params, hand, True), partial(accuracy_recording, params),
             partial(pace_recording, params),
             partial(two_tools_success, params, params.motion.max_phantoms, "two_tools"),
             partial(two_tools_success, params, ev.phantom_rich_max, "two_tools_phantom_rich"),
             partial(small_blob_sweep, params, experiment_rng(params, "small_blobs")),
             partial(recording_replay, params, Path(recording_folder).resolve())]
    stress, motion_a, (sim, no_filter), (pace_sim, pace_no_filter, pace), tools, rich_tools, blobs, (replay, replay_metrics) = \
        workers.map(call, first, desc="tracking recordings")
    recordings = {"accuracy": sim, "hand": motion_a["a_markers4"][1], "pace": pace_sim}
    filter_runs = study_filter_runs(params)
    second = [partial(success_recording, params, run) for run in others[1:]]
    second += [partial(run_filter_task, recordings[run.recording], params, run) for run in filter_runs]
    results = workers.map(call, second, desc="tracking recordings and filter runs")
    runs = dict(zip(filter_runs, results[len(others) - 1 :]))
    success_tables = {name: table for recorded in [stress, motion_a, *results[: len(others) - 1]] for name, (table, _) in recorded.items()}

    tables, accuracy = accuracy_and_occlusion(sim, no_filter, params, runs)
    success, success_frames = success_rates(params, success_tables)
    sigmas, sigma_metrics = published_against_our_sigmas(success_tables["a_markers4"], params, runs)
    pace["other_recordings"] = {name: trajectory_pace(recording.trajectory) for name, recording in (("accuracy", sim), ("motion_a", recordings["hand"]))}
    pace_table, pace_metrics = paper_pace(pace_sim, pace_no_filter, pace, params, runs)
    multi_tool = pd.concat([tools, rich_tools], ignore_index=True)
    geometry = np.array(params.markers_body)
    speed = filter_speed(geometry, params.filter, ev.timing_repeats, experiment_rng(params, "speed"))
    rate = dict(zip(success.run, success.rate))
    removals = [f"a_{run.label}" for run in success_runs(params) if run.motion == "a" and run.dropped >= 0]  # each marker removed
    rate["a_markers3_mean"] = float(np.mean([rate[run] for run in removals]))  # the claim's: the paper does not say which
    ukf = tables["ukf"]
    ukf_rows = ukf[(ukf.kind == "frame") & ukf.frame.isin(accuracy_frames(no_filter))]
    intervals = {  # ours (issue 49): the headline rates and errors, blocks of their recording resampled
        "success_rates": {run: rate_interval(success_frames[f"success_{run}"], params, run)
                          for run in dict.fromkeys(["a_markers4", "a_markers3", "b_markers4", "b_markers3", *removals])}
                         | {"a_markers3_mean": mean_rate_interval([success_frames[f"success_{run}"] for run in removals], params, "a_markers3_mean")},
        "rms_axis_mm": {"ukf": rms_interval(ukf_rows, "axis_mm", params, "ukf axis_mm")},
        "rms_euler_deg": {"ukf": rms_interval(ukf_rows, "euler_deg", params, "ukf euler_deg")},
        "block_s": params.evaluation.interval_block_s, "level": params.evaluation.interval_level,
        "n_draws": params.evaluation.interval_draws}
    metrics = {
        **accuracy,
        "rms_mm": {run: v["norm_mm"] for run, v in accuracy["rms"].items()},
        "rms_deg": {run: v["geodesic_deg"] for run, v in accuracy["rms"].items()},
        "rms_axis_mm": {run: v["axis_mm"] for run, v in accuracy["rms"].items()},
        "rms_euler_deg": {run: v["euler_deg"] for run, v in accuracy["rms"].items()},
        "euler_convention": "Unity: R = R_y R_x R_z (scipy intrinsic 'YXZ'); mean over the three angles of the RMS wrapped difference",
        "success_rate": {"markers4": rate["a_markers4"], "markers3": rate["a_markers3"]},
        "success_rates": rate,
        "success_possible": dict(zip(success.run, success.possible)),
        "intervals": intervals,
        "sigmas_motion_a": sigma_metrics,
        "paper_pace": pace_metrics,
        "small_blobs": sweep_summary(blobs),
        "multi_tool_success": multi_tool.groupby(["scene", "tool"]).correct.mean().unstack().to_dict(orient="index"),
        "ten_metre_jump": ten_metre_jump(sim, params),
        "recording_replay": replay_metrics,
        "pykalman_time_update_max_diff": pykalman_time_update(geometry, params.filter, experiment_rng(params, "pykalman")),
        "paper": BLACK_RESULTS,
    }
    tables = {**tables, "sigma_sweep": noise_against_lag(no_filter, params, runs), "success": success, **success_frames,
              "sigmas_motion_a": sigmas, "paper_pace": pace_table, "small_blobs": blobs, "multi_tool": multi_tool, "replay_poses": replay}
    timing = timing_table(sim, params)
    speed = {"speedup_vs_filterpy": speed["speedup_vs_filterpy"], "speedup_vs_pykalman": speed["speedup_vs_pykalman"],
             "filter_step_ms": {k: v for k, v in speed.items() if not k.startswith("speedup")},
             "subroutine_ms": dict(zip(timing.subroutine, timing.time_ms))}
    return Study(tables=tables, timing=timing, metrics=metrics, speed=speed)
