"""Bad input to the tracking entry points gives a family error naming the thing, or a flagged result; never a
raw IndexError / numba error / NaN pose presented as ordinary."""

import json

import cv2
import numpy as np
import pandas as pd
import pytest

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.tracking.simulation.frames import intrinsics, render_frame, unit_plane_lut
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M
from poseintegrity.tracking.markers.kabsch import kabsch, pose_from_points
from poseintegrity.tracking.io.recording import RecordingError, RecordingWriter, read_recording, track_recording, write_manifest
from poseintegrity.tracking.filter.srukf import SquareRootUKF
from poseintegrity.tracking.filter.multi_tool import MultiToolTracker
from poseintegrity.tracking.io.tool_files import read_tools
from poseintegrity.tracking.markers.tools import ToolError
from poseintegrity.tracking.filter.tracker import MarkerTracker
from poseintegrity.tracking.filter.ukf import UnscentedKalmanFilter

from tracking.track_section import GEOMETRY, TRACK
from tracking.track_section import TINY as PARAMS

SECOND = np.array(TRACK.evaluation.second_tool)
POINTS = GEOMETRY + [0.0, 0.0, 0.45]


def _tracker():
    tracker = MarkerTracker(GEOMETRY, TRACK.filter, TRACK.matching)
    assert tracker.frame(0.0, POINTS).flag == "initialized"
    return tracker


@pytest.mark.parametrize("t, found", [(None, "NoneType"), ("0.1", "str"), (1e300, "1e\\+300"), (float("nan"), "nan"), (True, "bool")])
def test_bad_timestamps_are_refused_naming_t(t, found):
    tracker = _tracker()
    with pytest.raises(PoseIntegrityError, match=f"^t: expected .*{found}"):
        tracker.frame(t, POINTS)
    with pytest.raises(PoseIntegrityError, match=f"^t: expected .*{found}"):
        tracker.gyro(t, np.zeros(3))
    with pytest.raises(PoseIntegrityError, match="^t: "):
        MultiToolTracker({"probe": GEOMETRY}, TRACK.filter, TRACK.matching).frame(t, POINTS)


def test_time_going_backwards_is_flagged_stale_and_a_long_jump_restarts():
    tracker = _tracker()
    x = tracker.filter.x.copy()
    assert tracker.frame(-0.5, POINTS).flag == "stale" and tracker.gyro(-0.5, np.zeros(3)) == "stale"
    np.testing.assert_array_equal(tracker.filter.x, x)  # a stale sample changes nothing
    gyro_tracker = MarkerTracker(GEOMETRY, TRACK.filter, TRACK.matching, use_gyro=True)
    gyro_tracker.frame(0.0, POINTS)
    assert gyro_tracker.gyro(1e9, np.zeros(3)) == "restart"  # no 4e11 filter steps for a clock glitch
    first = MarkerTracker(GEOMETRY, TRACK.filter, TRACK.matching)
    assert first.frame(-3.0, POINTS).flag == "initialized"  # negative clocks are clocks


def test_points_and_gyro_of_the_wrong_shape_are_refused():
    tracker = _tracker()
    with pytest.raises(PoseIntegrityError, match=r"points: expected shape \(n, 3\), got \(4, 2\)"):
        tracker.frame(0.05, POINTS[:, :2])
    with pytest.raises(PoseIntegrityError, match=r"points: expected shape \(n, 3\), got \(6, 2\)"):
        tracker.frame(0.05, np.zeros((6, 2)))  # 12 numbers: reshape(-1, 3) used to make 4 points of them
    with pytest.raises(PoseIntegrityError, match="points: expected an array, got str"):
        tracker.frame(0.05, "points")
    for omega in (np.zeros(2), np.zeros(4), np.zeros((1, 3))):
        with pytest.raises(PoseIntegrityError, match=r"omega_body: expected shape \(3\)"):
            tracker.gyro(0.05, omega)
    assert tracker.gyro(0.05, np.array([np.nan, 0.0, 0.0])) == "bad_gyro"  # bad data: a flag
    assert tracker.frame(0.1, []).flag == "no_points"


