"""The registry of public entry points the battery runs: for each, a valid call and the kind of each argument.

An :class:`EntryPoint` builds its valid arguments (``valid``, cached), calls the function with one of them
replaced (``call``), and says which results are flagged (``flagged``: a status other than "ok", a flag, a
warning); ``accepts`` lists bad-value labels whose plain result is the documented, correct one (e.g. a NaN depth
pixel is an invalid pixel, not an error). Add a public function here when you add one.
"""

from __future__ import annotations

import json
import shutil
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml
from scipy.spatial.transform import Rotation

from bad_values import stored

ROOT = Path(__file__).resolve().parents[2]
TINY_PARAMS = ROOT / "tests" / "params_tiny.yaml"


@dataclass(frozen=True)
class EntryPoint:
    name: str
    call: Callable[[dict[str, Any]], Any]
    valid: Callable[[Path], dict[str, Any]]
    arguments: dict[str, str]  # argument -> kind of bad_values.KINDS
    flagged: Callable[[Any], bool] = lambda result: False
    accepts: dict[str, set[str]] = field(default_factory=dict)  # argument -> labels whose result is correct
    names: dict[str, str] = field(default_factory=dict)  # argument -> the word its error message must contain
    cases: dict[str, dict[str, Callable]] = field(default_factory=dict)  # argument -> bad values of its own beyond its kind's


# ----------------------------------------------------------------------------------------------- valid inputs
@cache
def params():
    from poseintegrity.config import load_params

    return load_params(TINY_PARAMS)


@cache
def localization_scene() -> dict[str, Any]:
    """A rendered view of the synthetic plane (board + textured target) with exact pose and matches."""
    import loc_synthetic as synthetic

    rng = np.random.default_rng(0)
    plane, _ = synthetic.canvas(rng)
    T = synthetic.arc_pose(10.0, 0.0)
    image = synthetic.render(plane, T)
    world = rng.uniform([85, -20, 0], [165, 65, 0], (60, 3))
    uv, _ = __import__("cv2").projectPoints(world, __import__("cv2").Rodrigues(T[:3, :3])[0], T[:3, 3], synthetic.K, None)
    return dict(image=image, T=T, object_points=world, image_points=uv.reshape(-1, 2), K=synthetic.K,
                camera=synthetic.CAMERA, board=synthetic.BOARD, checks=synthetic.CHECKS)


