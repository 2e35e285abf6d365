import numpy as np
import pandas as pd
import pytest

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.tracking.filter.recording_replay import track_recording
from poseintegrity.tracking.io.recording import RecordingError, RecordingWriter, read_recording, write_manifest
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M
from poseintegrity.tracking.simulation.frames import intrinsics, render_frame, unit_plane_lut

from tracking.recording_folders import record
from tracking.track_section import GEOMETRY
from tracking.track_section import TINY as PARAMS


def test_bad_recordings_are_refused_naming_the_problem(tmp_path):
    record(tmp_path)
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


def test_a_missing_frame_file_is_refused_before_tracking(tmp_path):
    record(tmp_path)
    (tmp_path / "depth" / "000001.png").unlink()
    write_manifest(tmp_path)
    with pytest.raises(RecordingError, match="1 frame file.* missing, e.g. 'depth/000001.png'"):
        read_recording(tmp_path)


def test_a_gyro_rate_that_is_not_a_number_is_refused_naming_its_row(tmp_path):
    record(tmp_path)
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


def test_writing_over_a_recording_needs_overwrite_and_replaces_it_whole(tmp_path):
    folder = record(tmp_path / "rec", n=5)
    with pytest.raises(RecordingError, match="rec: the folder is not empty; pass overwrite=True"):
        record(folder, n=2)
    assert len(read_recording(folder).frames) == 5  # the refused writer left it alone
    record(folder, n=2, overwrite=True, seed=1)
    assert len(read_recording(folder).frames) == 2 and sorted(p.name for p in (folder / "ir").iterdir()) == ["000000.png", "000001.png"]
    assert [p.name for p in tmp_path.iterdir()] == ["rec"]  # no staging or old folder left behind


def test_a_folder_mixing_recordings_or_without_manifest_is_refused(tmp_path):
    folder = record(tmp_path / "rec", n=3)
    other = record(tmp_path / "other", n=3, seed=5)
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
    folder = record(tmp_path / "rec", n=2)
    (folder / name).write_bytes(content)
    write_manifest(folder)
    with pytest.raises(RecordingError, match=message):
        read_recording(folder)


def test_bad_lookup_tables_and_timestamps_are_refused(tmp_path):
    folder = record(tmp_path / "rec", n=3)
    lut_x = np.load(folder / "lut_x.npy")
    np.save(folder / "lut_x.npy", np.where(np.eye(*lut_x.shape) > 0, np.nan, lut_x))
    with pytest.raises(RecordingError, match="lookup table has .* non-finite entries, e.g. lut_x.npy at pixel"):
        read_recording(folder)
    np.save(folder / "lut_x.npy", lut_x[:10, :10])
    np.save(folder / "lut_y.npy", np.load(folder / "lut_y.npy")[:10, :10])
    with pytest.raises(RecordingError, match="the lookup table is 10 x 10"):
        read_recording(folder)
    folder = record(tmp_path / "rec2", n=3)
    frames = pd.read_csv(folder / "frames.csv")
    for times, message in [([0.0, 0.0, 0.1], "repeat at row 1"), ([0.0, 0.1, 1e300], "row 2 is not a finite number of seconds")]:
        frames.assign(t_s=times).to_csv(folder / "frames.csv", index=False)
        with pytest.raises(RecordingError, match=f"frames.csv: .*{message}"):
            read_recording(folder)
    with pytest.raises(RecordingError, match="nope: the recording folder does not exist"):
        read_recording(tmp_path / "nope")