@pytest.mark.parametrize("cls", [SquareRootUKF, UnscentedKalmanFilter])
def test_filter_steps_and_updates_are_checked_at_the_entry(cls):
    f = cls(GEOMETRY, TRACK.filter)
    f.initialize(POINTS)
    for dt in (-0.01, 0.0, float("nan"), "0.01"):
        with pytest.raises(PoseIntegrityError, match="dt: expected a finite time step > 0"):
            f.predict(dt)
    with pytest.raises(PoseIntegrityError, match="n_steps: expected a non-negative integer"):
        f.predict_steps(-1, 0.0025)
    assert f.predict_steps(0, 0.0)  # nothing to do
    with pytest.raises(PoseIntegrityError, match=r"z: expected shape \(12,\).*got \(5,\)"):
        f.update(np.zeros(5), np.ones(4, bool), gyro=False)
    with pytest.raises(PoseIntegrityError, match=r"observed: expected a boolean mask of shape \(4,\).*got shape \(3,\)"):
        f.update(POINTS[:3].ravel(), np.ones(3, bool), gyro=False)
    with pytest.raises(PoseIntegrityError, match=r"observed: .*got shape \(5,\)"):
        f.update(POINTS.ravel(), np.ones(5, bool), gyro=False)
    with pytest.raises(PoseIntegrityError, match="observed: .*dtype int64"):
        f.update(POINTS[:3].ravel(), np.array([0, 1, 2]), gyro=False)  # indices are not a mask
    with pytest.raises(PoseIntegrityError, match=r"markers: expected shape \(4, 3\)"):
        f.initialize(POINTS[:3])
    assert f.update(POINTS.ravel(), np.ones(4, bool), gyro=False) and f.initialized


def test_kabsch_refuses_non_finite_too_few_and_collinear_points():
    with pytest.raises(PoseIntegrityError, match="points_world: entries must be finite.*nan"):
        pose_from_points(POINTS * np.nan, GEOMETRY)
    with pytest.raises(PoseIntegrityError, match="points_world: entries must be finite.*inf"):
        kabsch(np.where(np.eye(4, 3) > 0, np.inf, POINTS), GEOMETRY)
    with pytest.raises(PoseIntegrityError, match="points_world: Kabsch needs at least 3 corresponding points, got 2"):
        pose_from_points(POINTS[:2], GEOMETRY[:2])
    line = np.array([[0, 0, 0], [0.01, 0, 0], [0.03, 0, 0]], float)
    with pytest.raises(PoseIntegrityError, match="points_body: the points lie on one line"):
        pose_from_points(line + [0, 0, 0.5], line)
    with pytest.raises(PoseIntegrityError, match=r"points_body: expected shape \(3, 3\)"):
        pose_from_points(POINTS[:3], GEOMETRY)
    with pytest.raises(PoseIntegrityError, match=r"points_body: the points lie on one line"):
        MarkerTracker(line, TRACK.filter, TRACK.matching)
    assert np.isfinite(pose_from_points(POINTS, GEOMETRY)).all()


def test_multi_tool_tracker_refuses_empty_duplicated_and_unknown_tools():
    with pytest.raises(ToolError, match="no tools given"):
        MultiToolTracker({}, TRACK.filter, TRACK.matching)
    with pytest.raises(ToolError, match="tool name 'a' appears more than once"):
        MultiToolTracker([("a", GEOMETRY), ("a", SECOND)], TRACK.filter, TRACK.matching)
    with pytest.raises(ToolError, match=r"gyro_tool: 'nope' names no tool; the tools are \['probe'\]"):
        MultiToolTracker({"probe": GEOMETRY}, TRACK.filter, TRACK.matching, gyro_tool="nope")
    with pytest.raises(ToolError, match="needs at least 3 rows, got 2"):
        MultiToolTracker({"probe": GEOMETRY[:2]}, TRACK.filter, TRACK.matching)


def test_a_frame_without_detections_is_flagged_and_tracking_recovers():
    tracker = MultiToolTracker({"probe": GEOMETRY, "needle": SECOND}, TRACK.filter, TRACK.matching)
    both = np.vstack([POINTS, SECOND + [0.1, 0.0, 0.5]])
    assert {r.flag for r in tracker.frame(0.0, both).values()} == {"initialized"}
    for k, empty in enumerate([np.zeros((0, 3)), np.full((3, 3), np.nan)]):  # a hand over the tools
        results = tracker.frame(0.05 * (k + 1), empty)
        assert {r.flag for r in results.values()} <= {"no_points", "no_markers"}
        assert all(np.isfinite(r.T_filtered).all() for r in results.values())  # the filters keep predicting
    assert tracker.frame(0.15, POINTS)["needle"].flag == "no_points"  # probe took every point: no IndexError
    assert {r.flag for r in tracker.frame(0.2, both).values()} == {"ok"}


