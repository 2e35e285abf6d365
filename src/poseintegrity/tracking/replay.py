"""Replay a recording from the command line: detection (II-B), correspondence (II-D), Kabsch (Alg. 4) and the
SR-UKF (Alg. 5) of every tool of a tool file, frame by frame, into a pose table.

    python -m poseintegrity.tracking.replay RECORDING --tools tools.json [--gyro-tool NAME]
        [--format auto|folder|stream-recorder|hl2ss] [--calibration DIR] [--out poses.csv|poses.parquet]
        [--overwrite] [--params my.yaml]

RECORDING is a recording folder of our layout (``--format folder``), a StreamRecorder capture folder
(``stream-recorder``) or an hl2ss ``rm_depth_ahat.bin`` (``hl2ss``, with ``--calibration``, hl2ss's calibration
folder). The default, ``auto``, finds the layout from what RECORDING holds (:func:`detect_format`); a ``--format``
that does not fit what is there is refused naming the one that does. The last two are converted into a temporary
recording folder first,
beside the output and deleted afterwards (:mod:`~poseintegrity.tracking.io.hl2_recordings`, about 1 MB per frame;
convert once with its functions to replay a recording often).
The table (one row per frame and tool: t_s, frame, tool, flag, n_points, n_matched, x/y/z_mm, qx..qw, in the
camera frame; :func:`~poseintegrity.tracking.filter.recording_replay.track_recording`) is written to ``--out`` through a
temporary file and a rename; a progress bar runs on stderr and a summary per tool is printed: tracked (flag ok or
initialized), gated (the innovation gate refused the match), lost (no_points, no_markers, stale, restart,
diverged) and bad_frame (an undecodable frame).  ``--params``: a params file whose ``track`` section is used
(default: the published params.yaml).

``--out`` is checked before any work: a folder, a missing parent folder or an existing file (without
``--overwrite``) is refused naming it.

Bad input (a missing or bad recording, tool file, params file, gyro tool or output name): one line
``file: what is wrong`` on stderr, exit status 2, no traceback, and no output file.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import pandas as pd
from tqdm import tqdm

from poseintegrity.atomic_write import check_new_file
from poseintegrity.config import load_section
from poseintegrity.config import published
from poseintegrity.errors import PoseIntegrityError
from poseintegrity.stage_timing import usage_error
from poseintegrity.tracking.filter.recording_replay import track_recording
from poseintegrity.tracking.io.hl2_recordings import HL2SS_MAGIC, STREAM_RECORDER_SENSOR, convert_hl2ss, convert_stream_recorder
from poseintegrity.tracking.io.recording import RecordingError, read_recording
from poseintegrity.tracking.io.tool_files import read_tools

FORMATS = ("folder", "stream-recorder", "hl2ss")
LAYOUTS = {"folder": "a recording folder of ours (frames.csv)",
           "stream-recorder": f"a StreamRecorder capture folder ({STREAM_RECORDER_SENSOR}/, {STREAM_RECORDER_SENSOR}.tar "
                              f"or {STREAM_RECORDER_SENSOR}_lut.bin)",
           "hl2ss": f"an hl2ss recording file (it starts with {HL2SS_MAGIC.decode()})"}  # what each format holds
SUMMARY_GROUPS = {"tracked": ("ok", "initialized"), "gated": ("gated",), "bad_frame": ("bad_frame",)}  # the rest: lost


def detect_format(recording: Path) -> str | None:
    """The format whose layout ``recording`` has (:data:`LAYOUTS`), or None: a file starting with hl2ss's magic is
    ``hl2ss``; a folder with ``frames.csv`` ``folder``; a folder with StreamRecorder's AHAT frames or lookup table
    ``stream-recorder``."""
    if recording.is_file():
        with open(recording, "rb") as file:
            return "hl2ss" if file.read(len(HL2SS_MAGIC)) == HL2SS_MAGIC else None
    if (recording / "frames.csv").is_file():
        return "folder"
    sensor = recording / STREAM_RECORDER_SENSOR
    if sensor.is_dir() or sensor.with_name(f"{sensor.name}.tar").is_file() or \
            sensor.with_name(f"{sensor.name}_lut.bin").is_file():
        return "stream-recorder"
    return None


def choose_format(recording: Path, given: str) -> str:
    """The format to read ``recording`` with: ``given``, or the detected one for ``auto``; :class:`RecordingError`
    when nothing fits ``auto`` or ``given`` is not the layout that is there (naming the ``--format`` that fits)."""
    if not recording.exists():
        raise RecordingError(f"{recording}: no such recording (file or folder)")
    detected = detect_format(recording)
    if given == "auto" and detected is None:
        raise RecordingError(f"{recording}: not a recording this command reads: neither "
                             f"{', nor '.join(LAYOUTS.values())}")
    if given not in ("auto", detected) and detected is not None:
        raise RecordingError(f"{recording}: is {LAYOUTS[detected]}, not {LAYOUTS[given]}: use --format {detected} "
                             f"(or leave --format out)")
    return detected if given == "auto" else given


def replay_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per tool (rows, in table order): frames tracked, gated, lost and bad_frame (columns) of a pose table."""
    group = table.flag.map({flag: name for name, flags in SUMMARY_GROUPS.items() for flag in flags}).fillna("lost")
    counts = pd.crosstab(pd.Categorical(table.tool, categories=table.tool.unique()), group)
    return counts.reindex(columns=["tracked", "gated", "lost", "bad_frame"], fill_value=0).rename_axis(index="tool", columns=None)


