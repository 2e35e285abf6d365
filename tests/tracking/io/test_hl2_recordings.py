"""HoloLens 2 AHAT recordings (StreamRecorder, hl2ss) written by independent test writers from simulated frames,
converted, and replayed: the poses must equal those of the same frames written by RecordingWriter; bad files are
refused naming the file and field, leaving nothing behind."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity.tracking.filter.recording_replay import track_recording
from poseintegrity.tracking.io.hl2_recordings import convert_hl2ss, convert_stream_recorder, decode_pgm
from poseintegrity.tracking.io.recording import RecordingError, RecordingWriter, read_recording

from tracking.hl2_writers import T0_TICKS, pgm, simulated_frames, write_hl2ss, write_stream_recorder
from tracking.track_section import TINY as PARAMS

N_FRAMES = 8


@pytest.fixture(scope="module")
def recorded():
    lut, frames = simulated_frames(PARAMS, N_FRAMES)
    return lut, frames


def _rigid(seed):
    rng = np.random.default_rng(seed)
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rng.normal(0, 0.5, 3)).as_matrix()
    T[:3, 3] = rng.normal(0, 0.3, 3)
    return T


def _track(folder):
    return track_recording(read_recording(folder), {"tool": np.array(PARAMS.markers_body)}, PARAMS)


@pytest.fixture(scope="module")
def reference(recorded, tmp_path_factory):
    """The same frames through RecordingWriter (times from the same ticks), tracked."""
    lut, frames = recorded
    folder = tmp_path_factory.mktemp("own") / "rec"
    with RecordingWriter(folder, lut) as writer:
        for ticks, ir, depth in frames:
            writer.add_frame((ticks - frames[0][0]) / 1e7, ir, depth)  # seconds since the first frame
        writer.close()
    return _track(folder)


def _same_poses(table, reference):
    assert list(table.flag) == list(reference.flag) and (reference.flag == "ok").sum() >= N_FRAMES - 2
    assert np.allclose(table.t_s, reference.t_s, rtol=0, atol=1e-12)
    diff = np.abs(table[["x_mm", "y_mm", "z_mm"]].to_numpy() - reference[["x_mm", "y_mm", "z_mm"]].to_numpy())
    assert np.nanmax(diff) < 1e-3  # the float32 lookup tables of the recorders: ~1e-4 mm
    assert np.allclose(table[["qx", "qy", "qz", "qw"]], reference[["qx", "qy", "qz", "qw"]], atol=1e-6, equal_nan=True)


@pytest.mark.parametrize("tar", [False, True], ids=["folder", "tar"])
def test_a_stream_recorder_capture_replays_as_the_same_frames_in_our_layout(recorded, reference, tmp_path, tar):
    lut, frames = recorded
    rig_to_cam, rig_to_world = _rigid(1), [_rigid(10 + k) for k in range(N_FRAMES)]
    capture = write_stream_recorder(tmp_path / "capture", lut, frames, tar, rig_to_cam, rig_to_world)
    folder = convert_stream_recorder(capture, tmp_path / "converted")
    _same_poses(_track(folder), reference)
    poses = __import__("pandas").read_csv(folder / "camera_poses.csv")
    assert list(poses.ticks) == [f[0] for f in frames] and poses.has_pose.all()
    T = poses[[f"T{i}{j}" for i in range(4) for j in range(4)]].to_numpy().reshape(-1, 4, 4)
    assert np.allclose(T, [W @ np.linalg.inv(rig_to_cam) for W in rig_to_world], atol=1e-6)


@pytest.mark.parametrize("scale", [1000.0, 4000.0])
def test_an_hl2ss_recording_replays_as_the_same_frames_in_our_layout(recorded, reference, tmp_path, scale):
    lut, frames = recorded
    rig_to_cam, rig_to_world = _rigid(2), [_rigid(20 + k) for k in range(N_FRAMES)]
    path = write_hl2ss(tmp_path / "rm_depth_ahat.bin", tmp_path / "calibration", lut, frames, rig_to_cam, rig_to_world, scale)
    folder = convert_hl2ss(path, tmp_path / "calibration", tmp_path / "converted")
    _same_poses(_track(folder), reference)
    poses = __import__("pandas").read_csv(folder / "camera_poses.csv")
    T = poses[[f"T{i}{j}" for i in range(4) for j in range(4)]].to_numpy().reshape(-1, 4, 4)
    assert np.allclose(T, [W @ np.linalg.inv(rig_to_cam) for W in rig_to_world], atol=1e-5)  # float32 poses


def test_pgm_decoding_matches_the_big_endian_words_and_refuses_a_truncated_frame():
    image = np.array([[1, 256, 65535], [4090, 0, 513]], np.uint16)
    assert np.array_equal(decode_pgm(pgm(image), "f.pgm"), image)
    assert np.array_equal(decode_pgm(b"P5\n# comment\n3 2\n65535\n" + image.astype(">u2").tobytes(), "c.pgm"), image)
    with pytest.raises(RecordingError, match=r"t\.pgm: PGM pixel data is 11 bytes.*announces 12"):
        decode_pgm(pgm(image)[:-1], "t.pgm")
    with pytest.raises(RecordingError, match=r"e\.pgm: the PGM file is empty"):
        decode_pgm(b"", "e.pgm")
    with pytest.raises(RecordingError, match="not a binary PGM"):
        decode_pgm(b"P2\n3 2\n65535\n1 2 3 4 5 6", "a.pgm")


def _capture(tmp_path, recorded, **kwargs):
    lut, frames = recorded
    return write_stream_recorder(tmp_path / "capture", lut, frames[:4], **kwargs)


def _hl2ss(tmp_path, recorded, **kwargs):
    lut, frames = recorded
    return write_hl2ss(tmp_path / "rm_depth_ahat.bin", tmp_path / "calibration", lut, frames[:4], **kwargs)


def _break_lut(value):
    def breaks(capture):
        rays = np.fromfile(capture / "Depth AHaT_lut.bin", "<f4").reshape(512, 512, 3)
        rays[2, 3] = value
        rays.tofile(capture / "Depth AHaT_lut.bin")
    return breaks


def _frame(capture, k, suffix=".pgm"):
    return sorted((capture / "Depth AHaT").glob(f"*[0-9]{suffix}"))[k]


STREAM_RECORDER_BREAKS = {
    "lut_nan": (_break_lut(np.nan), r"Depth AHaT_lut\.bin: the lookup table has 1 non-finite pixel\(s\), e\.g\. \(u 3, v 2\)"),
    "lut_unmapped": (_break_lut([0.1, 0.2, 0.0]), r"Depth AHaT_lut\.bin: 1 pixel\(s\) of the lookup table have no ray"),
    "lut_other_camera": (lambda c: (c / "Depth AHaT_lut.bin").write_bytes(np.zeros(256 * 256 * 3, "<f4").tobytes()),
                         r"Depth AHaT_lut\.bin: the lookup table is 786432 bytes; frames of 512 x 512 px need 3145728"),
    "lut_missing": (lambda c: (c / "Depth AHaT_lut.bin").unlink(), r"Depth AHaT_lut\.bin: cannot read the lookup table"),
    "frame_other_size": (lambda c: _frame(c, 2).write_bytes(pgm(np.zeros((256, 512), np.uint16))),
                         r"\.pgm: the frame is 512 x 256 px, the lookup table 512 x 512"),
    "pgm_zero_bytes": (lambda c: _frame(c, 1).write_bytes(b""), r"Depth AHaT/\d+\.pgm: the PGM file is empty"),
    "pgm_truncated": (lambda c: _frame(c, 3, "_ab.pgm").write_bytes(_frame(c, 3, "_ab.pgm").read_bytes()[:-100]),
                      r"\d+_ab\.pgm: PGM pixel data is 524188 bytes"),
    "ab_missing": (lambda c: _frame(c, 2, "_ab.pgm").unlink(), r"Depth AHaT: 1 frame\(s\) lack their _ab\.pgm file"),
    "rig2world_not_increasing": (lambda c: (c / "Depth AHaT_rig2world.txt").write_text(
        "\n".join(reversed((c / "Depth AHaT_rig2world.txt").read_text().splitlines()))),
        r"rig2world\.txt: the timestamps \(first column\) must increase; they do not at row 1"),
    "rig2world_short_row": (lambda c: (c / "Depth AHaT_rig2world.txt").write_text("123,1,0,0\n"),
                            r"rig2world\.txt: row 0 of the rig2world poses must be 17"),
    "extrinsics_not_rigid": (lambda c: (c / "Depth AHaT_extrinsics.txt").write_text(",".join(["2"] * 16)),
                             r"extrinsics\.txt: extrinsics is not a rigid transform"),
}


@pytest.mark.parametrize("case", list(STREAM_RECORDER_BREAKS))
def test_a_bad_stream_recorder_capture_is_refused_naming_file_and_field_and_nothing_is_written(recorded, tmp_path, case):
    capture = _capture(tmp_path, recorded, rig_to_cam=_rigid(1), rig_to_world=[_rigid(k) for k in range(4)])
    breaks, message = STREAM_RECORDER_BREAKS[case]
    breaks(capture)
    with pytest.raises(RecordingError, match=message):
        convert_stream_recorder(capture, tmp_path / "out" / "converted")
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())  # not even a staging folder


def test_a_truncated_stream_recorder_tarball_is_refused(recorded, tmp_path):
    capture = _capture(tmp_path, recorded, tar=True)
    data = (capture / "Depth AHaT.tar").read_bytes()
    (capture / "Depth AHaT.tar").write_bytes(data[: len(data) // 2])
    with pytest.raises(RecordingError, match=r"Depth AHaT\.tar: cannot read"):
        convert_stream_recorder(capture, tmp_path / "out" / "converted")
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def _rewrite(offset_from_end=None, at=None, value=None):
    def breaks(path):
        data = bytearray(path.read_bytes())
        if offset_from_end is not None:
            data = data[:-offset_from_end]
        if at is not None:
            data[at:at + len(value)] = value
        path.write_bytes(bytes(data))
    return breaks


PACKET = 12 + 8 + 4 * 512 * 512 + 8  # header, prefix, depth + AB, sensor ticks (mode 0)
CONFIG_END = 14 + 4 + 10 + 16  # header with 4 bytes of user data, configuration with one option
HL2SS_BREAKS = {
    "zero_bytes": (_rewrite(offset_from_end=0, at=0, value=b""), None, r"rm_depth_ahat\.bin: the hl2ss recording is empty"),
    "truncated_packet": (_rewrite(offset_from_end=1000), None, r"rm_depth_ahat\.bin: packet 3 is truncated"),
    "truncated_header": (_rewrite(offset_from_end=2 * PACKET + PACKET - 6), None, r"ends inside the header of packet 1"),
    "other_version": (_rewrite(at=0, value=b"HL2SSV22"), None, r"header magic is b'HL2SSV22'"),
    "other_port": (_rewrite(at=8, value=(3805).to_bytes(2, "little")), None, r"header port is 3805"),
    "compressed": (lambda p: None, {"profile_ab": 1}, r"profile_z 0, profile_ab 1: the frames are compressed"),
    "not_increasing": (_rewrite(at=CONFIG_END + 2 * PACKET, value=(T0_TICKS).to_bytes(8, "little")), None,
                       r"rm_depth_ahat\.bin: packet timestamps must increase; packet 2 has"),
    "uv2xy_nan": (lambda p: _calibration(p, "uv2xy.bin", lambda a: a.__setitem__(5, np.nan)), None,
                  r"uv2xy\.bin: the lookup table has 1 non-finite pixel\(s\), e\.g\. \(u 2, v 0\)"),
    "uv2xy_unmapped": (lambda p: _calibration(p, "uv2xy.bin", lambda a: a.__setitem__(slice(10, 12), 0.0)), None,
                       r"uv2xy\.bin: 1 pixel\(s\) of the lookup table have no ray .*\(u 5, v 0\)"),
    "uv2xy_truncated": (lambda p: _calibration(p, "uv2xy.bin", lambda a: None, cut=8), None, r"uv2xy\.bin: 2097144 bytes, expected 2097152"),
    "scale_zero": (lambda p: _calibration(p, "scale.bin", lambda a: a.__setitem__(0, 0.0)), None, r"scale\.bin: the depth scale must be"),
}


def _calibration(path, name, change, cut=0):
    file = path.parent / "calibration" / "rm_depth_ahat" / name
    array = np.fromfile(file, "<f4")
    change(array)
    file.write_bytes(array.tobytes()[: len(array) * 4 - cut])


@pytest.mark.parametrize("case", list(HL2SS_BREAKS))
def test_a_bad_hl2ss_recording_is_refused_naming_file_and_field_and_nothing_is_written(recorded, tmp_path, case):
    breaks, kwargs, message = HL2SS_BREAKS[case]
    path = _hl2ss(tmp_path, recorded, **(kwargs or {}))
    breaks(path)
    with pytest.raises(RecordingError, match=message):
        convert_hl2ss(path, tmp_path / "calibration", tmp_path / "out" / "converted")
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
