"""Recorded frames as input, the recording folder: converted from a HoloLens 2 recorder (:mod:`hl2_recordings`:
StreamRecorder, hl2ss) or written by :class:`RecordingWriter` from our simulation, read and checked by
:func:`read_recording`; :mod:`~poseintegrity.tracking.filter.recording_replay` runs it through the tracking into a
pose table.

Folder layout:
- ``frames.csv``: one row per marker frame, columns ``t_s`` (seconds, finite, increasing), ``ir`` and ``depth``
  (file names relative to the folder);
- the frames: IR (raw reflectivity) and depth (millimetres along the ray), each (H, W), as 16-bit PNG or
  ``.npy`` (uint8/uint16/float);
- ``lut_x.npy`` and ``lut_y.npy``: the depth camera's per-pixel unit-plane lookup table as two (H, W) arrays
  (Research Mode's MapImagePointToCameraUnitPlane: pixel (u, v) -> (x, y) on z = 1);
- optional ``gyro.csv``: columns ``t_s, wx, wy, wz`` (rad/s, body frame of the tool carrying the gyro);
- ``manifest.json``, written last: the number of frames, the size of every file of the folder, the SHA-256 of
  frames.csv and gyro.csv, and a recording id derived from them (the same recording, the same id and the same bytes:
  no time or random id inside).  :func:`read_recording` checks it, so a folder that mixes the frames of
  two recordings, or whose writing was interrupted, is refused.  A recording from another recorder is sealed,
  once checked by eye, with :func:`write_manifest`.
Points are expressed in the camera frame (T_world_cam = identity).

Bad input: a missing folder or file (frames.csv, a frame it lists, the lookup table), an empty, binary or
non-UTF-8 frames.csv / gyro.csv, a frames.csv without frames, a timestamp that is not a finite number within
+-1e12 s or does not increase, a gyro rate that is not a number, a lookup table with a NaN, all zero or of
another size than the first frame, or a missing / mismatching manifest raises :class:`RecordingError` naming
the folder or file and what is wrong, when the recording is read, before any frame is tracked.  A frame file
that cannot be decoded, or a frame of the wrong shape, dtype or units (depth in metres) is not an error here:
:func:`frame_problem` says what is wrong with it.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import shutil
import uuid
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from poseintegrity.errors import ArgumentError, PoseIntegrityError, check_array, check_increasing, check_same_length, read_text_file
from poseintegrity.tracking.io.timestamps import MAX_ABS_TIME_S, check_timestamp
from poseintegrity.tracking.markers.detection import validate_frame

MANIFEST = "manifest.json"
MANIFEST_FORMAT = 1


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
    """The csv at path with its columns checked: t_s finite (within +-1e12 s) and increasing, the ``numeric``
    columns numbers (NaN allowed: a non-finite gyro sample is flagged by the tracker).  Every problem, including
    an empty, binary or non-UTF-8 file, raises :class:`RecordingError` naming the file."""
    if not path.is_file():
        raise RecordingError(f"{path} is missing")
    text = read_text_file(path, RecordingError, f"table (expected a header {','.join(columns)} and one row per sample)")
    try:
        table = pd.read_csv(io.StringIO(text))
    except (ValueError, pd.errors.ParserError) as error:  # EmptyDataError is a ValueError
        raise RecordingError(f"{path}: cannot parse as CSV ({type(error).__name__}: {str(error).strip()})") from None
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise RecordingError(f"{path} lacks the columns {missing}")
    for column in numeric:
        values = pd.to_numeric(table[column], errors="coerce")
        text_rows = np.flatnonzero(values.isna() & table[column].notna())
        if text_rows.size:
            raise RecordingError(f"{path}: {column} of row {text_rows[0]} is not a number ({table[column].iloc[text_rows[0]]!r})")
        table[column] = values
    t = pd.to_numeric(table["t_s"], errors="coerce").to_numpy(float)
    bad = np.flatnonzero(~np.isfinite(t) | (np.abs(t) > MAX_ABS_TIME_S))
    if bad.size:
        raise RecordingError(f"{path}: timestamp t_s of row {bad[0]} is not a finite number of seconds within "
                             f"+-{MAX_ABS_TIME_S:g} ({table['t_s'].iloc[bad[0]]!r})")
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        what = "repeat" if t[back[0] + 1] == t[back[0]] else "decrease"
        raise RecordingError(f"{path}: timestamps must increase; they {what} at row {back[0] + 1} ({t[back[0]]} -> {t[back[0] + 1]})")
    return table.assign(t_s=t)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _folder_files(folder: Path) -> dict[str, int]:
    """{relative posix path: size in bytes} of every file under folder but the manifest."""
    return {p.relative_to(folder).as_posix(): p.stat().st_size for p in sorted(folder.rglob("*")) if p.is_file() and p.name != MANIFEST}


def write_manifest(folder: str | Path) -> dict:
    """Seal a recording folder: write manifest.json (frame count, every file's size, SHA-256 of frames.csv and
    gyro.csv, and the recording id: the SHA-256 of those, first 16 hex digits) through a temporary file and a
    rename, so it is complete or absent.
    :class:`RecordingWriter` calls it last; call it on a recording from another recorder once it is checked."""
    folder = Path(folder)
    frames_csv = folder / "frames.csv"
    if not frames_csv.is_file():
        raise RecordingError(f"{folder}: cannot seal a recording without frames.csv")
    n_frames = max(sum(1 for line in frames_csv.read_bytes().splitlines() if line.strip()) - 1, 0)
    content = {
        "n_frames": n_frames, "files": _folder_files(folder),
        "sha256": {name: _sha256(folder / name) for name in ("frames.csv", "gyro.csv") if (folder / name).is_file()},
    }
    recording_id = hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()[:16]
    manifest = {"format": MANIFEST_FORMAT, "recording_id": recording_id, **content}
    tmp = folder / (MANIFEST + ".tmp")
    tmp.write_text(json.dumps(manifest, indent=1), encoding="utf-8")
    os.replace(tmp, folder / MANIFEST)
    return manifest


def check_manifest(folder: Path, n_frames: int) -> dict:
    """The manifest of a recording folder, checked against the folder (files present with their sizes, no other
    file, frames.csv / gyro.csv unchanged, n_frames rows); :class:`RecordingError` saying what differs."""
    path = folder / MANIFEST
    if not path.is_file():
        raise RecordingError(f"{folder}: no {MANIFEST}; the recording was not closed (an interrupted or overwritten write) "
                             f"or comes from another recorder (seal it with poseintegrity.tracking.io.recording.write_manifest once checked)")
    try:
        manifest = json.loads(path.read_text(encoding="utf-8"))
        files, sha, expected_frames = dict(manifest["files"]), dict(manifest["sha256"]), int(manifest["n_frames"])
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise RecordingError(f"{path}: unreadable manifest ({type(error).__name__}: {error})") from None
    found = _folder_files(folder)
    missing = sorted(set(files) - set(found))
    extra = sorted(set(found) - set(files))
    resized = sorted(name for name in set(files) & set(found) if files[name] != found[name])
    changed = sorted(name for name, digest in sha.items() if name in found and _sha256(folder / name) != digest)
    problems = []
    if missing:
        problems.append(f"{len(missing)} file(s) of the manifest are missing, e.g. {missing[0]!r}")
    if extra:
        problems.append(f"{len(extra)} file(s) are not in the manifest (left from another recording?), e.g. {extra[0]!r}")
    if resized:
        problems.append(f"{len(resized)} file(s) differ in size from the manifest, e.g. {resized[0]!r}")
    if changed:
        problems.append(f"{', '.join(changed)} changed since the manifest was written")
    if expected_frames != n_frames:
        problems.append(f"the manifest counts {expected_frames} frames, frames.csv has {n_frames}")
    if problems:
        recording = manifest.get("recording_id", manifest.get("run_id"))  # run_id: a manifest of before ids were derived
        raise RecordingError(f"{folder}: does not match its {MANIFEST} (recording {recording!r}): " + "; ".join(problems))
    return manifest


def read_recording(folder: str | Path) -> Recording:
    """Read and check frames.csv, the lookup table, gyro.csv (if present) and the manifest of a recording
    folder (module docstring); :class:`RecordingError` naming the folder or file and what is wrong."""
    folder = Path(folder)
    if not folder.is_dir():
        raise RecordingError(f"{folder}: the recording folder does not exist")
    frames = _read_table(folder / "frames.csv", ["t_s", "ir", "depth"])
    if len(frames) == 0:
        raise RecordingError(f"{folder / 'frames.csv'}: lists no frames")
    absent = [name for name in [*frames.ir, *frames.depth] if not (folder / str(name)).is_file()]
    if absent:
        raise RecordingError(f"{folder}: {len(absent)} frame file(s) listed in frames.csv are missing, e.g. {absent[0]!r}")
    try:
        lut = np.stack([np.load(folder / "lut_x.npy"), np.load(folder / "lut_y.npy")], axis=-1).astype(float)
    except (OSError, ValueError, TypeError, EOFError) as error:
        raise RecordingError(f"{folder}: cannot read the unit-plane lookup table lut_x.npy / lut_y.npy ({error})") from None
    if lut.ndim != 3:
        raise RecordingError(f"{folder}: lut_x.npy and lut_y.npy must be (H, W) arrays, got {lut.shape[:-1]}")
    if not np.all(np.isfinite(lut)):
        v, u, c = np.argwhere(~np.isfinite(lut))[0]
        raise RecordingError(f"{folder}: the unit-plane lookup table has {int((~np.isfinite(lut)).sum())} non-finite entries, "
                             f"e.g. {('lut_x.npy', 'lut_y.npy')[c]} at pixel (u {u}, v {v}); it cannot unproject those pixels")
    if not np.any(lut):
        raise RecordingError(f"{folder}: the unit-plane lookup table is all zero; it cannot unproject pixels")
    first = load_image(folder / str(frames.ir.iloc[0]))
    if first is not None and first.shape[:2] != lut.shape[:2]:
        raise RecordingError(f"{folder}: the frames are {first.shape[1]} x {first.shape[0]} px ({frames.ir.iloc[0]}) but the "
                             f"lookup table is {lut.shape[1]} x {lut.shape[0]}; it is not this camera's table")
    gyro = _read_table(folder / "gyro.csv", ["t_s", "wx", "wy", "wz"], ("wx", "wy", "wz")) if (folder / "gyro.csv").exists() else None
    check_manifest(folder, len(frames))
    return Recording(folder, frames, lut, gyro)


def load_image(path: Path) -> np.ndarray | None:
    """One frame array from a 16-bit (or 8-bit) PNG or a .npy file, unchanged; None if the file cannot be
    decoded (a truncated or corrupt file: :func:`~poseintegrity.tracking.filter.recording_replay.track_recording`
    flags its frame ``bad_frame``)."""
    if path.suffix.lower() == ".npy":
        try:
            return np.load(path)
        except (OSError, ValueError, EOFError):
            return None
    return cv2.imread(str(path), cv2.IMREAD_UNCHANGED)


def frame_problem(recording: Recording, k: int) -> tuple[str, np.ndarray, np.ndarray]:
    """(why frame k cannot be used or "", ir, depth_mm) of a recording, reading its two files."""
    ir_name, depth_name = recording.frames.ir.iat[k], recording.frames.depth.iat[k]  # not .iloc[k]: 0.3 ms a frame
    ir, depth = load_image(recording.folder / ir_name), load_image(recording.folder / depth_name)
    unreadable = [name for name, image in ((ir_name, ir), (depth_name, depth)) if image is None]
    if unreadable:
        return f"cannot decode {', '.join(map(str, unreadable))}", np.zeros((0, 0)), np.zeros((0, 0))
    return validate_frame(ir, depth, recording.lut), ir, depth


class RecordingWriter:
    """Writes a recording folder that :func:`read_recording` reads: frames as 16-bit PNG (``frame_format="png"``,
    smaller) or ``.npy`` (``"npy"``, as large as the raw frames but ~50 x faster to read: a 512 x 512 frame
    decodes in ~5 ms as PNG, ~0.1 ms as .npy, so a replay from PNG is bounded by the decoding).

    The frames go into a temporary sibling folder; :meth:`close` writes frames.csv, gyro.csv and, last, the
    manifest, then moves the folder into place by renames, so ``folder`` only ever holds a whole recording.
    A folder that exists and is not empty is refused (:class:`RecordingError`) unless ``overwrite=True``, which
    replaces it at close.  Used as a context manager, an exception discards the partial recording.
    lut : (H, W, 2) unit-plane lookup table; every frame must be (H, W).
    """

    def __init__(self, folder: str | Path, lut: np.ndarray, overwrite: bool = False, frame_format: str = "png"):
        self.folder = Path(folder)
        if frame_format not in ("png", "npy"):
            raise ArgumentError(f"frame_format: expected 'png' or 'npy', got {frame_format!r}")
        self.frame_format = frame_format
        if self.folder.exists() and not self.folder.is_dir():
            raise RecordingError(f"{self.folder}: exists and is not a folder")
        if self.folder.is_dir() and any(self.folder.iterdir()) and not overwrite:
            raise RecordingError(f"{self.folder}: the folder is not empty; pass overwrite=True to replace the recording in it")
        try:
            self.lut = check_array("lut", lut, shape=(None, None, 2))
        except ArgumentError as error:
            raise RecordingError(f"{self.folder}: {error}") from None
        self.writer_id = uuid.uuid4().hex  # names this writer's staging folder only, never a file of the recording
        self.folder.parent.mkdir(parents=True, exist_ok=True)
        self.staging = self.folder.parent / f".{self.folder.name}.writing-{self.writer_id}"
        (self.staging / "ir").mkdir(parents=True)
        (self.staging / "depth").mkdir()
        np.save(self.staging / "lut_x.npy", self.lut[..., 0])
        np.save(self.staging / "lut_y.npy", self.lut[..., 1])
        self.rows: list[dict] = []
        self.closed = False

    def add_frame(self, t: float, ir: np.ndarray, depth_mm: np.ndarray) -> None:
        """ir, depth_mm : (H, W) uint16 (or uint8) of the lookup table's size; t (s) after the previous frame."""
        t = check_timestamp(t)
        if self.rows and t <= self.rows[-1]["t_s"]:
            raise ArgumentError(f"t: frame times must increase, got {t!r} after {self.rows[-1]['t_s']!r}")
        for name, image in (("ir", ir), ("depth_mm", depth_mm)):
            if not isinstance(image, np.ndarray) or image.shape != self.lut.shape[:2] or image.dtype not in (np.uint8, np.uint16):
                raise ArgumentError(f"{name}: expected a {self.lut.shape[:2]} uint16 image like the lookup table, got "
                                    f"{type(image).__name__} {getattr(image, 'shape', '')} {getattr(image, 'dtype', '')}")
        name = f"{len(self.rows):06d}.{self.frame_format}"
        if self.frame_format == "npy":
            np.save(self.staging / "ir" / name, ir)
            np.save(self.staging / "depth" / name, depth_mm)
        elif not (cv2.imwrite(str(self.staging / "ir" / name), ir) and cv2.imwrite(str(self.staging / "depth" / name), depth_mm)):
            raise RecordingError(f"{self.staging}: cannot write frame {name}")
        self.rows.append({"t_s": t, "ir": f"ir/{name}", "depth": f"depth/{name}"})

    def close(self, gyro_t: np.ndarray | None = None, gyro: np.ndarray | None = None,
              tables: dict[str, pd.DataFrame] | None = None) -> None:
        """Write frames.csv, gyro.csv if given (times (G,) s, rates (G, 3) rad/s), the extra ``tables``
        ({file name: table}, e.g. the headset's camera poses of a converted recording) and the manifest, then
        move the recording into place (replacing the old one if overwrite was given)."""
        if self.closed:
            raise RecordingError(f"{self.folder}: the recording is already closed")
        if (gyro_t is None) != (gyro is None):
            raise ArgumentError("gyro_t, gyro: give both (sample times and rates) or neither")
        if gyro_t is not None:  # checked before anything is written
            gyro_t = check_increasing("gyro_t", gyro_t)
            if not len(gyro_t) or np.abs(gyro_t).max() > MAX_ABS_TIME_S:
                raise ArgumentError(f"gyro_t: expected one or more sample times within +-{MAX_ABS_TIME_S:g} s")
            gyro = check_array("gyro", gyro, shape=(None, 3), allow_nan=True)  # NaN: flagged bad_gyro when tracked
            check_same_length(gyro_t=gyro_t, gyro=gyro)
        for name in tables or {}:
            if name in ("frames.csv", "gyro.csv") or Path(name).name != name or not name.endswith(".csv"):
                raise ArgumentError(f"tables: {name!r} must be a plain .csv file name other than frames.csv and gyro.csv")
        pd.DataFrame(self.rows, columns=["t_s", "ir", "depth"]).to_csv(self.staging / "frames.csv", index=False, float_format="%.17g")
        if gyro_t is not None:
            table = pd.DataFrame({"t_s": gyro_t, "wx": gyro[:, 0], "wy": gyro[:, 1], "wz": gyro[:, 2]})
            table.to_csv(self.staging / "gyro.csv", index=False, float_format="%.17g")
        for name, table in (tables or {}).items():
            table.to_csv(self.staging / name, index=False, float_format="%.17g")
        write_manifest(self.staging)
        old = self.folder.parent / f".{self.folder.name}.old-{self.writer_id}"
        if self.folder.exists():
            os.replace(self.folder, old)  # an empty folder, or the recording overwrite=True replaces
        os.replace(self.staging, self.folder)
        shutil.rmtree(old, ignore_errors=True)
        self.closed = True

    def discard(self) -> None:
        """Drop the partial recording (the staging folder); ``folder`` is left as it was."""
        shutil.rmtree(self.staging, ignore_errors=True)
        self.closed = True

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(self, kind, value, traceback) -> None:
        if kind is not None and not self.closed:
            self.discard()