def _write_tool(path, content):
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    return path


@pytest.mark.parametrize("name, content, message", [
    ("few.json", json.dumps({"tools": [{"name": "a", "markers_body": GEOMETRY[:2].tolist()}]}), "tool 'a'.* at least 3 rows, got 2"),
    ("dup.json", json.dumps({"tools": [{"name": "a", "markers_body": [GEOMETRY[0].tolist()] + GEOMETRY.tolist()}]}), "markers 1 and 2 at the same place"),
    ("nan.json", json.dumps({"tools": [{"name": "a", "markers_body": (GEOMETRY * [1, 1, np.nan]).tolist()}]}), "tool 'a'.* must be finite"),
    ("names.json", json.dumps({"tools": [{"name": "a", "markers_body": GEOMETRY.tolist()}, {"name": "a", "markers_body": SECOND.tolist()}]}), "'a' appears more than once"),
    ("none.json", json.dumps({"tools": []}), "no tools given"),
    ("zero.json", b"", "the tool file is empty"),
    ("zero.csv", b"", "the tool file is empty"),
    ("binary.json", bytes(range(256)) * 4, "not UTF-8 text"),
    ("binary.csv", b"tool,x,y,z\x00\x01\x02\n", "NUL bytes"),
    ("latin1.csv", "tool,x,y,z\n\xe9,0,0,0\n".encode("latin-1"), "not UTF-8 text"),
    ("few.csv", "tool,x,y,z\na,0,0,0\na,0.01,0,0\n", "at least 3 rows, got 2"),
    ("text.csv", "tool,x,y,z\na,0,0,0\na,0.01,0,0\na,abc,0.02,0\n", "x of row 3 is not a number"),
    ("split.csv", "tool,x,y,z\n" + "".join(f"a,{x},{y},{z}\n" for x, y, z in GEOMETRY[:3]) + "b,0,0,0\na,0.1,0.1,0.1\n", "'a' appears again at row 5"),
])
def test_bad_tool_files_are_refused_naming_the_file(tmp_path, name, content, message):
    path = _write_tool(tmp_path / name, content)
    with pytest.raises(ToolError, match=f"{name}: .*{message}"):
        read_tools(path, 0.001)


def test_a_missing_tool_file_is_refused_naming_it(tmp_path):
    with pytest.raises(ToolError, match="nope.json: cannot read the tool file"):
        read_tools(tmp_path / "nope.json", 0.001)


def _record(folder, n=4, overwrite=False, seed=0):
    camera = PARAMS.camera
    writer = RecordingWriter(folder, unit_plane_lut(intrinsics(camera), camera.width, camera.height), overwrite=overwrite)
    rng = np.random.default_rng(seed)
    for k in range(n):
        ir, depth = render_frame(GEOMETRY + [0.0, 0.0, 0.45], [], camera, PARAMS.frames, MARKER_DIAMETER_M / 2, rng)
        writer.add_frame(0.046 * k, ir, depth)
    writer.close()
    return folder


def test_writing_over_a_recording_needs_overwrite_and_replaces_it_whole(tmp_path):
    folder = _record(tmp_path / "rec", n=5)
    with pytest.raises(RecordingError, match="rec: the folder is not empty; pass overwrite=True"):
        _record(folder, n=2)
    assert len(read_recording(folder).frames) == 5  # the refused writer left it alone
    _record(folder, n=2, overwrite=True, seed=1)
    assert len(read_recording(folder).frames) == 2 and sorted(p.name for p in (folder / "ir").iterdir()) == ["000000.png", "000001.png"]
    assert [p.name for p in tmp_path.iterdir()] == ["rec"]  # no staging or old folder left behind


def test_a_folder_mixing_recordings_or_without_manifest_is_refused(tmp_path):
    folder = _record(tmp_path / "rec", n=3)
    other = _record(tmp_path / "other", n=3, seed=5)
    (folder / "ir" / "000001.png").write_bytes((other / "ir" / "000001.png").read_bytes())  # an old frame
    with pytest.raises(RecordingError, match="rec: does not match its manifest.json.*differ in size.*ir/000001.png"):
        read_recording(folder)
    (folder / "ir" / "000009.png").write_bytes(b"")
    with pytest.raises(RecordingError, match="not in the manifest.*ir/000009.png"):
        read_recording(folder)
    (folder / "manifest.json").unlink()
    with pytest.raises(RecordingError, match="rec: no manifest.json; the recording was not closed"):
        read_recording(folder)
    with RecordingWriter(tmp_path / "crashed", unit_plane_lut(intrinsics(PARAMS.camera), PARAMS.camera.width, PARAMS.camera.height)):
        pass  # never closed: nothing appears at the target
    assert not (tmp_path / "crashed").exists()


