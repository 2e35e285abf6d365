"""Tracking success rates (III-C): motions (a) paper-like and (b) stress, with 4 or 3 markers, and two tools among
phantom reflections (ours)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from poseintegrity.tracking.markers.detection import detect_markers_unchecked
from poseintegrity.tracking.simulation.frames import draw_phantoms, intrinsics, render_frame
from poseintegrity.poses import pose_matrix
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M, transform_points
from poseintegrity.tracking.simulation.motion import sample_sensors, simulate_trajectory
from poseintegrity.params.track import TrackParams
from poseintegrity.tracking.simulation.simulate import Simulation, T_world_cam, background_seen, run_no_filter, simulate, simulate_hand
from poseintegrity.tracking.filter.multi_tool import MultiToolTracker
from poseintegrity.tracking.experiments.filter_runs import experiment_rng


def success_frames_duration(params: TrackParams) -> float:
    """Seconds of recording that give at least evaluation.success_frames marker frames."""
    return params.evaluation.success_frames * params.motion.frame_interval_s * 1.2 + 1.0


@dataclass(frozen=True)
class SuccessRun:
    """One success-rate recording: motion "a" (paper-like) or "b" (stress); label markers4 / markers3 /
    markers3_drop<k>; dropped : index of the removed marker, -1 for none.  On (b) the frames are detected
    with and without splitting touching blobs (the same frames)."""

    motion: str
    label: str
    dropped: int


def success_runs(params: TrackParams) -> list[SuccessRun]:
    """(a) with 4 markers and with each marker removed (params.drop_marker's run is ``markers3``); (b) with 4
    markers and without params.drop_marker."""
    n = len(params.markers_body)
    three = {"markers3" if i == params.drop_marker else f"markers3_drop{i + 1}": i for i in range(n)}
    runs = [SuccessRun("a", "markers4", -1)] + [SuccessRun("a", label, i) for label, i in three.items()]
    return runs + [SuccessRun("b", "markers4", -1), SuccessRun("b", "markers3", params.drop_marker)]


def success_recording(params: TrackParams, run: SuccessRun, keep: bool = False) -> dict[str, tuple[pd.DataFrame, Simulation | None]]:
    """The recording of one :class:`SuccessRun` and its no-filter tables, by run name (``a_markers4``,
    ``b_markers3_no_split``, ...): {name: (no-filter table, recording if keep else None)} (a recording of motion
    (a) holds ~50 MB of ground truth: only the one filtered later is kept).  The motion and its timeline are
    drawn for success_frames_duration seconds, and only the evaluation.success_frames frames that are counted
    are rendered (and filtered later, for the kept one)."""
    geometry = np.array(params.markers_body)
    body = geometry if run.dropped < 0 else np.delete(geometry, run.dropped, axis=0)
    duration, n_frames = success_frames_duration(params), params.evaluation.success_frames
    if run.motion == "a":
        sims = {f"a_{run.label}": simulate_hand(params, experiment_rng(params, f"hand_{run.label}"), body, duration, n_frames)}
    else:
        no_split = params.detection.model_copy(update={"split_touching": False})
        split, unsplit = simulate(params, experiment_rng(params, f"stress_{run.label}"), body, params.evaluation.success_omega_std,
                                  duration, [params.detection, no_split], n_frames=n_frames)
        sims = {f"b_{run.label}": split, f"b_{run.label}_no_split": unsplit}
    return {name: (run_no_filter(sim, params), sim if keep else None) for name, sim in sims.items()}


def success_rates(params: TrackParams, no_filter: Mapping[str, pd.DataFrame]) -> tuple[pd.DataFrame, dict[str, pd.DataFrame]]:
    """Share of evaluation.success_frames frames with a correct pose (section III) on motion (a), paper-like, and
    motion (b), the stress test, with 4 and with 3 markers (params.drop_marker removed; the paper does not say
    which one it removed, so on (a) every other choice is run too, ``markers3_drop<k>``); on (b) also without
    splitting touching blobs (the same frames).  no_filter : the tables of :func:`success_recording` by run name.
    Returns (table motion/markers/dropped/split/rate/possible, per-frame tables ``success_<run>``).  ``possible``:
    share of frames with >= 3 markers not hidden by an occlusion (a marker hidden behind another still counts)."""
    n = params.evaluation.success_frames
    rows, tables = [], {}
    for run in success_runs(params):
        for split in (True,) if run.motion == "a" else (True, False):
            name = f"{run.motion}_{run.label}" + ("" if split else "_no_split")
            df = no_filter[name].iloc[:n]
            tables[f"success_{name}"] = df
            rows.append({"run": name, "motion": run.motion, "markers": run.label, "dropped": run.dropped + 1, "split_touching": split,
                         "rate": float(df.correct.mean()), "possible": float((df.n_visible >= 3).mean()), "frames": len(df)})
    return pd.DataFrame(rows), tables


def two_tools_success(params: TrackParams, phantom_max: int, name: str) -> pd.DataFrame:
    """Two tools in view (params.markers_body and evaluation.second_tool), each on its own hand-like trajectory
    (the second 0.12 m to the side), one filter per tool (:class:`MultiToolTracker`), no gyro; phantoms
    binomial(phantom_max, p_phantom) per frame.  One row per frame and tool: correct (>= 3 markers matched and
    every matched point within correct_tolerance_m of its own marker)."""
    rng = experiment_rng(params, name)
    tools = {"tool1": np.array(params.markers_body), "tool2": np.array(params.evaluation.second_tool)}
    duration = params.evaluation.multi_tool_frames * params.motion.frame_interval_s * 1.2 + 1.0
    motion = params.motion.model_copy(update={"duration_s": duration, "occlusions": [], "max_phantoms": phantom_max})
    homes = {"tool1": np.array(motion.home_m) + [-0.06, 0.0, 0.0], "tool2": np.array(motion.home_m) + [0.06, 0.0, 0.0]}
    trajectories = {k: simulate_trajectory(motion.model_copy(update={"home_m": tuple(homes[k])}), rng) for k in tools}
    timeline = sample_sensors(trajectories["tool1"], 8, motion, rng)
    idx = timeline.frame_index[: params.evaluation.multi_tool_frames]
    K, T_wc = intrinsics(params.camera), T_world_cam(params)
    tracker = MultiToolTracker(tools, params.filter, params.matching)
    background_noise = background_seen(params, [params.detection])
    rows = []
    for f, i in enumerate(idx):
        T = {k: pose_matrix(tr.rotation(np.array([i]))[0], tr.position[i]) for k, tr in trajectories.items()}
        true = {k: transform_points(T[k], tools[k]) for k in tools}
        markers = np.vstack([true["tool1"], true["tool2"]])[~timeline.occluded[f]]
        phantoms = draw_phantoms(int(timeline.n_phantoms[f]), params.camera, params.frames, motion.phantom_round_fraction, rng)
        ir, depth = render_frame(transform_points(np.linalg.inv(T_wc), markers), phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng,
                                 background_noise)
        points = detect_markers_unchecked(ir, depth, K, params.detection, T_world_cam=T_wc)  # rendered here: a usable frame
        for tool, result in tracker.frame(trajectories["tool1"].t[i], points).items():
            matched = result.assignment >= 0
            err = np.linalg.norm(points[result.assignment[matched]] - true[tool][matched], axis=1)
            rows.append({"scene": name, "frame": f, "tool": tool, "flag": result.flag, "n_points": len(points), "n_matched": int(matched.sum()),
                         "correct": bool(matched.sum() >= 3 and np.all(err <= params.evaluation.correct_tolerance_m))})
    return pd.DataFrame(rows)
