"""A recording folder (:mod:`~poseintegrity.tracking.io.recording`) replayed through the tracking: detection (II-B)
-> correspondence (II-D) -> Kabsch (Alg. 4) -> SR-UKF (Alg. 5) of every tool, frame by frame and with the gyro
samples in time order, giving a pose table.

Usage, e.g. on a HoloLens 2 recording with the probe of the paper::

    from poseintegrity.config import load_section
    from poseintegrity.tracking import read_recording, read_tools, track_recording

    params = load_section("params.yaml", "track")
    tools = {"probe": np.array(params.markers_body)}  # or read_tools("tools.json", params.matching.distinct_m)
    poses = track_recording(read_recording("my_recording"), tools, params, gyro_tool="probe")
    poses.to_csv("poses.csv", index=False)

Bad input: a bad recording is refused when it is read (:func:`~poseintegrity.tracking.io.recording.read_recording`),
before any frame is tracked; a frame file that cannot be decoded, or a frame of the wrong shape, dtype or units (depth
in metres) gives a row flagged ``bad_frame`` and a RuntimeWarning naming the file and the reason; a frame in which
nothing is detected (a hand over the tool, an all-zero or all-NaN depth frame) gives rows flagged ``no_points`` /
``no_markers`` and the tracking goes on; no NaN point is ever produced.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from poseintegrity.config import published
from poseintegrity.params.track import TrackParams
from poseintegrity.tracking.filter.multi_tool import MultiToolTracker
from poseintegrity.tracking.io.recording import Recording, frame_problem
from poseintegrity.tracking.markers.detection import detect_markers_unchecked


def track_recording(recording: Recording, tools: dict[str, np.ndarray], params: TrackParams | None = None,
                    gyro_tool: str | None = None, progress: Callable[[int], object] | None = None) -> pd.DataFrame:
    """Pose table of a recording: one row per frame and tool, in time order.

    Columns: t_s, frame, tool, flag, n_points, n_matched, x_mm / y_mm / z_mm and qx / qy / qz / qw (filtered
    T_world_body, NaN while the filter is not running).  Gyro samples are fused by gyro_tool's filter between
    the frames (events in time order; a gyro sample at the time of a frame comes after it).
    A frame in which nothing is detected is a row flagged no_points (the filter keeps predicting and picks the
    tool up again on the next good frame).  Bad tools or a gyro_tool naming no tool raise ToolError.
    params : ``track`` (detection, matching, filter); None takes the published defaults (params.yaml).
    progress : called with 1 after each frame (e.g. a tqdm bar's ``update``).
    """
    params = published("track") if params is None else params
    tracker = MultiToolTracker(tools, params.filter, params.matching, gyro_tool)  # checks tools and gyro_tool
    if recording.gyro is None and gyro_tool is not None:
        tracker = MultiToolTracker(tools, params.filter, params.matching, None)
    events = [(t, 0, k) for k, t in enumerate(recording.frames.t_s)]
    if recording.gyro is not None:
        events += [(t, 1, k) for k, t in enumerate(recording.gyro.t_s)]
    rows, warned = [], set()
    gyro = recording.gyro[["wx", "wy", "wz"]].to_numpy(float) if recording.gyro is not None else None
    for t, is_gyro, k in sorted(events):
        if is_gyro:
            tracker.gyro_unchecked(float(t), gyro[k])  # read_recording checked the times and rates
            continue
        reason, ir, depth = frame_problem(recording, k)
        if reason:
            if reason not in warned:
                warnings.warn(f"{recording.folder / recording.frames.ir.iloc[k]}: {reason} (frame flagged bad_frame)", RuntimeWarning, stacklevel=2)
                warned.add(reason)
            results = {name: None for name in tools}
            points = np.zeros((0, 3))
        else:
            points = detect_markers_unchecked(ir, depth, recording.lut, params.detection)  # frame_problem validated it
            results = tracker.frame_unchecked(float(t), points)
        for name, result in results.items():
            T = result.T_filtered if result is not None else tracker.trackers[name].pose()
            ok = np.isfinite(T).all()
            q = Rotation.from_matrix(T[:3, :3]).as_quat() if ok else np.full(4, np.nan)
            rows.append({
                "t_s": t, "frame": k, "tool": name, "flag": result.flag if result is not None else "bad_frame",
                "n_points": len(points), "n_matched": int((result.assignment >= 0).sum()) if result is not None else 0,
                "x_mm": T[0, 3] * 1000.0, "y_mm": T[1, 3] * 1000.0, "z_mm": T[2, 3] * 1000.0,
                "qx": q[0], "qy": q[1], "qz": q[2], "qw": q[3],
            })
        if progress is not None:
            progress(1)
    return pd.DataFrame(rows)
