"""Table I-like timings of the pipeline's subroutines (ms, machine-dependent, run alone on the machine)."""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from poseintegrity.params.track import TrackParams
from poseintegrity.tracking.experiments.filter_runs import experiment_rng
from poseintegrity.tracking.filter.tracker import MarkerTracker
from poseintegrity.tracking.markers.brute_force import match_brute_force
from poseintegrity.tracking.markers.correspondence import match_markers_unchecked
from poseintegrity.tracking.markers.detection import detect_markers
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M, transform_points
from poseintegrity.tracking.markers.kabsch import kabsch_unchecked, pose_from_points_unchecked
from poseintegrity.tracking.markers.voting import match_voting
from poseintegrity.tracking.simulation.frames import draw_phantoms, intrinsics, render_frame
from poseintegrity.tracking.simulation.simulate import Simulation, T_world_cam



def _mean_time_ms(fn, repeats: int) -> float:
    fn()
    start = time.perf_counter()
    for _ in range(repeats):
        fn()
    return (time.perf_counter() - start) / repeats * 1000.0


def detect_match_kabsch(ir: np.ndarray, depth_mm: np.ndarray, K: np.ndarray, params: TrackParams, geometry: np.ndarray) -> np.ndarray:
    """The no-filter chain on one frame: detection, correspondence, Kabsch.  Returns T_world_body (4, 4),
    NaN if fewer than 3 markers were matched."""
    points = detect_markers(ir, depth_mm, K, params.detection)
    assignment = match_markers_unchecked(points, geometry, None, params.matching)
    matched = assignment >= 0
    if matched.sum() < 3:
        return np.full((4, 4), np.nan)
    return pose_from_points_unchecked(points[assignment[matched]], geometry[matched])


def timing_table(sim: Simulation, params: TrackParams) -> pd.DataFrame:
    """Mean time (ms) of the subroutines, like Table I, on one frame of the recording with a round phantom."""
    rng = experiment_rng(params, "timing")
    K = intrinsics(params.camera)
    T_cw = np.linalg.inv(T_world_cam(params))
    geometry = sim.markers_body
    markers_cam = transform_points(T_cw, transform_points(sim.T_true[0], geometry))
    phantoms = draw_phantoms(1, params.camera, params.frames, 1.0, rng)
    ir, depth_mm = render_frame(markers_cam, phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng)
    points = detect_markers(ir, depth_mm, K, params.detection)
    tol, repeats = params.matching.tolerance_m, params.evaluation.timing_repeats
    tracker = MarkerTracker(geometry, params.filter, params.matching)
    tracker.frame(0.0, points)
    filt = tracker.filter
    z = filt.markers().ravel()
    observed = np.ones(len(geometry), dtype=bool)
    rows = {
        "Frame synthesis (ours)": lambda: render_frame(markers_cam, phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng),
        "Contour detection": lambda: detect_markers(ir, depth_mm, K, params.detection),
        "Euclidean matching": lambda: match_voting(points, geometry, tolerance_m=tol),
        "Brute force matching": lambda: match_brute_force(points, geometry, tolerance_m=tol, min_markers=params.matching.min_markers),
        "Kabsch algorithm": lambda: kabsch_unchecked(z.reshape(-1, 3), geometry),
        "Detection + correspondence + Kabsch": lambda: detect_match_kabsch(ir, depth_mm, K, params, geometry),
        "UKF state update (one dt step)": lambda: filt.predict(params.filter.dt),
        "UKF measurement update (markers + gyro)": lambda: filt.update(np.r_[z, np.zeros(3)], observed, True),
    }
    return pd.DataFrame([{"subroutine": name, "time_ms": _mean_time_ms(fn, repeats)} for name, fn in rows.items()])
