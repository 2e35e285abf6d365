"""Recorded frames as input: a folder written by a HoloLens 2 recorder (or by :class:`RecordingWriter` from our
simulation) is read and run through detection (II-B) -> correspondence (II-D) -> Kabsch (Alg. 4) -> SR-UKF
(Alg. 5), giving a pose table.

Folder layout:
- ``frames.csv``: one row per marker frame, columns ``t_s`` (seconds, finite, increasing), ``ir`` and ``depth``
  (file names relative to the folder);
- the frames: IR (raw reflectivity) and depth (millimetres along the ray), each (H, W), as 16-bit PNG or
  ``.npy`` (uint8/uint16/float);
- ``lut_x.npy`` and ``lut_y.npy``: the depth camera's per-pixel unit-plane lookup table as two (H, W) arrays
  (Research Mode's MapImagePointToCameraUnitPlane: pixel (u, v) -> (x, y) on z = 1);
- optional ``gyro.csv``: columns ``t_s, wx, wy, wz`` (rad/s, body frame of the tool carrying the gyro).
Points are expressed in the camera frame (T_world_cam = identity).

Usage, e.g. on a HoloLens 2 recording with the probe of the paper::

    from poseintegrity.config import load_section
    from poseintegrity.tracking import read_recording, read_tools, track_recording

    params = load_section("params.yaml", "track")
    tools = {"probe": np.array(params.markers_body)}  # or read_tools("tools.json", params.matching.distinct_m)
    poses = track_recording(read_recording("my_recording"), tools, params, gyro_tool="probe")
    poses.to_csv("poses.csv", index=False)

Bad input: a missing file (frames.csv, a frame it lists, the lookup table), a non-finite or decreasing
timestamp, a gyro rate that is not a number, or an all-zero lookup table raises :class:`RecordingError` naming
it when the recording is read, before any frame is tracked; a frame file that cannot be decoded, or a frame of
the wrong shape, dtype or units (depth in metres) gives a row flagged ``bad_frame`` and a RuntimeWarning naming
the file and the reason; no NaN point is ever produced.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.tracking.detection import detect_markers, validate_frame
from poseintegrity.tracking.params import TrackParams
from poseintegrity.tracking.tools import MultiToolTracker


class RecordingError(PoseIntegrityError):
    """A recording folder that cannot be replayed as a whole."""


@dataclass(frozen=True)
class Recording:
    """A recording folder, read and checked.  frames : table of frames.csv; lut : (H, W, 2); gyro : table or None."""

    folder: Path
    frames: pd.DataFrame
    lut: np.ndarray
    gyro: pd.DataFrame | None


def _read_table(path: Path, columns: list[str], numeric: tuple[str, ...] = ()) -> pd.DataFrame:
    """The csv at path with its columns checked: t_s finite and non-decreasing, the ``numeric`` columns numbers
    (NaN allowed: a non-finite gyro sample is flagged by the tracker)."""
    if not path.exists():
        raise RecordingError(f"{path} is missing")
    table = pd.read_csv(path)
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise RecordingError(f"{path} lacks the columns {missing}")
    for column in numeric:
        values = pd.to_numeric(table[column], errors="coerce")
        text = np.flatnonzero(values.isna() & table[column].notna())
        if text.size:
            raise RecordingError(f"{path}: {column} of row {text[0]} is not a number ({table[column].iloc[text[0]]!r})")
        table[column] = values
    t = pd.to_numeric(table["t_s"], errors="coerce").to_numpy(float)
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise RecordingError(f"{path}: timestamp t_s of row {bad[0]} is not a finite number ({table['t_s'].iloc[bad[0]]!r})")
    back = np.flatnonzero(np.diff(t) < 0)
    if back.size:
        raise RecordingError(f"{path}: timestamps decrease at row {back[0] + 1} ({t[back[0]]} -> {t[back[0] + 1]})")
    return table.assign(t_s=t)


def read_recording(folder: str | Path) -> Recording:
    """Read and check frames.csv, the lookup table and gyro.csv (if present) of a recording folder."""
    folder = Path(folder)
    frames = _read_table(folder / "frames.csv", ["t_s", "ir", "depth"])
    absent = [name for name in [*frames.ir, *frames.depth] if not (folder / str(name)).is_file()]
    if absent:
        raise RecordingError(f"{folder}: {len(absent)} frame file(s) listed in frames.csv are missing, e.g. {absent[0]!r}")
    try:
        lut = np.stack([np.load(folder / "lut_x.npy"), np.load(folder / "lut_y.npy")], axis=-1).astype(float)
    except (OSError, ValueError) as error:
        raise RecordingError(f"{folder}: cannot read the unit-plane lookup table lut_x.npy / lut_y.npy ({error})") from None
    if lut.ndim != 3:
        raise RecordingError(f"{folder}: lut_x.npy and lut_y.npy must be (H, W) arrays, got {lut.shape[:-1]}")
    if not np.all(np.isfinite(lut)) or not np.any(lut):
        raise RecordingError(f"{folder}: the unit-plane lookup table is all zero or not finite; it cannot unproject pixels")
    gyro = _read_table(folder / "gyro.csv", ["t_s", "wx", "wy", "wz"], ("wx", "wy", "wz")) if (folder / "gyro.csv").exists() else None
    return Recording(folder, frames, lut, gyro)


def load_image(path: Path) -> np.ndarray | None:
    """One frame array from a 16-bit (or 8-bit) PNG or a .npy file, unchanged; None if the file cannot be
    decoded (a truncated or corrupt file: :func:`track_recording` flags its frame ``bad_frame``)."""
    if path.suffix.lower() == ".npy":
        try:
            return np.load(path)
        except (OSError, ValueError):
            return None
    return cv2.imread(str(path), cv2.IMREAD_UNCHANGED)


def frame_problem(recording: Recording, k: int) -> tuple[str, np.ndarray, np.ndarray]:
    """(why frame k cannot be used or "", ir, depth_mm) of a recording, reading its two files."""
    row = recording.frames.iloc[k]
    ir, depth = load_image(recording.folder / row.ir), load_image(recording.folder / row.depth)
    unreadable = [name for name, image in ((row.ir, ir), (row.depth, depth)) if image is None]
    if unreadable:
        return f"cannot decode {', '.join(map(str, unreadable))}", np.zeros((0, 0)), np.zeros((0, 0))
    return validate_frame(ir, depth, recording.lut), ir, depth


class RecordingWriter:
    """Writes a recording folder (16-bit PNG frames) that :func:`read_recording` reads."""

    def __init__(self, folder: str | Path, lut: np.ndarray):
        self.folder = Path(folder)
        (self.folder / "ir").mkdir(parents=True, exist_ok=True)
        (self.folder / "depth").mkdir(parents=True, exist_ok=True)
        np.save(self.folder / "lut_x.npy", lut[..., 0])
        np.save(self.folder / "lut_y.npy", lut[..., 1])
        self.rows: list[dict] = []

    def add_frame(self, t: float, ir: np.ndarray, depth_mm: np.ndarray) -> None:
        """ir, depth_mm : (H, W) uint16."""
        name = f"{len(self.rows):06d}.png"
        cv2.imwrite(str(self.folder / "ir" / name), ir)
        cv2.imwrite(str(self.folder / "depth" / name), depth_mm)
        self.rows.append({"t_s": t, "ir": f"ir/{name}", "depth": f"depth/{name}"})

    def close(self, gyro_t: np.ndarray | None = None, gyro: np.ndarray | None = None) -> None:
        """Write frames.csv and, if given, gyro.csv (times (G,) s, rates (G, 3) rad/s)."""
        pd.DataFrame(self.rows).to_csv(self.folder / "frames.csv", index=False, float_format="%.17g")
        if gyro_t is not None:
            table = pd.DataFrame({"t_s": gyro_t, "wx": gyro[:, 0], "wy": gyro[:, 1], "wz": gyro[:, 2]})
            table.to_csv(self.folder / "gyro.csv", index=False, float_format="%.17g")


def track_recording(recording: Recording, tools: dict[str, np.ndarray], params: TrackParams, gyro_tool: str | None = None) -> pd.DataFrame:
    """Pose table of a recording: one row per frame and tool, in time order.

    Columns: t_s, frame, tool, flag, n_points, n_matched, x_mm / y_mm / z_mm and qx / qy / qz / qw (filtered
    T_world_body, NaN while the filter is not running).  Gyro samples are fused by gyro_tool's filter between
    the frames (events in time order; a gyro sample at the time of a frame comes after it).
    """
    tracker = MultiToolTracker(tools, params.filter, params.matching, gyro_tool if recording.gyro is not None else None)
    events = [(t, 0, k) for k, t in enumerate(recording.frames.t_s)]
    if recording.gyro is not None:
        events += [(t, 1, k) for k, t in enumerate(recording.gyro.t_s)]
    rows, warned = [], set()
    gyro = recording.gyro[["wx", "wy", "wz"]].to_numpy(float) if recording.gyro is not None else None
    for t, is_gyro, k in sorted(events):
        if is_gyro:
            tracker.gyro(t, gyro[k])
            continue
        reason, ir, depth = frame_problem(recording, k)
        if reason:
            if reason not in warned:
                warnings.warn(f"{recording.folder / recording.frames.ir.iloc[k]}: {reason} (frame flagged bad_frame)", RuntimeWarning, stacklevel=2)
                warned.add(reason)
            results = {name: None for name in tools}
            points = np.zeros((0, 3))
        else:
            points = detect_markers(ir, depth, recording.lut, params.detection)
            results = tracker.frame(t, points)
        for name, result in results.items():
            T = result.T_filtered if result is not None else tracker.trackers[name].pose()
            ok = np.isfinite(T).all()
            q = Rotation.from_matrix(T[:3, :3]).as_quat() if ok else np.full(4, np.nan)
            rows.append({
                "t_s": t, "frame": k, "tool": name, "flag": result.flag if result is not None else "bad_frame",
                "n_points": len(points), "n_matched": int((result.assignment >= 0).sum()) if result is not None else 0,
                "x_mm": T[0, 3] * 1000.0, "y_mm": T[1, 3] * 1000.0, "z_mm": T[2, 3] * 1000.0,
                "qx": q[0], "qy": q[1], "qz": q[2], "qw": q[3],
            })
    return pd.DataFrame(rows)