@cache
def inlier_series() -> tuple[np.ndarray, np.ndarray]:
    from poseintegrity.artifact_models.base_functions import emg

    theta = np.repeat(np.arange(0.0, 40.0, 2.5), 3)
    return theta, np.round(emg(theta, 3000.0, 8.0, -3.0)) + np.tile([0.0, 3.0, 2.0], len(theta) // 3)


HL2_SIZE = 512  # px: the HoloLens 2 formats' depth camera (AHaT), 512 x 512 by their layout


@cache
def tracking_frame(size: int = 128) -> dict[str, Any]:
    """One rendered frame of the marker body at 0.45 m: IR, depth, K and unit-plane table of the centre ``size`` x
    ``size`` px of the tiny parameters' camera (the body is seen at u 59..93, v 50..75 px of 128). The recordings the
    battery writes for its ~130 cases took 1 GB per run at the full 512 x 512 px, most of it the unit-plane table; no
    check depends on the size, except the HoloLens 2 formats' (HL2_SIZE)."""
    from poseintegrity.tracking.simulation.frames import intrinsics, render_frame, unit_plane_lut
    from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M

    track = params().track
    camera = track.camera.model_copy(update={"width": size, "height": size})
    geometry = np.array(track.markers_body)
    markers = geometry @ Rotation.from_rotvec([0.3, 0.2, 0.1]).as_matrix().T + [0.02, -0.01, 0.45]
    ir, depth = render_frame(markers, [], camera, track.frames, MARKER_DIAMETER_M / 2, np.random.default_rng(0))
    K = intrinsics(camera)
    return dict(ir=ir, depth=depth, lut=unit_plane_lut(K, camera.width, camera.height), K=K, markers=markers,
                geometry=geometry)


def _tracker():
    from poseintegrity.tracking.filter.tracker import MarkerTracker

    track = params().track
    tracker = MarkerTracker(np.array(track.markers_body), track.filter, track.matching)
    tracker.frame(0.0, tracking_frame()["markers"])
    return tracker


def _filter(cls_name: str):
    from poseintegrity.tracking.filter.srukf import SquareRootUKF
    from poseintegrity.tracking.filter.ukf import UnscentedKalmanFilter

    cls = SquareRootUKF if cls_name == "srukf" else UnscentedKalmanFilter
    track = params().track
    f = cls(np.array(track.markers_body), track.filter)
    f.initialize(tracking_frame()["markers"])
    return f


def _write(folder: Path, name: str, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text(text)
    return folder / name


def _recording_dir(tmp: Path) -> Path:
    from poseintegrity.tracking.io.recording import RecordingWriter

    frame = tracking_frame()
    folder = tmp / "recording"
    writer = RecordingWriter(folder, frame["lut"])
    for k in range(3):
        writer.add_frame(0.046 * k, frame["ir"], frame["depth"])
    writer.close(np.array([0.01, 0.02]), np.zeros((2, 3)))
    return folder


def _status_not_ok(result: Any) -> bool:
    status = getattr(result, "status", None)
    return status is not None and status != "ok"


NORMAL = ("ok", "initialized")  # statuses and tracker flags of a result that did not fail


def _any_flag(result: Any) -> bool:
    """A result that says it failed: a status or flag other than ok, or a flag column with such a row."""
    if isinstance(result, pd.DataFrame):
        for column in ("status", "flag"):
            if column in result and (~result[column].isin(NORMAL)).any():
                return True
        return False
    if isinstance(result, dict):
        return any(_any_flag(v) for v in result.values())
    for attribute in ("status", "flag"):
        value = getattr(result, attribute, None)
        if value is not None and not isinstance(value, np.ndarray) and value not in NORMAL:
            return True
        if isinstance(value, np.ndarray) and (~np.isin(value, NORMAL)).any():
            return True
    return False


# ------------------------------------------------------------------------------------------------- registry
# A tracker frame with fewer points is a partial update; NaN rows and points 1e300 m away are dropped detections.
GRAY8_CONVERSIONS = {"image": {"uint16", "three_channel", "four_channel"}}  # converted once, documented (as_gray8)
FEWER = {"empty", "one_element", "one_fewer"}  # fewer items: a smaller answer
UNKNOWN_POSITION = {"theta_p": {"nan"}, "theta_a": {"nan"}}  # NaN in, NaN (the unknown) out: documented
# a series' samples with a non-finite theta or count are dropped (documented); fewer thresholds: fewer answers
SERIES_ACCEPTS = {"theta": {"nan", "inf"}, "n_inliers": {"nan", "inf"}, "thresholds": FEWER | {"huge"}}
TRACKER_ACCEPTS = {"points": {"one_element", "one_fewer", "nan", "inf", "huge"}}


def _entries() -> list[EntryPoint]:
    from poseintegrity import boards, config, lens, poses, stage_timing, table_checks
    from poseintegrity.artifact_models.models import fit_model
    from poseintegrity.localization import (dataset, envelope, features, ground_truth, matching, pnp, pose_covariance,
                                            target_model)
    from poseintegrity.prediction import error_predictors, metrics, predictors
    from poseintegrity.recorded import __main__ as recorded_cli, export, geometry, materialize, reader, rosbag
    from poseintegrity.tracking import replay
    from poseintegrity.tracking.io import hl2_recordings, recording
    from poseintegrity.tracking.filter import multi_tool, recording_replay
    from poseintegrity.tracking.io import tool_files
    from poseintegrity.tracking.markers import correspondence, detection
    from poseintegrity.tracking.markers.kabsch import kabsch as kabsch_fit

    P = params
    loc = localization_scene
    entries = [
        # ---- params
        EntryPoint("config.load_params", lambda a: config.load_params(a["path"]),
                   lambda tmp: {"path": TINY_PARAMS}, {"path": "file"}),
        EntryPoint("config.load_params[generate.calibration.max_tilt_deg]",
                   lambda a: config.load_params(_overlay(a["folder"], {"generate": {"calibration": {"max_tilt_deg": a["value"]}}})),
                   lambda tmp: {"value": 40.0, "folder": tmp}, {"value": "scalar"},
                   names={"value": "generate.calibration.max_tilt_deg"},
                   # every view (nearly) facing the camera: Zhang's method cannot separate the focal length from distance
                   cases={"value": {"fronto_parallel": lambda v, _: 0.0, "nearly_fronto_parallel": lambda v, _: 1.0}}),
        # ---- lens
        EntryPoint("lens.read_camera_yaml", lambda a: lens.read_camera_yaml(a["path"]),
                   lambda tmp: {"path": _camera_yaml(tmp)}, {"path": "file"}),
        EntryPoint("lens.Camera", lambda a: lens.Camera(a["K"], a["dist"], 640, 400),
                   lambda tmp: {"K": loc()["K"], "dist": np.zeros(5)}, {"K": "matrix", "dist": "array"},
                   names={"dist": "dist"}),
        # ---- localization
        EntryPoint("localization.detect_features",
                   lambda a: features.detect_features(a["image"], P().extract.clahe, P().extract.sift),
                   lambda tmp: {"image": loc()["image"]}, {"image": "image"}, accepts=GRAY8_CONVERSIONS),
        EntryPoint("localization.decode_gray", lambda a: features.read_gray(a["path"]),
                   lambda tmp: {"path": _png(tmp)}, {"path": "file"}),
        EntryPoint("localization.match_ratio_test",
                   lambda a: matching.match_ratio_test(a["query"], a["train"], 0.8),
                   lambda tmp: {"query": _descriptors(0), "train": _descriptors(1)},
                   {"query": "points", "train": "points"},
                   accepts={"query": FEWER, "train": FEWER}),  # fewer descriptors: fewer (or no) matches
        EntryPoint("localization.solve_pnp_ransac",
                   lambda a: pnp.solve_pnp_ransac(a["object_points"], a["image_points"], a["K"], "usac_magsac", 2.0,
                                                  0.999, 1000, 0, True),
                   lambda tmp: {k: loc()[k] for k in ("object_points", "image_points", "K")},
                   {"object_points": "points", "image_points": "points", "K": "matrix"}, flagged=_status_not_ok),
        EntryPoint("localization.board_pose", lambda a: ground_truth.board_pose(a["image"], loc()["board"], a["camera"],
                                                                              loc()["checks"]),
                   lambda tmp: {"image": loc()["image"], "camera": loc()["camera"]}, {"image": "image"},
                   flagged=_status_not_ok, accepts=GRAY8_CONVERSIONS),
        EntryPoint("localization.triangulate",
                   lambda a: target_model.triangulate(a["K"], a["T_cam1_cam0"], a["x0"], a["x1"]),
                   lambda tmp: _two_views(), {"K": "matrix", "T_cam1_cam0": "matrix", "x0": "points", "x1": "points"}),
        EntryPoint("localization.actual_envelope",
                   lambda a: envelope.actual_envelope(a["theta"], a["criteria"], a["bounds"]),
                   lambda tmp: {"theta": np.arange(0.0, 40, 2.5), "criteria": np.c_[np.linspace(0.1, 3, 16),
                                np.linspace(0.1, 4, 16)], "bounds": np.array([2.0, 3.0])},
                   {"theta": "array", "criteria": "points", "bounds": "array"},
                   # NaN: an unmeasured stop, skipped and named; inf and 1e300: an error that fails the stop (documented)
                   flagged=lambda result: bool(result.unmeasured) or bool(np.isnan(result.theta_a)),
                   accepts={"criteria": {"inf", "huge"}},
                   cases={"criteria": {"unmeasured_stop": lambda v, _: np.where(np.arange(len(v))[:, None] == 3, np.nan, v)}}),
        EntryPoint("localization.pose_covariance",
                   lambda a: pose_covariance.pose_covariance(a["points_model"], a["image_points"], a["T_cam_model"],
                                                             a["K"], a["point_covariances"], inlier_threshold_px=0.6),
                   lambda tmp: {"points_model": loc()["object_points"], "image_points": loc()["image_points"],
                                "T_cam_model": loc()["T"], "K": loc()["K"],
                                "point_covariances": np.tile(np.diag([0.01, 0.01, 1.0]), (60, 1, 1))},
                   {"points_model": "points", "image_points": "points", "T_cam_model": "matrix", "K": "matrix",
                    "point_covariances": "array"},
                   flagged=lambda result: result.status != "ok",  # too few points: NaN and a status, no error
                   accepts={"point_covariances": {"None"}}),  # None: exact model points (the residual term alone)
        EntryPoint("localization.triangulation_covariances",
                   lambda a: pose_covariance.triangulation_covariances(a["points_cam0"], a["T_cam1_cam0"], a["K"], 0.3),
                   lambda tmp: {"points_cam0": loc()["object_points"] + [0.0, 0.0, 300.0],
                                "T_cam1_cam0": _two_views()["T_cam1_cam0"], "K": loc()["K"]},
                   {"points_cam0": "points", "T_cam1_cam0": "matrix", "K": "matrix"},
                   accepts={"points_cam0": {"empty"} | FEWER}),  # fewer points: fewer covariances
        EntryPoint("boards.board_from_dict", lambda a: boards.board_from_dict(a["board"]),
                   lambda tmp: {"board": dict(__import__("loc_synthetic").BOARD)}, {"board": "mapping"}),
        EntryPoint("localization.load_index", lambda a: dataset.load_index(a["index"].parents[1]),
                   lambda tmp: {"index": _dataset_dir(tmp)}, {"index": "file"}, names={"index": "index.parquet"}),
        EntryPoint("localization.load_dataset",
                   lambda a: dataset.load_dataset(a["meta"].parents[2], a["meta"].parent.relative_to(a["meta"].parents[2])),
                   lambda tmp: {"meta": _dataset_dir(tmp).parent / "ds_arc" / "meta.json"}, {"meta": "file"},
                   names={"meta": "meta.json"}),
        EntryPoint("localization.load_dataset[frames.parquet]",
                   lambda a: dataset.load_dataset(a["frames"].parents[2], a["frames"].parent.relative_to(a["frames"].parents[2])),
                   lambda tmp: {"frames": _dataset_dir(tmp).parent / "ds_arc" / "frames.parquet"}, {"frames": "parquet"},
                   names={"frames": "frames.parquet"}, cases={"frames": {"text_in_x_mm": stored(_text_in_x_mm)}}),
        EntryPoint("poses.pose_errors", lambda a: poses.pose_errors(a["T_est"], a["T_true"]),
                   lambda tmp: {"T_est": loc()["T"], "T_true": loc()["T"]}, {"T_est": "matrix", "T_true": "matrix"},
                   accepts={"T_est": {"nan", "inf"}, "T_true": {"nan", "inf"}}),  # an unknown pose: NaN errors
        # ---- artifact models
        EntryPoint("artifact_models.fit_model",
                   lambda a: fit_model("emg", a["theta"], a["n_inliers"], theta_end=a["theta_end"], params=P().fit,
                                       rng=np.random.default_rng(0)),
                   lambda tmp: {"theta": inlier_series()[0], "n_inliers": inlier_series()[1], "theta_end": 60.0},
                   {"theta": "array", "n_inliers": "array", "theta_end": "scalar"}, flagged=_status_not_ok,
                   # samples with a non-finite theta or count are dropped, any shape is flattened (documented)
                   accepts={"n_inliers": {"nan", "inf", "wrong_ndim"}, "theta": {"nan", "inf", "wrong_ndim"}}),
        # ---- prediction
        EntryPoint("prediction.boundaries",
                   lambda a: predictors.boundaries(lambda x: 300.0 - 5.0 * x, a["levels"], a["theta_start"],
                                                   a["theta_end"], a["n_grid"]),
                   lambda tmp: {"levels": np.array([15.0, 30.0]), "theta_start": 0.0, "theta_end": 60.0,
                                "n_grid": 50},
                   {"levels": "array", "theta_start": "scalar", "theta_end": "scalar", "n_grid": "scalar"},
                   flagged=lambda b: bool(np.isin(b.status, ["non_finite", "bad_threshold"]).any()),
                   # fewer levels: fewer answers; a level of 1e300 lies above every count: below_at_start (documented)
                   accepts={"levels": FEWER | {"huge"}}),
        EntryPoint("prediction.safe_path_length", lambda a: metrics.safe_path_length(a["theta_p"], a["theta_a"]),
                   lambda tmp: {"theta_p": np.array([5.0, 9.0]), "theta_a": np.array([7.0, 8.0])},
                   {"theta_p": "array", "theta_a": "array"}, accepts=UNKNOWN_POSITION),
        EntryPoint("prediction.incursion", lambda a: metrics.incursion(a["theta_p"], a["theta_a"]),
                   lambda tmp: {"theta_p": np.array([5.0, 9.0]), "theta_a": np.array([7.0, 8.0])},
                   {"theta_p": "array", "theta_a": "array"}, accepts=UNKNOWN_POSITION),
        EntryPoint("prediction.NextStepSupervisor.update",
                   lambda a: _supervisor().update(a["theta"], a["n_inliers"]),
                   lambda tmp: {"theta": 2.5, "n_inliers": np.array([200.0, 210.0])},
                   {"theta": "scalar", "n_inliers": "array"},
                   accepts={"n_inliers": {"one_element", "one_fewer"}},  # fewer images at this stop
                   flagged=lambda d: d.status in ("non_finite", "bad_threshold") or d.fit_status not in ("ok", "no_fit")),
        EntryPoint("prediction.long_range",
                   lambda a: predictors.long_range(_series(a["theta"], a["n_inliers"]), 4, "emg", a["thresholds"],
                                                   P().fit, np.random.default_rng(0), 64),
                   lambda tmp: {"theta": inlier_series()[0], "n_inliers": inlier_series()[1],
                                "thresholds": np.array([15.0, 30.0])},
                   {"theta": "array", "n_inliers": "array", "thresholds": "array"},
                   flagged=lambda r: _boundaries_flagged(r.prediction) or r.fitted is None or r.fitted.status != "ok",
                   accepts=SERIES_ACCEPTS),
        EntryPoint("prediction.next_step",
                   lambda a: predictors.next_step(_series(a["theta"], a["n_inliers"]), 4, "emg", a["thresholds"],
                                                  P().fit, 0, "usac_magsac", 64),
                   lambda tmp: {"theta": inlier_series()[0], "n_inliers": inlier_series()[1],
                                "thresholds": np.array([15.0, 30.0])},
                   {"theta": "array", "n_inliers": "array", "thresholds": "array"},
                   flagged=lambda r: bool((~np.isin(r.fit_status, ["ok"])).any()
                                          or (~np.isin(r.prediction.status, ["stopped", "end_of_path"])).any()),
                   accepts=SERIES_ACCEPTS),
        EntryPoint("prediction.error_long_range",
                   lambda a: error_predictors.error_long_range(
                       _series(a["theta"], a["n_inliers"], a["sigma_t"]), 4, "emg", a["safety_factors"], (2.0, 3.0), P().fit,
                       np.random.default_rng(0), 64),
                   lambda tmp: {"theta": inlier_series()[0], "n_inliers": inlier_series()[1],
                                "sigma_t": 0.3 * np.sqrt(inlier_series()[1][0] / inlier_series()[1]),
                                "safety_factors": np.array([1.0, 3.0])},
                   {"theta": "array", "n_inliers": "array", "sigma_t": "array", "safety_factors": "array"},
                   flagged=lambda r: _boundaries_flagged(r[0]) or r[1] != "ok",
                   accepts=SERIES_ACCEPTS | {"sigma_t": {"nan", "inf", "huge"},  # no usable error at an image
                                             "safety_factors": FEWER | {"huge"}}),
        # ---- tracking
        EntryPoint("tracking.detect_markers",
                   lambda a: _warned(detection.detect_markers, a["ir"], a["depth_mm"], a["unproject"],
                                     P().track.detection),
                   lambda tmp: {"ir": tracking_frame()["ir"], "depth_mm": tracking_frame()["depth"],
                                "unproject": tracking_frame()["lut"]},
                   {"ir": "image", "depth_mm": "image", "unproject": "points"}, flagged=_warning_flag,
                   # uint8/uint16/float IR and depth are documented inputs; a NaN pixel is an invalid pixel
                   accepts={"ir": {"uint16", "float32", "int32", "float_nan"},
                            "depth_mm": {"uint16", "float32", "int32", "float_nan"}}),
        EntryPoint("tracking.detect_markers[K, T_world_cam]",
                   lambda a: _warned(detection.detect_markers, tracking_frame()["ir"], tracking_frame()["depth"], a["K"],
                                     P().track.detection, a["T_world_cam"]),
                   lambda tmp: {"K": tracking_frame()["K"], "T_world_cam": np.eye(4)}, {"K": "matrix", "T_world_cam": "matrix"},
                   flagged=_warning_flag, accepts={"T_world_cam": {"None"}}),  # None: the camera's frame (documented)
        EntryPoint("tracking.kabsch", lambda a: kabsch_fit(a["points_world"], a["points_body"]),
                   lambda tmp: {"points_world": tracking_frame()["markers"], "points_body": tracking_frame()["geometry"]},
                   {"points_world": "points", "points_body": "points"},
                   accepts={"points_world": {"wrong_ndim"}}),  # (..., n, 3): a stack of frames is documented
        EntryPoint("tracking.match_markers",
                   lambda a: correspondence.match_markers(a["points"], a["geometry"], None, P().track.matching),
                   lambda tmp: {"points": tracking_frame()["markers"], "geometry": tracking_frame()["geometry"]},
                   {"points": "points", "geometry": "points"}, accepts={"geometry": {"one_fewer"}},  # 3 markers: a tool
                   flagged=lambda result: bool((np.asarray(result) < 0).any())),
        EntryPoint("tracking.MarkerTracker.frame", lambda a: _tracker().frame(a["t"], a["points"]),
                   lambda tmp: {"t": 0.05, "points": tracking_frame()["markers"]},
                   {"t": "timestamp", "points": "points"}, flagged=_any_flag, accepts=TRACKER_ACCEPTS),
        EntryPoint("tracking.MarkerTracker.gyro", lambda a: _tracker().gyro(a["t"], a["omega_body"]),
                   lambda tmp: {"t": 0.01, "omega_body": np.array([0.1, 0.0, 0.0])},
                   {"t": "timestamp", "omega_body": "array"}, flagged=lambda r: r != "ok"),
        EntryPoint("tracking.SquareRootUKF.predict", lambda a: _filter("srukf").predict(a["dt"]),
                   lambda tmp: {"dt": 0.01}, {"dt": "scalar"}, flagged=lambda ok: ok is False),
        EntryPoint("tracking.SquareRootUKF.update",
                   lambda a: _filter("srukf").update(a["z"], a["observed"], False),
                   lambda tmp: {"z": tracking_frame()["markers"].ravel(), "observed": np.ones(4, bool)},
                   {"z": "array", "observed": "array"}, flagged=lambda ok: ok is False,
                   accepts={"observed": {"bool"}}),  # all True: every marker observed, a valid mask
        EntryPoint("tracking.UnscentedKalmanFilter.update",
                   lambda a: _filter("ukf").update(a["z"], a["observed"], False),
                   lambda tmp: {"z": tracking_frame()["markers"].ravel(), "observed": np.ones(4, bool)},
                   {"z": "array", "observed": "array"}, flagged=lambda ok: ok is False,
                   accepts={"observed": {"bool"}}),  # all True: every marker observed, a valid mask
        EntryPoint("tracking.read_tools", lambda a: tool_files.read_tools(a["path"], P().track.matching.distinct_m),
                   lambda tmp: {"path": _tools_json(tmp)}, {"path": "text_file"}),
        EntryPoint("tracking.MultiToolTracker",
                   lambda a: multi_tool.MultiToolTracker(a["tools"], P().track.filter, P().track.matching).frame(
                       0.0, a["points"]),
                   lambda tmp: {"tools": {"probe": tracking_frame()["geometry"]}, "points": tracking_frame()["markers"]},
                   {"points": "points"}, flagged=_any_flag, accepts=TRACKER_ACCEPTS),
        *[EntryPoint(f"tracking.read_recording[{name}]", lambda a: recording.read_recording(a["file"].parent),
                     lambda tmp, name=name: {"file": _recording_dir(tmp) / name}, {"file": "file"},
                     names={"file": name}, accepts={"file": {"missing"}} if name == "gyro.csv" else {})
          for name in ("frames.csv", "gyro.csv", "lut_x.npy")],
        EntryPoint("tracking.RecordingWriter",
                   lambda a: _write_recording(a["folder"], a["t"], a["ir"], a["depth_mm"], a["gyro_t"], a["gyro"]),
                   lambda tmp: {"folder": tmp / "written", "t": 0.046, "ir": tracking_frame()["ir"],
                                "depth_mm": tracking_frame()["depth"], "gyro_t": np.array([0.01, 0.02]),
                                "gyro": np.zeros((2, 3))},
                   {"t": "timestamp", "ir": "image", "depth_mm": "image", "gyro_t": "array", "gyro": "points"},
                   # 8/16-bit frames, any clock; a NaN rate is kept and flagged bad_gyro when tracked
                   accepts={"ir": {"uint16"}, "depth_mm": {"uint16"}, "t": {"negative"}, "gyro": {"nan"}}),
        EntryPoint("tracking.track_recording",
                   lambda a: recording_replay.track_recording(recording.read_recording(a["file"].parents[1]),
                                                              {"probe": tracking_frame()["geometry"]}, P().track),
                   lambda tmp: {"file": _recording_dir(tmp) / "ir" / "000001.png"}, {"file": "file"},
                   names={"file": "000001.png"}, flagged=_any_flag),
        # ---- HoloLens 2 recordings, converted (a frame without a headset pose is flagged in camera_poses.csv)
        *[EntryPoint(f"tracking.convert_stream_recorder[{Path(name).name}]",
                     lambda a: hl2_recordings.convert_stream_recorder(_capture_of(a["file"]), _capture_of(a["file"]).parent / "converted",
                                                                      overwrite=True),
                     lambda tmp, name=name: {"file": _stream_recorder_capture(tmp) / name}, {"file": _file_kind(name)},
                     names={"file": Path(name).name}, flagged=_pose_missing)
          for name in ("Depth AHaT/1000.pgm", "Depth AHaT/1000_ab.pgm", "Depth AHaT_lut.bin", "Depth AHaT_extrinsics.txt",
                       "Depth AHaT_rig2world.txt")],
        *[EntryPoint(f"tracking.convert_hl2ss[{Path(name).name}]",
                     lambda a: hl2_recordings.convert_hl2ss(_hl2ss_of(a["file"]) / "rm_depth_ahat.bin",
                                                            _hl2ss_of(a["file"]) / "calibration",
                                                            _hl2ss_of(a["file"]).parent / "converted", overwrite=True),
                     lambda tmp, name=name: {"file": _hl2ss_recording(tmp) / name}, {"file": "file"},
                     names={"file": Path(name).name}, flagged=_pose_missing)
          for name in ("rm_depth_ahat.bin", "calibration/rm_depth_ahat/uv2xy.bin", "calibration/rm_depth_ahat/extrinsics.bin",
                       "calibration/rm_depth_ahat/scale.bin")],
        # ---- recorded datasets: every file of the folder (an image lies one folder down)
        *[EntryPoint(f"recorded.read_recorded[{Path(name).name}]",
                     lambda a, name=name: reader.read_recorded(a["file"].parents[name.count("/")]),
                     lambda tmp, name=name: {"file": _recorded_dir(tmp) / name}, {"file": _file_kind(name)})
          for name in RECORDED_FILES],
        EntryPoint("recorded.read_image", lambda a: reader.read_image(a["path"]), lambda tmp: {"path": _png(tmp)},
                   {"path": "file"}),
        EntryPoint("recorded.viewing_angle_deg", lambda a: geometry.viewing_angle_deg(a["T_cam0_ref"], a["T_cam_ref"]),
                   lambda tmp: {"T_cam0_ref": loc()["T"], "T_cam_ref": loc()["T"]},
                   {"T_cam0_ref": "matrix", "T_cam_ref": "matrix"}),
        EntryPoint("recorded.distance_mm", lambda a: geometry.distance_mm(a["origin_mm"], a["T_cam_ref"]),
                   lambda tmp: {"origin_mm": np.zeros(3), "T_cam_ref": loc()["T"]},
                   {"origin_mm": "array", "T_cam_ref": "matrix"}),
        EntryPoint("recorded.relative_pose", lambda a: geometry.relative_pose(a["T_cam0_ref"], a["T_cam1_ref"]),
                   lambda tmp: {"T_cam0_ref": loc()["T"], "T_cam1_ref": loc()["T"]},
                   {"T_cam0_ref": "matrix", "T_cam1_ref": "matrix"}),
        *[EntryPoint(f"recorded.import_rosbag[{name}]",
                     lambda a, name=name: rosbag.import_rosbag(
                         a["file"] if name == "bag" else a["file"].parent / "run.bag", "/camera/image",
                         "/camera/camera_info", a["file"] if name == "stops" else a["file"].parent / "stops.csv",
                         a["file"].parent / "imported", trajectory="arc"),
                     lambda tmp, name=name: {"file": _bag_dir(tmp) / ("run.bag" if name == "bag" else "stops.csv")},
                     {"file": "file" if name == "bag" else "text_file"})
          for name in ("bag", "stops")],
        EntryPoint("recorded.materialize", lambda a: materialize.materialize([a["file"].parent], a["file"].parents[2]),
                   lambda tmp: {"file": _recorded_dir(tmp) / "stops.csv"}, {"file": "text_file"}),
        EntryPoint("recorded.export_dataset",
                   lambda a: export.export_dataset(a["meta"].parents[2], f"datasets/{a['meta'].parent.name}",
                                                   a["meta"].parents[2] / "exported"),
                   lambda tmp: {"meta": _dataset_dir(tmp).parent / "ds_arc" / "meta.json"}, {"meta": "file"}),
        *[EntryPoint(f"python -m poseintegrity.recorded validate [{Path(name).name}]",
                     lambda a, name=name: _cli(recorded_cli.main,
                                               ["validate", str(a["file"].parents[name.count("/")])], a["file"]),
                     lambda tmp, name=name: {"file": _recorded_dir(tmp) / name}, {"file": _file_kind(name)},
                     flagged=_cli_listed)
          for name in RECORDED_FILES],
        # ---- stage tables and the files they are written to
        EntryPoint("table_checks.check_envelopes", lambda a: table_checks.check_envelopes(a["table"]),
                   lambda tmp: {"table": _envelope_table()}, {"table": "table"}),
        EntryPoint("table_checks.check_artifacts", lambda a: table_checks.check_artifacts(a["table"]),
                   lambda tmp: {"table": _artifacts_table()}, {"table": "table"}),
        EntryPoint("table_checks.read_envelopes", lambda a: table_checks.read_envelopes(a["path"]),
                   lambda tmp: {"path": _parquet(tmp, "envelopes.parquet", _envelope_table())}, {"path": "file"}),
        EntryPoint("table_checks.read_fig2_rmse", lambda a: table_checks.read_fig2_rmse(a["path"]),
                   lambda tmp: {"path": _parquet(tmp, "fig2_rmse.parquet", _fig2_table())}, {"path": "file"}),
        EntryPoint("table_checks.read_artifacts", lambda a: table_checks.read_artifacts(a["path"]),
                   lambda tmp: {"path": _parquet(tmp, "artifacts.parquet", _artifacts_table())}, {"path": "file"}),
        # ---- command lines: one line naming the file, exit status 2, no traceback
        EntryPoint("python -m poseintegrity.tracking.replay",  # the recording stays where it is (checked first)
                   lambda a: _cli(replay.main, [str(a["recording"]), "--tools", str(a["tools"]), "--out",
                                                str(a["recording"].parent / "poses.csv"), "--params", str(TINY_PARAMS)],
                                  a["tools"]),
                   lambda tmp: {"recording": _recording_dir(tmp), "tools": _tools_json(tmp)}, {"tools": "text_file"},
                   flagged=_cli_refused),
        EntryPoint("python -m poseintegrity.stage_timing", lambda a: _cli(stage_timing.main, [str(a["path"].parent)], a["path"]),
                   lambda tmp: {"path": _timing_file(tmp)}, {"path": "file"}, flagged=_cli_refused,
                   accepts={"path": {"missing"}}),  # a folder without timing files yet: said, exit 0
    ]
    return entries


ENTRY_POINTS: dict[str, EntryPoint] = {}


def entry_points() -> dict[str, EntryPoint]:
    if not ENTRY_POINTS:
        ENTRY_POINTS.update({entry.name: entry for entry in _entries()})
    return ENTRY_POINTS


# ------------------------------------------------------------------------------------------------ helpers
def _file_kind(name: str) -> str:
    """A text file a person may write or edit (tables, YAML, JSON, text) is a "text_file"; images and binaries "file"."""
    return "text_file" if name.endswith((".csv", ".yaml", ".json", ".txt")) else "file"


def _overlay(folder: Path, values: dict[str, Any]) -> Path:
    """A params overlay on the tiny parameters setting ``values`` (arrays written as lists)."""
    def plain(value):
        return {k: plain(v) for k, v in value.items()} if isinstance(value, dict) else (
            value.tolist() if isinstance(value, np.ndarray) else value)
    return _write(folder, "overlay.yaml", yaml.safe_dump({"extends": str(TINY_PARAMS), **plain(values)}))


def _text_in_x_mm(table: pd.DataFrame, _) -> pd.DataFrame:
    """A frames table whose x_mm holds text in its first row, as a hand-edited table may ('20.0 mm')."""
    bad = table.astype({"x_mm": object})
    bad.loc[bad.index[0], "x_mm"] = "20.0 mm"
    return bad


def _warned(function, *args):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = function(*args)
    return result, [str(w.message) for w in caught]


def _warning_flag(result) -> bool:
    return bool(result[1])


def _supervisor():
    from poseintegrity.prediction.supervisor import NextStepSupervisor

    s = NextStepSupervisor.from_params(params(), "arc", n_t=30.0, theta_b=2.5, rng=np.random.default_rng(0))
    s.update(0.0, np.array([300.0, 305.0]))
    return s


def _descriptors(seed: int) -> np.ndarray:
    return np.random.default_rng(seed).random((40, 128)).astype(np.float32)


def _two_views() -> dict[str, Any]:

    rng = np.random.default_rng(3)
    X = rng.uniform([-20, -20, 280], [20, 20, 320], (30, 3))
    T = np.eye(4)
    T[:3, 3] = [-20.0, 0.0, 0.0]
    K = localization_scene()["K"]

    def project(points):
        uv = (K @ points.T).T
        return uv[:, :2] / uv[:, 2:]

    return {"K": K, "T_cam1_cam0": T, "x0": project(X), "x1": project(X + T[:3, 3])}


def _png(tmp: Path) -> Path:
    import cv2

    path = tmp / "image.png"
    cv2.imwrite(str(path), localization_scene()["image"])
    return path


def _camera_yaml(tmp: Path) -> Path:
    from poseintegrity.lens import write_camera_yaml

    path = tmp / "camera.yaml"
    write_camera_yaml(path, localization_scene()["camera"], "battery")
    return path


RECORDED_FILES = ("dataset.yaml", "camera.yaml", "board.yaml", "model.csv", "stops.csv", "images/s00_i00.png",
                  "model/mask_1.png")


def _recorded_dir(tmp: Path) -> Path:
    """A recorded dataset folder: the one-image stage-01 dataset of :func:`_dataset_dir` exported (a copy in ``tmp``
    of the one exported once per session, as :func:`_dataset_dir`)."""
    folder = tmp / "recorded" / "ds_arc"
    shutil.copytree(_recorded_once(str(tmp.parent / "shared")), folder, dirs_exist_ok=True)
    return folder


@cache
def _recorded_once(shared: str) -> Path:
    from poseintegrity.recorded.export import export_dataset

    return export_dataset(_dataset_once(shared), "datasets/ds_arc", Path(shared) / "recorded")


def _bag_dir(tmp: Path) -> Path:
    """A ROS 1 bag (run.bag: the model pair and a stop as CompressedImage PNGs, a CameraInfo) and its stops.csv."""
    from recorded_tools import write_bag

    folder = tmp / "bag"
    folder.mkdir(parents=True, exist_ok=True)
    image = _png(tmp).read_bytes()
    write_bag(folder / "run.bag", 1, [image] * 3, localization_scene()["camera"])
    (folder / "stops.csv").write_text("index,stop\n0,model0\n1,model1\n2,0\n")
    return folder


def _tools_json(tmp: Path) -> Path:
    geometry = tracking_frame()["geometry"]
    return _write(tmp, "tools.json", json.dumps({"tools": [{"name": "probe", "markers_body": geometry.tolist()}]}))


def _hl2_frames() -> list:
    frame = tracking_frame(HL2_SIZE)
    return [(1000 + 460_000 * k, frame["ir"], frame["depth"]) for k in range(3)]  # 46 ms apart, in 100 ns ticks


def _stream_recorder_capture(tmp: Path) -> Path:
    from tracking.hl2_writers import write_stream_recorder

    return write_stream_recorder(tmp / "capture", tracking_frame(HL2_SIZE)["lut"], _hl2_frames(), rig_to_cam=np.eye(4),
                                 rig_to_world=[np.eye(4)] * 3)


def _capture_of(file: Path) -> Path:
    return next(p for p in Path(file).parents if p.name == "capture")


def _hl2ss_recording(tmp: Path) -> Path:
    from tracking.hl2_writers import write_hl2ss

    (tmp / "hl2ss").mkdir(parents=True, exist_ok=True)
    write_hl2ss(tmp / "hl2ss" / "rm_depth_ahat.bin", tmp / "hl2ss" / "calibration", tracking_frame(HL2_SIZE)["lut"], _hl2_frames(),
                np.eye(4), [np.eye(4)] * 3)
    return tmp / "hl2ss"


def _hl2ss_of(file: Path) -> Path:
    return next(p for p in Path(file).parents if p.name == "hl2ss")


def _pose_missing(folder: Path) -> bool:
    """A converted recording with frames the headset could not locate (no pose in camera_poses.csv)."""
    poses = Path(folder) / "camera_poses.csv"
    return not poses.is_file() or not pd.read_csv(poses).has_pose.all()


def _recording_copy(tmp: Path, name: str) -> Path:
    source = _recording_dir(str(tmp.parent / "shared"))
    folder = tmp / f"copy_{name}"
    if not folder.exists():
        shutil.copytree(source, folder)
    return folder / name


def _dataset_dir(tmp: Path) -> Path:
    """index.parquet of a one-image stage-01 dataset (loc_synthetic) in ``tmp``: a copy of the one written once per
    session beside the cases' folders (writing it took 27 ms, a copy takes 2), so that each case spoils its own."""
    data_dir = tmp / "data"
    shutil.copytree(_dataset_once(str(tmp.parent / "shared")), data_dir, dirs_exist_ok=True)
    return data_dir / "datasets" / "index.parquet"


@cache
def _dataset_once(shared: str) -> Path:
    import loc_synthetic as synthetic

    data_dir = Path(shared) / "data"
    rows = [synthetic.write_dataset(data_dir, "ds_arc", np.random.default_rng(0), stops=(10.0,), images_per_stop=1)]
    synthetic.write_index(data_dir, rows)
    return data_dir


def _series(theta: np.ndarray, n_inliers: np.ndarray, sigma_t: np.ndarray | None = None):
    """A Series of these samples; with ``sigma_t``, its predicted errors too (E_r's: 0.1 x E_t's, in deg)."""
    from poseintegrity.artifact_models.series import Series

    theta = np.asarray(theta)  # the stops of the valid series (3 images each), as long as theta has entries
    stop = np.arange(theta.shape[0]) // 3 if theta.dtype.kind in "iuf" and theta.ndim == 1 else theta
    sigma_r = None if sigma_t is None else 0.1 * np.asarray(sigma_t, dtype=float) if np.asarray(sigma_t).dtype.kind in "iuf" else sigma_t
    return Series("scene_1_arc000", "arc", stop, theta, n_inliers, 45.0, sigma_t, sigma_r)


def _boundaries_flagged(b) -> bool:
    return bool(np.isin(b.status, ["non_finite", "bad_threshold", "too_few_stops"]).any())


def _write_recording(folder: Path, t, ir, depth_mm, gyro_t, gyro) -> Path:
    from poseintegrity.tracking.io.recording import RecordingWriter, read_recording

    writer = RecordingWriter(folder, tracking_frame()["lut"])
    writer.add_frame(0.0, tracking_frame()["ir"], tracking_frame()["depth"])
    writer.add_frame(t, ir, depth_mm)
    writer.close(gyro_t, gyro)
    return read_recording(folder)


def _fig2_table() -> pd.DataFrame:
    return pd.DataFrame([dict(trajectory="arc", dataset=f"scene_1_arc00{i}", k=4, model="emg", rmse=5.0 + i,
                              status="ok", reason="ok", n_samples=12) for i in range(2)])


def _parquet(tmp: Path, name: str, table: pd.DataFrame) -> Path:
    folder = tmp / "tables"
    folder.mkdir(parents=True, exist_ok=True)
    table.to_parquet(folder / name)
    return folder / name


def _artifacts_table() -> pd.DataFrame:
    rows = [dict(world="main", dataset=dataset, trajectory="arc", stop=stop, image=0, theta_deg=2.5 * stop,
                 x_mm=0.0, method="usac_magsac", status="ok", n_inliers=100.0 - 10 * stop, E_t_mm=0.2, E_r_deg=0.1)
            for dataset in ("scene_1_arc000", "scene_1_arc001") for stop in range(3)]
    return pd.DataFrame(rows)


def _timing_file(tmp: Path) -> Path:
    from poseintegrity.stage_timing import StageTiming

    folder = tmp / "timing"
    folder.mkdir(parents=True, exist_ok=True)
    StageTiming("01_generate_datasets", 12.0, "local", 2, None, "2026-11-25T10:00:00").write(folder / "01.json")
    return folder / "01.json"


@dataclass(frozen=True)
class CommandResult:
    status: int
    stderr: str
    names_the_file: bool


def _cli(main, argv: list[str], path: Path) -> CommandResult:
    """Run a command line's main in-process: its exit status and what it wrote on stderr."""
    import contextlib
    import io

    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        try:
            main(argv)
            status = 0
        except SystemExit as exit_:
            status = exit_.code if isinstance(exit_.code, int) else 1
            stderr.write("" if isinstance(exit_.code, int) or exit_.code is None else str(exit_.code))
    text = stderr.getvalue()
    return CommandResult(status, text, Path(path).name in text)


def _cli_refused(result: CommandResult) -> bool:
    """Exit status 2 with one line naming the file, no traceback."""
    lines = result.stderr.strip().splitlines()
    return result.status == 2 and len(lines) == 1 and result.names_the_file and "Traceback" not in result.stderr


def _cli_listed(result: CommandResult) -> bool:
    """Exit status 2, the file named, one line per problem each naming its file (a path), no traceback: what
    ``validate`` prints, every problem of the folder at once."""
    lines = result.stderr.strip().splitlines()
    return (result.status == 2 and result.names_the_file and "Traceback" not in result.stderr
            and all("/" in line for line in lines))


def _envelope_table() -> pd.DataFrame:
    rows = []
    for dataset, theta_a in (("scene_1_arc000", 12.5), ("scene_1_arc001", 17.0)):
        for tolerance in ("2mm_3deg", "4mm_10deg"):
            rows.append(dict(world="main", dataset=dataset, trajectory="arc", method="usac_magsac",
                             tolerance=tolerance, rule="fail_fraction", theta_a=theta_a, censored=False))
    return pd.DataFrame(rows)
