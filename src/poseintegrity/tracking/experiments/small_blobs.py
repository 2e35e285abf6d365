"""Small blobs: does the detector keep markers that a real AHAT camera shows as 8-20 px blobs, and does it still
reject elongated reflections?  A rendered sweep over distance and tool orientation (section II-B's detector,
published shape measure against ours; :mod:`poseintegrity.tracking.markers.detection`)."""

from __future__ import annotations

from typing import get_args

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from poseintegrity.tracking.markers.detection import detect_markers
from poseintegrity.tracking.simulation.frames import Phantom, intrinsics, render_frame
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M, pairwise_distances
from poseintegrity.params.track import DetectionParams, TrackParams

MEASURES = get_args(DetectionParams.model_fields["shape_measure"].annotation)  # ("contour", "pixel")


def _unoccluded(markers_cam: np.ndarray, focal_px: float) -> np.ndarray:
    """(n,) bool: markers whose image is at least two blob diameters from every other marker's image."""
    uv = focal_px * markers_cam[:, :2] / markers_cam[:, 2:]
    radius = focal_px * (MARKER_DIAMETER_M / 2) / markers_cam[:, 2]
    D = pairwise_distances(np.column_stack([uv, np.zeros(len(uv))]))
    np.fill_diagonal(D, np.inf)
    return (D > 2 * (radius[:, None] + radius[None, :])).all(axis=1)


def small_blob_sweep(params: TrackParams, rng: np.random.Generator) -> pd.DataFrame:
    """One row per (marker or phantom, shape measure): kind, distance_m, tilt_deg, blob_area_px (the sphere's
    projected disc area), measure, detected.

    Markers: the tool at each of evaluation.sweep_distances_m, evaluation.sweep_poses random orientations
    (tilt_deg: angle of the tool rotation) and a random offset in the view, focal evaluation.sweep_focal_px,
    the sensor noise of ``frames``; only unoccluded markers count; detected = a point within
    correct_tolerance_m of the marker.  Phantoms: evaluation.sweep_phantoms elongated reflections (radius and
    axis ratio from ``frames``) alone in a frame; detected = any point.
    """
    ev = params.evaluation
    camera = params.camera.model_copy(update={"focal_px": ev.sweep_focal_px})
    K = intrinsics(camera)
    geometry = np.array(params.markers_body)
    detectors = {m: params.detection.model_copy(update={"shape_measure": m}) for m in MEASURES}
    rows = []
    for distance in ev.sweep_distances_m:
        for _ in range(ev.sweep_poses):
            rotation = Rotation.random(random_state=rng)
            offset = np.r_[rng.uniform(-0.3, 0.3, 2) * distance, distance]
            markers = rotation.apply(geometry - geometry.mean(axis=0)) + offset
            ir, depth = render_frame(markers, [], camera, params.frames, MARKER_DIAMETER_M / 2, rng)
            visible = _unoccluded(markers, camera.focal_px)
            area = np.pi * (camera.focal_px * MARKER_DIAMETER_M / 2 / markers[:, 2]) ** 2
            for measure, detection in detectors.items():
                points = detect_markers(ir, depth, K, detection)
                found = np.zeros(len(markers), dtype=bool)
                if len(points):
                    found = np.linalg.norm(points[:, None] - markers[None], axis=-1).min(axis=0) <= ev.correct_tolerance_m
                rows += [{"kind": "marker", "distance_m": distance, "tilt_deg": float(np.degrees(rotation.magnitude())),
                          "blob_area_px": float(area[i]), "measure": measure, "detected": bool(found[i])} for i in np.flatnonzero(visible)]
    for _ in range(ev.sweep_phantoms):
        phantom = Phantom(u=rng.uniform(40, camera.width - 40), v=rng.uniform(40, camera.height - 40),
                          radius_px=rng.uniform(*params.frames.phantom_radius_px), elongation=rng.uniform(*params.frames.phantom_elongation),
                          angle=rng.uniform(0, np.pi), depth_mm=rng.uniform(*params.frames.phantom_depth_mm))
        ir, depth = render_frame(np.zeros((0, 3)), [phantom], camera, params.frames, MARKER_DIAMETER_M / 2, rng)
        for measure, detection in detectors.items():
            rows.append({"kind": "phantom", "distance_m": np.nan, "tilt_deg": np.nan, "blob_area_px": np.pi * phantom.radius_px**2 * phantom.elongation,
                         "measure": measure, "detected": len(detect_markers(ir, depth, K, detection)) > 0})
    return pd.DataFrame(rows)


def sweep_summary(sweep: pd.DataFrame) -> dict[str, dict[str, float]]:
    """Keep rate of unoccluded markers and rejection rate of elongated phantoms per shape measure."""
    markers, phantoms = sweep[sweep.kind == "marker"], sweep[sweep.kind == "phantom"]
    return {
        "marker_keep_rate": markers.groupby("measure").detected.mean().to_dict(),
        "phantom_rejection_rate": (1 - phantoms.groupby("measure").detected.mean()).to_dict(),
        "marker_area_px": {"min": float(markers.blob_area_px.min()), "max": float(markers.blob_area_px.max())},
    }
