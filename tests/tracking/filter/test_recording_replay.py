import cv2
import numpy as np
import pandas as pd
import pytest

from poseintegrity.tracking.filter.recording_replay import track_recording
from poseintegrity.tracking.io.recording import read_recording, write_manifest
from poseintegrity.tracking.markers.tools import ToolError

from tracking.recording_folders import record
from tracking.track_section import GEOMETRY
from tracking.track_section import TINY as PARAMS


def _last_depth_in_metres(folder):
    """Replace the last frame's depth by a .npy of it in metres, and seal the folder again (a deliberate change)."""
    frames = pd.read_csv(folder / "frames.csv")
    depth = cv2.imread(str(folder / frames.depth.iloc[-1]), cv2.IMREAD_UNCHANGED)
    np.save(folder / "depth" / "last.npy", depth.astype(float) * 0.001)
    frames.loc[len(frames) - 1, "depth"] = "depth/last.npy"
    frames.to_csv(folder / "frames.csv", index=False)
    write_manifest(folder)


def test_depth_in_metres_and_wrong_shapes_are_flagged_rows_with_a_warning(tmp_path):
    record(tmp_path)
    _last_depth_in_metres(tmp_path)
    with pytest.warns(RuntimeWarning, match="last.npy|metres"):
        table = track_recording(read_recording(tmp_path), {"tool": GEOMETRY}, PARAMS)
    assert list(table.flag) == ["initialized", "ok", "ok", "bad_frame"]
    np.save(tmp_path / "depth" / "last.npy", np.zeros((10, 10)))
    write_manifest(tmp_path)
    with pytest.warns(RuntimeWarning, match="differs from IR shape"):
        table = track_recording(read_recording(tmp_path), {"tool": GEOMETRY}, PARAMS)
    assert table.flag.iloc[-1] == "bad_frame" and np.isfinite(table.x_mm.iloc[-1])  # the filter's pose, not NaN points


def test_an_undecodable_frame_is_a_flagged_row(tmp_path):
    record(tmp_path)
    (tmp_path / "ir" / "000002.png").write_bytes(b"not a png")  # present but truncated / corrupt
    write_manifest(tmp_path)
    with pytest.warns(RuntimeWarning, match="cannot decode ir/000002.png"):
        table = track_recording(read_recording(tmp_path), {"tool": GEOMETRY}, PARAMS)
    assert list(table.flag) == ["initialized", "ok", "bad_frame", "ok"] and table.n_points.iloc[2] == 0


def test_frames_without_detections_in_a_recording_are_flagged_and_tracking_goes_on(tmp_path):
    folder = record(tmp_path / "rec", n=6)
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
