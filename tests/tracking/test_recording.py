import numpy as np
import pandas as pd
import pytest

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.tracking.experiments.robustness import recording_replay
from poseintegrity.tracking.simulation.frames import intrinsics, render_frame, unit_plane_lut
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M
from poseintegrity.tracking.io.recording import RecordingError, RecordingWriter, read_recording, track_recording, write_manifest

from tracking.track_section import GEOMETRY
from tracking.track_section import TINY as PARAMS


def test_replay_from_disk_gives_the_in_memory_poses(tmp_path):
    table, agreement = recording_replay(PARAMS, tmp_path / "rec")
    assert agreement["same_flags"] and agreement["max_position_diff_mm"] < 1e-4
    assert (table.flag == "ok").mean() > 0.8
    assert {"t_s", "tool", "flag", "x_mm", "qw"} <= set(table.columns)


def _write(folder, n=4, depth_scale=1.0, npy=False):
    camera = PARAMS.camera
    writer = RecordingWriter(folder, unit_plane_lut(intrinsics(camera), camera.width, camera.height))
    rng = np.random.default_rng(0)
    for k in range(n):
        ir, depth = render_frame(GEOMETRY + [0.0, 0.0, 0.45], [], camera, PARAMS.frames, MARKER_DIAMETER_M / 2, rng)
        writer.add_frame(0.046 * k, ir, depth)
    writer.close()
    if npy or depth_scale != 1.0:  # replace the last frame's depth by a .npy in other units
        frames = pd.read_csv(folder / "frames.csv")
        np.save(folder / "depth" / "last.npy", depth.astype(float) * depth_scale)
        frames.loc[len(frames) - 1, "depth"] = "depth/last.npy"
        frames.to_csv(folder / "frames.csv", index=False)
        write_manifest(folder)  # a deliberate change: sealed again


def test_depth_in_metres_and_wrong_shapes_are_flagged_rows_with_a_warning(tmp_path):
    _write(tmp_path, depth_scale=0.001)
    with pytest.warns(RuntimeWarning, match="last.npy|metres"):
        table = track_recording(read_recording(tmp_path), {"tool": GEOMETRY}, PARAMS)
    assert list(table.flag) == ["initialized", "ok", "ok", "bad_frame"]
    np.save(tmp_path / "depth" / "last.npy", np.zeros((10, 10)))
    write_manifest(tmp_path)
    with pytest.warns(RuntimeWarning, match="differs from IR shape"):
        table = track_recording(read_recording(tmp_path), {"tool": GEOMETRY}, PARAMS)
    assert table.flag.iloc[-1] == "bad_frame" and np.isfinite(table.x_mm.iloc[-1])  # the filter's pose, not NaN points


def test_bad_recordings_are_refused_naming_the_problem(tmp_path):
    _write(tmp_path)
    frames = pd.read_csv(tmp_path / "frames.csv")
    frames.loc[2, "t_s"] = np.nan
    frames.to_csv(tmp_path / "frames.csv", index=False)
    with pytest.raises(RecordingError, match="row 2 is not a finite number"):
        read_recording(tmp_path)
    frames.loc[2, "t_s"] = 0.0
    frames.to_csv(tmp_path / "frames.csv", index=False)
    with pytest.raises(RecordingError, match="decrease at row 2"):
        read_recording(tmp_path)
    frames.loc[2, "t_s"] = 0.1
    frames.to_csv(tmp_path / "frames.csv", index=False)
    np.save(tmp_path / "lut_x.npy", np.zeros((512, 512)))
    np.save(tmp_path / "lut_y.npy", np.zeros((512, 512)))
    with pytest.raises(RecordingError, match="all zero"):
        read_recording(tmp_path)
    (tmp_path / "frames.csv").unlink()
    with pytest.raises(RecordingError, match="frames.csv is missing"):
        read_recording(tmp_path)


def test_a_missing_frame_file_is_refused_before_tracking_and_an_undecodable_one_is_a_flagged_row(tmp_path):
    _write(tmp_path)
    (tmp_path / "ir" / "000002.png").write_bytes(b"not a png")  # present but truncated / corrupt
    write_manifest(tmp_path)
    with pytest.warns(RuntimeWarning, match="cannot decode ir/000002.png"):
        table = track_recording(read_recording(tmp_path), {"tool": GEOMETRY}, PARAMS)
    assert list(table.flag) == ["initialized", "ok", "bad_frame", "ok"] and table.n_points.iloc[2] == 0
    (tmp_path / "depth" / "000001.png").unlink()
    write_manifest(tmp_path)
    with pytest.raises(RecordingError, match="1 frame file.* missing, e.g. 'depth/000001.png'"):
        read_recording(tmp_path)


def test_a_gyro_rate_that_is_not_a_number_is_refused_naming_its_row(tmp_path):
    _write(tmp_path)
    pd.DataFrame({"t_s": [0.01, 0.02], "wx": [0.1, "0.2 rad/s"], "wy": [0.0, 0.0], "wz": [0.0, 0.0]}).to_csv(tmp_path / "gyro.csv", index=False)
    with pytest.raises(RecordingError, match="wx of row 1 is not a number"):
        read_recording(tmp_path)


def test_npy_frames_replay_as_the_png_frames_and_an_unknown_format_is_refused(tmp_path):
    camera = PARAMS.camera
    lut = unit_plane_lut(intrinsics(camera), camera.width, camera.height)
    rng = np.random.default_rng(0)
    frames = [render_frame(GEOMETRY + [0.01 * k, 0.0, 0.45], [], camera, PARAMS.frames, MARKER_DIAMETER_M / 2, rng) for k in range(3)]
    tables = []
    for frame_format in ("png", "npy"):
        with RecordingWriter(tmp_path / frame_format, lut, frame_format=frame_format) as writer:
            for k, (ir, depth) in enumerate(frames):
                writer.add_frame(0.046 * k, ir, depth)
            writer.close()
        assert len(list((tmp_path / frame_format / "ir").glob(f"*.{frame_format}"))) == 3
        tables.append(track_recording(read_recording(tmp_path / frame_format), {"tool": GEOMETRY}, PARAMS))
    pd.testing.assert_frame_equal(tables[0], tables[1])
    with pytest.raises(PoseIntegrityError, match="frame_format: expected 'png' or 'npy', got 'jpg'"):
        RecordingWriter(tmp_path / "jpg", lut, frame_format="jpg")
