"""python -m poseintegrity.tracking.replay: the pose table it writes is track_recording's on the same recording,
its summary counts the flags, and bad input is one line naming the file, exit status 2, no output file."""

import contextlib
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from poseintegrity.tracking.filter.recording_replay import track_recording
from poseintegrity.tracking.io.recording import RecordingWriter, read_recording
from poseintegrity.tracking.io.tool_files import write_tools
from poseintegrity.tracking.replay import main, replay_summary

from tracking.hl2_writers import simulated_frames, write_hl2ss, write_stream_recorder
from tracking.track_section import TINY as PARAMS

ROOT = Path(__file__).resolve().parents[2]
TINY_PARAMS = ROOT / "tests" / "params_tiny.yaml"
GEOMETRY = np.array(PARAMS.markers_body)


@pytest.fixture(scope="module")
def recorded():
    return simulated_frames(PARAMS, 6)


@pytest.fixture
def tools(tmp_path):
    write_tools(tmp_path / "tools.json", {"probe": GEOMETRY})
    return tmp_path / "tools.json"


def _run(argv):
    """(exit status, stdout, stderr) of main(argv) in this process."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main([str(a) for a in argv])
            status = 0
        except SystemExit as exit_:
            status = exit_.code
    return status, out.getvalue(), err.getvalue()


def _own_layout(folder, recorded):
    lut, frames = recorded
    with RecordingWriter(folder, lut) as writer:
        for ticks, ir, depth in frames:
            writer.add_frame((ticks - frames[0][0]) / 1e7, ir, depth)
        writer.close()
    return folder


def test_replay_writes_track_recordings_table_and_counts_its_flags(recorded, tools, tmp_path):
    folder = _own_layout(tmp_path / "rec", recorded)
    status, stdout, _ = _run([folder, "--tools", tools, "--out", tmp_path / "poses.parquet", "--params", TINY_PARAMS])
    assert status == 0
    table = pd.read_parquet(tmp_path / "poses.parquet")
    expected = track_recording(read_recording(folder), {"probe": GEOMETRY}, PARAMS)
    pd.testing.assert_frame_equal(table, expected)
    flags = expected.flag
    counts = [flags.isin(["ok", "initialized"]).sum(), (flags == "gated").sum(),
              (~flags.isin(["ok", "initialized", "gated", "bad_frame"])).sum(), (flags == "bad_frame").sum()]
    line = next(line for line in stdout.splitlines() if line.startswith("probe"))
    assert [int(v) for v in line.split()[1:]] == counts and sum(counts) == 6
    assert stdout.startswith("6 frames")
    assert not list(tmp_path.glob(".poses*"))  # the temporary file was renamed


def test_replay_summary_groups_the_flags():
    table = pd.DataFrame({"tool": ["b", "a", "b", "a", "b", "a", "b"],
                          "flag": ["initialized", "ok", "gated", "no_points", "bad_frame", "stale", "ok"]})
    summary = replay_summary(table)
    assert list(summary.index) == ["b", "a"]
    assert summary.loc["b"].to_dict() == {"tracked": 2, "gated": 1, "lost": 0, "bad_frame": 1}
    assert summary.loc["a"].to_dict() == {"tracked": 1, "gated": 0, "lost": 2, "bad_frame": 0}


def test_the_command_replays_a_stream_recorder_capture_as_the_same_frames_in_our_layout(recorded, tools, tmp_path):
    lut, frames = recorded
    capture = write_stream_recorder(tmp_path / "capture", lut, frames)
    folder = _own_layout(tmp_path / "rec", recorded)
    out = tmp_path / "poses.csv"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    result = subprocess.run([sys.executable, "-m", "poseintegrity.tracking.replay", str(capture), "--tools", str(tools),
                             "--format", "stream-recorder", "--out", str(out), "--params", str(TINY_PARAMS)],
                            capture_output=True, text=True, env=env, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "tracked" in result.stdout and "bad_frame" in result.stdout
    table, expected = pd.read_csv(out), track_recording(read_recording(folder), {"probe": GEOMETRY}, PARAMS)
    assert list(table.flag) == list(expected.flag)
    assert np.nanmax(np.abs(table[["x_mm", "y_mm", "z_mm"]].to_numpy() - expected[["x_mm", "y_mm", "z_mm"]].to_numpy())) < 1e-3


def test_an_hl2ss_recording_replays_with_its_calibration(recorded, tools, tmp_path):
    lut, frames = recorded
    path = write_hl2ss(tmp_path / "rm_depth_ahat.bin", tmp_path / "calibration", lut, frames)
    status, stdout, stderr = _run([path, "--calibration", tmp_path / "calibration", "--tools", tools,  # format found
                                   "--out", tmp_path / "poses.csv", "--params", TINY_PARAMS])
    assert status == 0, stderr
    assert (pd.read_csv(tmp_path / "poses.csv").flag == "ok").sum() >= 4


def _tool_file(tmp_path, markers):
    (tmp_path / "bad_tools.json").write_text(json.dumps({"tools": [{"name": "probe", "markers_body": markers}]}))
    return tmp_path / "bad_tools.json"


def _empty_hl2ss(tmp):
    lut, frames = simulated_frames(PARAMS, 1)
    write_hl2ss(tmp / "one.bin", tmp / "calibration", lut, frames)
    (tmp / "empty.bin").write_bytes(b"")
    return tmp / "empty.bin"


BAD = {
    "two_markers": lambda tmp, rec, tools: ([rec, "--tools", _tool_file(tmp, GEOMETRY[:2].tolist())], "bad_tools.json"),
    "duplicated_marker": lambda tmp, rec, tools: ([rec, "--tools", _tool_file(tmp, GEOMETRY[[0, 1, 2, 2]].tolist())], "bad_tools.json"),
    "no_recording": lambda tmp, rec, tools: ([tmp / "nothing", "--tools", tools], "nothing"),
    "gyro_tool_unknown": lambda tmp, rec, tools: ([rec, "--tools", tools, "--gyro-tool", "scalpel"], "scalpel"),
    "hl2ss_without_calibration": lambda tmp, rec, tools: ([rec, "--tools", tools, "--format", "hl2ss"], "rec"),
    "hl2ss_empty_bin": lambda tmp, rec, tools: ([_empty_hl2ss(tmp), "--tools", tools, "--format", "hl2ss",
                                                "--calibration", tmp / "calibration"], "empty.bin"),
    "out_suffix": lambda tmp, rec, tools: ([rec, "--tools", tools, "--out", tmp / "poses.txt"], "poses.txt"),
    "params_missing": lambda tmp, rec, tools: ([rec, "--tools", tools, "--params", tmp / "my.yaml"], "my.yaml"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_is_one_line_naming_the_file_exit_2_and_no_output(recorded, tools, tmp_path, case):
    folder = _own_layout(tmp_path / "rec", recorded)
    argv, name = BAD[case](tmp_path, folder, tools)
    out = tmp_path / "poses.csv"
    if "--out" not in argv:
        argv += ["--out", out]
    status, _, stderr = _run(argv + ["--params", TINY_PARAMS] if "--params" not in argv else argv)
    lines = stderr.strip().splitlines()
    assert status == 2 and len(lines) == 1 and name in lines[0] and "Traceback" not in stderr, stderr
    assert not out.exists() and not list(tmp_path.glob(".poses*"))


def test_a_gyro_tool_without_gyro_samples_is_said_and_tracks_without_gyro(recorded, tools, tmp_path):
    folder = _own_layout(tmp_path / "rec", recorded)
    status, _, stderr = _run([folder, "--tools", tools, "--gyro-tool", "probe", "--out", tmp_path / "poses.csv", "--params", TINY_PARAMS])
    assert status == 0 and "no gyro.csv, so --gyro-tool probe fused nothing" in stderr
    expected = track_recording(read_recording(folder), {"probe": GEOMETRY}, PARAMS)
    assert list(pd.read_csv(tmp_path / "poses.csv").flag) == list(expected.flag)


def test_the_layout_is_found_without_format_and_a_wrong_format_names_the_right_one(recorded, tools, tmp_path):
    lut, frames = recorded
    capture = write_stream_recorder(tmp_path / "capture", lut, frames)
    status, stdout, stderr = _run([capture, "--tools", tools, "--out", tmp_path / "poses.csv", "--params", TINY_PARAMS])
    assert status == 0, stderr
    expected = track_recording(read_recording(_own_layout(tmp_path / "rec", recorded)), {"probe": GEOMETRY}, PARAMS)
    assert list(pd.read_csv(tmp_path / "poses.csv").flag) == list(expected.flag)
    for given, fits, folder in (("folder", "stream-recorder", capture), ("stream-recorder", "folder", tmp_path / "rec")):
        status, _, stderr = _run([folder, "--tools", tools, "--format", given, "--out", tmp_path / "again.csv"])
        assert status == 2 and f"use --format {fits}" in stderr and not (tmp_path / "again.csv").exists()
    (tmp_path / "empty").mkdir()
    status, _, stderr = _run([tmp_path / "empty", "--tools", tools, "--out", tmp_path / "again.csv"])
    assert status == 2 and "not a recording this command reads" in stderr and "frames.csv" in stderr


def test_the_output_is_checked_before_any_work(recorded, tools, tmp_path, monkeypatch):
    folder = _own_layout(tmp_path / "rec", recorded)
    monkeypatch.setattr("poseintegrity.tracking.replay._replay", lambda *a: pytest.fail("replayed before the check"))
    (tmp_path / "poses.csv").write_text("the user's table")
    (tmp_path / "folder.csv").mkdir()
    for out, words in ((tmp_path / "folder.csv", "is a folder"), (tmp_path / "poses.csv", "the file exists"),
                       (tmp_path / "no" / "poses.csv", "does not exist")):
        status, _, stderr = _run([folder, "--tools", tools, "--out", out])
        assert status == 2 and f"--out {out}: " in stderr and words in stderr
    assert (tmp_path / "poses.csv").read_text() == "the user's table"
    monkeypatch.undo()
    status, _, _ = _run([folder, "--tools", tools, "--out", tmp_path / "poses.csv", "--overwrite",
                         "--params", TINY_PARAMS])
    assert status == 0 and pd.read_csv(tmp_path / "poses.csv").frame.nunique() == 6