def write_table(table: pd.DataFrame, out: Path) -> None:
    """``table`` to ``out`` (.csv or .parquet) through a temporary sibling file and a rename."""
    tmp = out.with_name(f".{out.name}.writing-{os.getpid()}")
    try:
        if out.suffix == ".parquet":
            table.to_parquet(tmp, index=False)
        else:
            table.to_csv(tmp, index=False, float_format="%.9g")
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)


def _replay(args: argparse.Namespace, workdir: Path) -> pd.DataFrame:
    params = published("track") if args.params is None else load_section(args.params, "track")
    tools = read_tools(args.tools, params.matching.distinct_m)
    folder = args.recording
    if args.format == "stream-recorder":
        folder = convert_stream_recorder(args.recording, workdir / "converted")
    elif args.format == "hl2ss":
        folder = convert_hl2ss(args.recording, args.calibration, workdir / "converted")
    recording = read_recording(folder)
    with tqdm(total=len(recording.frames), desc="replay", unit="frame", file=sys.stderr, disable=None) as bar:
        table = track_recording(recording, tools, params, args.gyro_tool, progress=bar.update)  # checks gyro_tool first
    if args.gyro_tool is not None and recording.gyro is None:
        print(f"{args.recording}: no gyro.csv, so --gyro-tool {args.gyro_tool} fused nothing (tracked without gyro)", file=sys.stderr)
    return table


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording", type=Path, help="recording folder, StreamRecorder capture folder or hl2ss rm_depth_ahat.bin")
    parser.add_argument("--tools", type=Path, required=True, help="tool file (JSON or CSV, metres)")
    parser.add_argument("--gyro-tool", help="the tool carrying the gyro of gyro.csv")
    parser.add_argument("--format", choices=("auto", *FORMATS), default="auto",
                        help="the recording's layout (default: found from what RECORDING holds)")
    parser.add_argument("--calibration", type=Path, help="hl2ss: the calibration folder (holding rm_depth_ahat/)")
    parser.add_argument("--out", type=Path, default=Path("poses.csv"), help="pose table, .csv or .parquet")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing --out file")
    parser.add_argument("--params", type=Path, help="params file whose track section is used (default: the published one)")
    args = parser.parse_args(argv)
    if args.out.suffix not in (".csv", ".parquet"):
        sys.exit(usage_error(f"--out {args.out}: the output must end in .csv or .parquet"))
    try:  # before any work: the destination, then the recording's layout
        check_new_file(args.out, "--out", args.overwrite)
        args.format = choose_format(args.recording, args.format)
    except PoseIntegrityError as error:
        sys.exit(usage_error(str(error)))
    if args.format == "hl2ss" and args.calibration is None:
        sys.exit(usage_error(f"{args.recording}: an hl2ss recording needs --calibration (hl2ss's calibration folder)"))
    try:
        with tempfile.TemporaryDirectory(prefix=".replay-", dir=args.out.parent) as workdir:  # ~1 MB a frame: beside the output
            table = _replay(args, Path(workdir))
    except PoseIntegrityError as error:
        sys.exit(usage_error(" ".join(str(error).split())))  # one line
    write_table(table, args.out)
    summary = replay_summary(table)
    print(f"{table.frame.nunique()} frames, {table.t_s.max() - table.t_s.min():.2f} s; poses -> {args.out}")
    print(summary.to_string())


if __name__ == "__main__":
    main()