@pytest.mark.parametrize("name, content, message", [
    ("frames.csv", b"", r"frames.csv: the table \(expected a header t_s,ir,depth .*\) is empty"),
    ("frames.csv", bytes(range(256)) * 4, "frames.csv: (not UTF-8|contains NUL)"),
    ("frames.csv", b"t_s,ir,depth\n", "frames.csv: lists no frames"),
    ("gyro.csv", b"", r"gyro.csv: the table \(expected a header t_s,wx,wy,wz .*\) is empty"),
    ("gyro.csv", b"\xff\xfe" + "t_s,wx,wy,wz\n".encode("utf-16-le"), "gyro.csv: not UTF-8"),
    ("gyro.csv", b"t_s,wx,wy,wz\n0.01,0,0,0\n0.01,0,0,0\n", "gyro.csv: timestamps must increase; they repeat at row 1"),
])
def test_empty_or_binary_tables_are_refused_naming_the_file(tmp_path, name, content, message):
    folder = _record(tmp_path / "rec", n=2)
    (folder / name).write_bytes(content)
    write_manifest(folder)
    with pytest.raises(RecordingError, match=message):
        read_recording(folder)


def test_bad_lookup_tables_and_timestamps_are_refused(tmp_path):
    folder = _record(tmp_path / "rec", n=3)
    lut_x = np.load(folder / "lut_x.npy")
    np.save(folder / "lut_x.npy", np.where(np.eye(*lut_x.shape) > 0, np.nan, lut_x))
    with pytest.raises(RecordingError, match="lookup table has .* non-finite entries, e.g. lut_x.npy at pixel"):
        read_recording(folder)
    np.save(folder / "lut_x.npy", lut_x[:10, :10])
    np.save(folder / "lut_y.npy", np.load(folder / "lut_y.npy")[:10, :10])
    with pytest.raises(RecordingError, match="the lookup table is 10 x 10"):
        read_recording(folder)
    folder = _record(tmp_path / "rec2", n=3)
    frames = pd.read_csv(folder / "frames.csv")
    for times, message in [([0.0, 0.0, 0.1], "repeat at row 1"), ([0.0, 0.1, 1e300], "row 2 is not a finite number of seconds")]:
        frames.assign(t_s=times).to_csv(folder / "frames.csv", index=False)
        with pytest.raises(RecordingError, match=f"frames.csv: .*{message}"):
            read_recording(folder)
    with pytest.raises(RecordingError, match="nope: the recording folder does not exist"):
        read_recording(tmp_path / "nope")


def test_frames_without_detections_in_a_recording_are_flagged_and_tracking_goes_on(tmp_path):
    folder = _record(tmp_path / "rec", n=6)
    shape = (PARAMS.camera.height, PARAMS.camera.width)
    cv2.imwrite(str(folder / "depth" / "000001.png"), np.zeros(shape, np.uint16))  # all-zero depth
    cv2.imwrite(str(folder / "ir" / "000002.png"), np.full(shape, 80, np.uint16))  # a hand: no reflection
    np.save(folder / "depth" / "nan.npy", np.full(shape, np.nan))  # all-NaN depth
    frames = pd.read_csv(folder / "frames.csv")
    frames.loc[3, "depth"] = "depth/nan.npy"
    frames.to_csv(folder / "frames.csv", index=False)
    write_manifest(folder)
    table = track_recording(read_recording(folder), {"probe": GEOMETRY}, PARAMS)
    assert table.flag.iloc[0] == "initialized"
    assert set(table.flag.iloc[1:4]) <= {"no_points", "no_markers"} and np.isfinite(table.x_mm.iloc[1:4]).all()
    assert list(table.flag.iloc[4:]) == ["ok", "ok"]  # picked up again on the next good frame
    with pytest.raises(ToolError, match="gyro_tool: 'nope' names no tool"):
        track_recording(read_recording(folder), {"probe": GEOMETRY}, PARAMS, gyro_tool="nope")
