"""Robustness (ours): a 10 m jump of the tool, and a recording written to disk and replayed from it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from poseintegrity.params.track import TrackParams
from poseintegrity.tracking.experiments.filter_runs import experiment_rng
from poseintegrity.tracking.filter.recording_replay import track_recording
from poseintegrity.tracking.filter.tracker import MarkerTracker
from poseintegrity.tracking.io.recording import RecordingWriter, read_recording
from poseintegrity.tracking.markers.geometry import transform_points
from poseintegrity.tracking.simulation.frames import intrinsics, unit_plane_lut
from poseintegrity.tracking.simulation.simulate import Simulation, run_filter, simulate


def ten_metre_jump(sim: Simulation, params: TrackParams, jump_at_s: float = 2.0, jump_m: float = 10.0) -> dict:
    """The innovation gate on a persistent jump of every measured point by jump_m (m) along x at jump_at_s:
    the true markers of the accuracy recording (2 mm noise) are fed to the tracker, the jump persists.
    Returns how many frames after the jump were reported "ok" while more than 0.1 m off (must be 0), the flags
    seen, the frames until the restart, and the error after it."""
    rng = experiment_rng(params, "jump")
    tracker = MarkerTracker(sim.markers_body, params.filter, params.matching, use_gyro=False)
    flags, errors = [], []
    for f in range(len(sim.t)):
        t = sim.t[f]
        if t > jump_at_s + 2.0:
            break
        shift = np.array([jump_m, 0.0, 0.0]) if t >= jump_at_s else np.zeros(3)
        points = transform_points(sim.T_true[f], sim.markers_body) + rng.normal(0.0, 0.002, (len(sim.markers_body), 3))
        result = tracker.frame(t, points + shift)
        if t >= jump_at_s:
            flags.append(result.flag)
            errors.append(float(np.linalg.norm(result.T_filtered[:3, 3] - sim.T_true[f, :3, 3] - shift)))
    errors = np.array(errors)
    restart = flags.index("restart") if "restart" in flags else -1
    return {"frames_after_jump": len(flags), "ok_while_off": int(sum(fl == "ok" and e > 0.1 for fl, e in zip(flags, errors))),
            "flags": {fl: flags.count(fl) for fl in sorted(set(flags))}, "frames_to_restart": restart,
            "error_after_restart_mm": float(np.nanmax(errors[restart + 1 :]) * 1000) if 0 <= restart < len(errors) - 1 else float("nan")}


def recording_replay(params: TrackParams, folder: Path) -> tuple[pd.DataFrame, dict]:
    """Write evaluation.replay_s seconds of a simulated recording as a recording folder (16-bit PNG frames,
    gyro.csv, the unit-plane LUT) and replay it from disk with :func:`track_recording`; the in-memory run of the
    same recording (:func:`run_filter`, gyro fused) must give the same poses.  Returns (pose table, agreement)."""
    writer = RecordingWriter(folder, unit_plane_lut(intrinsics(params.camera), params.camera.width, params.camera.height), overwrite=True)
    [sim] = simulate(params, experiment_rng(params, "replay"), duration_s=params.evaluation.replay_s, sink=writer.add_frame)
    writer.close(sim.trajectory.t[sim.timeline.gyro_index], sim.timeline.gyro)
    table = track_recording(read_recording(folder), {"tool": sim.markers_body}, params, gyro_tool="tool")
    direct, _ = run_filter(sim, params, use_gyro=True)
    direct = direct[direct.kind == "frame"]
    diff = np.abs(table[["x_mm", "y_mm", "z_mm"]].to_numpy() - direct[["x_mm", "y_mm", "z_mm"]].to_numpy())
    same_nan = np.array_equal(np.isnan(diff), np.isnan(direct[["x_mm", "y_mm", "z_mm"]].to_numpy()))
    return table, {"frames": len(table), "max_position_diff_mm": float(np.nanmax(diff)) if np.isfinite(diff).any() else float("nan"),
                   "same_flags": bool((table.flag.to_numpy() == direct.flag.to_numpy()).all()) and same_nan}
