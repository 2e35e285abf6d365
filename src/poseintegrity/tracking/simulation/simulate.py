"""Simulated recordings (section II-F) and the two ways of running them: no filter and the tracker.

A recording is a trajectory, its sensor timeline, and the rendered AHAT-like frames run through the detector;
frames are not kept (a ``sink`` may receive them, e.g. a :class:`~poseintegrity.tracking.io.recording.RecordingWriter`).
Every random draw comes from the generator passed in; the same generator state gives bit-identical tables.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd
from tqdm import tqdm  # text bar: tqdm.auto warns "IProgress not found" in every kernel (no ipywidgets here)

from poseintegrity.poses import NAN_POSE, pose_matrix
from poseintegrity.tracking.markers.correspondence import match_markers_unchecked
from poseintegrity.tracking.markers.detection import detect_markers_each, raw_threshold
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M, transform_points
from poseintegrity.tracking.markers.kabsch import pose_from_points_unchecked
from poseintegrity.tracking.simulation.errors import error_columns
from poseintegrity.tracking.simulation.frames import background_quantiles, draw_phantoms, intrinsics, render_frame
from poseintegrity.workers import in_worker_task
from poseintegrity.tracking.simulation.motion import (
    SensorTimeline,
    Trajectory,
    brief_occlusions,
    sample_sensors,
    simulate_hand_motion,
    simulate_trajectory,
)
from poseintegrity.params.track import DetectionParams, FilterParams, TrackParams
from poseintegrity.tracking.filter.srukf import SquareRootUKF
from poseintegrity.tracking.filter.tracker import MarkerTracker
from poseintegrity.tracking.filter.unscented import UnscentedMarkerFilter


@dataclass(frozen=True)
class Simulation:
    """One simulated recording: ground truth, sensor timeline, and the detected points of every frame.

    t : (F,) s frame times; T_true : (F, 4, 4) T_world_body; points : list of (n_f, 3) detections, metres;
    in_occlusion : (F,) bool, inside a deliberate extended occlusion; occlusions : (start_s, duration_s) of those.
    """

    trajectory: Trajectory
    timeline: SensorTimeline
    markers_body: np.ndarray
    t: np.ndarray
    T_true: np.ndarray
    points: list[np.ndarray]
    in_occlusion: np.ndarray
    occlusions: list[tuple[float, float]]


def T_world_cam(params: TrackParams) -> np.ndarray:
    """Camera extrinsics (4, 4): the camera looks along world +z from params.camera.origin_m."""
    return pose_matrix(np.eye(3), np.array(params.camera.origin_m))


def background_seen(params: TrackParams, detections: Sequence[DetectionParams]) -> bool:
    """Whether any of these detectors can tell the noisy IR background from a flat one: the detector reads IR only
    through its threshold (:func:`~poseintegrity.tracking.markers.detection.raw_threshold`), so when that lies above
    the largest background value (:func:`~poseintegrity.tracking.simulation.frames.background_quantiles`) frames
    rendered with ``background_noise=False`` give the same masks, points and later random draws, for less work."""
    brightest_unlit = background_quantiles(params.frames.ir_background, params.frames.ir_noise_std).max()
    return any(brightest_unlit > raw_threshold(d, np.uint16) for d in detections)


def record(
    params: TrackParams,
    trajectory: Trajectory,
    timeline: SensorTimeline,
    markers_body: np.ndarray,
    rng: np.random.Generator,
    detections: Sequence[DetectionParams],
    sink: Callable[[float, np.ndarray, np.ndarray], None] | None = None,
    label: str = "frames",
) -> list[Simulation]:
    """Render every marker frame of a timeline (AHAT-like, with phantoms) and run each detector on it.

    detections : the detectors' constants; one :class:`Simulation` per detector is returned, all of the same
    rendered frames (detection draws no random number).  sink(t, ir, depth_mm) receives each rendered frame.
    The points of a frame come from detection on the rendered images, so their error is the detector's.
    Without a sink the frames are rendered without background noise unless a detector could see it
    (:func:`background_seen`).
    """
    idx = timeline.frame_index
    T_true = pose_matrix(trajectory.rotation(idx), trajectory.position[idx])
    T_wc = T_world_cam(params)
    T_cw = np.linalg.inv(T_wc)
    K = intrinsics(params.camera)
    t = trajectory.t[idx]
    points: list[list[np.ndarray]] = [[] for _ in detections]
    background_noise = sink is not None or background_seen(params, detections)
    for f in tqdm(range(len(idx)), desc=label, leave=False, mininterval=5, disable=in_worker_task()):
        markers_cam = transform_points(T_cw, transform_points(T_true[f], markers_body))[~timeline.occluded[f]]
        phantoms = draw_phantoms(int(timeline.n_phantoms[f]), params.camera, params.frames, params.motion.phantom_round_fraction, rng)
        ir, depth_mm = render_frame(markers_cam, phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng, background_noise)
        if sink is not None:
            sink(float(t[f]), ir, depth_mm)
        for found, detected in zip(points, detect_markers_each(ir, depth_mm, K, list(detections), T_world_cam=T_wc)):  # rendered here: usable
            found.append(detected)
    occlusions = [tuple(o) for o in params.motion.occlusions]
    return [Simulation(trajectory, timeline, markers_body, t, T_true, found, inside_occlusions(t, occlusions), occlusions)
            for found in points]


def inside_occlusions(t: np.ndarray, occlusions: Sequence[tuple[float, float]]) -> np.ndarray:
    """(k,) bool: which times t (k,) s fall inside one of the occlusion windows [start_s, start_s + duration_s)."""
    inside = np.zeros(len(t), dtype=bool)
    for start, duration in occlusions:
        inside |= (t >= start) & (t < start + duration)
    return inside


def simulate(params: TrackParams, rng: np.random.Generator, markers_body: np.ndarray | None = None, omega_std: float | None = None,
             duration_s: float | None = None, detections: Sequence[DetectionParams] | None = None, sink=None,
             n_frames: int | None = None) -> list[Simulation]:
    """The accuracy recording (params.motion), or motion (b), the stress test, with omega_std and no deliberate
    occlusion when omega_std is given.  markers_body : (m, 3) geometry (default params.markers_body).
    One :class:`Simulation` per detector of ``detections`` (default: params.detection alone), see :func:`record`.
    n_frames : render only the first n_frames marker frames of the duration_s timeline (all if None); the
    motion and the timeline are drawn for the whole duration, so those frames are the same either way."""
    markers_body = np.array(params.markers_body) if markers_body is None else markers_body
    update = {} if duration_s is None else {"duration_s": duration_s}
    if omega_std is not None:
        update["occlusions"] = []
    params = params.model_copy(update={"motion": params.motion.model_copy(update=update)})
    trajectory = simulate_trajectory(params.motion, rng, omega_std=omega_std)
    timeline = sample_sensors(trajectory, len(markers_body), params.motion, rng)
    if n_frames is not None:
        timeline = timeline.first_frames(n_frames)
    return record(params, trajectory, timeline, markers_body, rng, detections or [params.detection], sink,
                  label="stress" if omega_std else "recording")


def simulate_hand(params: TrackParams, rng: np.random.Generator, markers_body: np.ndarray, duration_s: float, n_frames: int | None = None) -> Simulation:
    """Motion (a), paper-like (:class:`~poseintegrity.params.track.HandMotionParams`): full turns about every
    axis, large translations, brief per-marker occlusions in place of the i.i.d. P_o and the deliberate occlusion.
    n_frames : as in :func:`simulate`."""
    motion = params.motion.model_copy(update={"duration_s": duration_s, "p_occlusion": 0.0, "occlusions": []})
    params = params.model_copy(update={"motion": motion})
    trajectory = simulate_hand_motion(motion, params.hand, rng)
    timeline = sample_sensors(trajectory, len(markers_body), motion, rng)
    hidden = brief_occlusions(trajectory.t[timeline.frame_index], len(markers_body), params.hand, rng)
    timeline = replace(timeline, occluded=timeline.occluded | hidden)
    if n_frames is not None:
        timeline = timeline.first_frames(n_frames)
    return record(params, trajectory, timeline, markers_body, rng, [params.detection], label="hand motion")[0]


def run_no_filter(sim: Simulation, params: TrackParams) -> pd.DataFrame:
    """Kabsch per frame on the matched detections (no filter, no prediction): one row per frame.

    correct: at least min_markers markers matched and every matched point within correct_tolerance_m of
    its true marker (correspondence right and pose usable).  Error columns: :func:`~poseintegrity.tracking.simulation.errors.error_columns`.
    """
    m, n_frames = params.matching, len(sim.points)
    true_markers = transform_points(sim.T_true, sim.markers_body)  # (F, m, 3)
    poses, n_matched, correct = np.empty((n_frames, 4, 4)), np.zeros(n_frames, dtype=np.int64), np.zeros(n_frames, dtype=bool)
    for f, points in enumerate(sim.points):
        assignment = match_markers_unchecked(points, sim.markers_body, None, m)
        matched = assignment >= 0
        n_matched[f] = matched.sum()
        poses[f] = pose_from_points_unchecked(points[assignment[matched]], sim.markers_body[matched]) if n_matched[f] >= 3 else NAN_POSE
        err = np.linalg.norm(points[assignment[matched]] - true_markers[f][matched], axis=1) if n_matched[f] else np.zeros(0)
        correct[f] = n_matched[f] >= m.min_markers and bool(np.all(err <= params.evaluation.correct_tolerance_m))
    df = pd.DataFrame({"frame": np.arange(n_frames), "t": sim.t[:n_frames], "n_visible": (~sim.timeline.occluded[:n_frames]).sum(axis=1),
                       "n_detected": [len(points) for points in sim.points], "n_matched": n_matched, "correct": correct})
    for name, column in error_columns(poses, sim.T_true).items():
        df[name] = column
    df[["x_mm", "y_mm", "z_mm"]] = poses[:, :3, 3] * 1000.0
    df["in_occlusion"] = sim.in_occlusion
    return df


def run_filter(
    sim: Simulation,
    params: TrackParams,
    use_gyro: bool,
    filter_params: FilterParams | None = None,
    filter_cls: type[UnscentedMarkerFilter] = SquareRootUKF,
) -> tuple[pd.DataFrame, MarkerTracker]:
    """Run the tracker over the recording: one row per event (marker frame or gyro sample), in time order.

    Columns: t, kind ("frame"/"gyro"), frame (index or -1), flag, n_matched, the error columns, x_mm / y_mm /
    z_mm (filtered position of the body origin), in_occlusion.
    """
    tracker = MarkerTracker(sim.markers_body, filter_params or params.filter, params.matching, use_gyro, filter_cls)
    tl, traj = sim.timeline, sim.trajectory
    # events in time order (grid index), a frame before a gyro sample of the same instant
    grid = np.concatenate([tl.frame_index, tl.gyro_index]).astype(np.int64)
    is_gyro = np.repeat([False, True], [len(tl.frame_index), len(tl.gyro_index)])
    k = np.concatenate([np.arange(len(tl.frame_index)), np.arange(len(tl.gyro_index))])
    order = np.lexsort((k, is_gyro, grid))
    grid, is_gyro, k = grid[order], is_gyro[order], k[order]
    t = traj.t[grid]
    flags, n_matched, poses = [], np.full(len(grid), -1), np.empty((len(grid), 4, 4))
    for e in range(len(grid)):
        if is_gyro[e]:
            flags.append(tracker.gyro_unchecked(float(t[e]), tl.gyro[k[e]]))  # simulated: already good, unchecked
            poses[e] = tracker.pose()
        else:
            result = tracker.frame_unchecked(float(t[e]), sim.points[k[e]])
            flags.append(result.flag)
            n_matched[e] = int((result.assignment >= 0).sum())
            poses[e] = result.T_filtered
    df = pd.DataFrame({"t": t, "kind": np.where(is_gyro, "gyro", "frame").astype(object), "frame": np.where(is_gyro, -1, k),
                       "flag": flags, "n_matched": n_matched, "in_occlusion": inside_occlusions(t, sim.occlusions)})
    truth = pose_matrix(traj.rotation(grid), traj.position[grid])
    for name, column in error_columns(poses, truth).items():
        df[name] = column
    df[["x_mm", "y_mm", "z_mm"]] = poses[:, :3, 3] * 1000.0
    return df, tracker
