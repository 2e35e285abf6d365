"""HoloLens 2 AHAT recordings of two public recorders, converted into our recording layout (:mod:`recording`), so
that :func:`~poseintegrity.tracking.io.recording.read_recording` and ``track_recording`` replay them unchanged.

Black and Salcudean (section II-B) detect their markers in the AHAT stream of the HoloLens 2 Research Mode: the
active-brightness (AB) image and the depth image of the 512 x 512 short-throw camera.  Two recorders write that
stream to disk (formats and their sources: docs/references.md, "HoloLens 2 AHAT recordings"; units and
conventions: docs/recorded-data.md):

- Microsoft's StreamRecorder (HoloLens2ForCV): per frame ``<ticks>.pgm`` (depth) and ``<ticks>_ab.pgm`` (AB),
  binary PGM (P5), 16 bit big-endian, in ``Depth AHaT.tar`` or, extracted, the folder ``Depth AHaT``; the name
  is the frame time in 100 ns ticks (FILETIME).  ``Depth AHaT_lut.bin``: float32 (x, y, z) per pixel, rows = v,
  the unit-length ray of the pixel centre; ``Depth AHaT_extrinsics.txt``: the rig -> camera transform,
  ``Depth AHaT_rig2world.txt``: one line per frame, ticks and rig -> world (both 16 comma-separated numbers,
  a row-major 4 x 4 for column vectors).  :func:`convert_stream_recorder`.
- hl2ss (jdibenes/hl2ss), its recorder's ``rm_depth_ahat.bin``: a header (magic ``HL2SSV23``, port, user data,
  the stream configuration) and packets (ticks, payload, optional float32 4 x 4 rig -> world pose for row
  vectors); the calibration folder ``rm_depth_ahat`` (uv2xy.bin: (x, y) on z = 1 sampled at the integer image
  point (u, v), where StreamRecorder samples (u + 0.5, v + 0.5); extrinsics.bin, scale.bin).  Only frames sent
  uncompressed (AB profile RAW, depth profile SAME) can be read: an H.264 / HEVC or Zdepth stream needs a video
  decoder and is refused.  :func:`convert_hl2ss`.

What the conversion writes (frames as .npy by default, see ``frame_format``): IR = AB (uint16, unchanged),
depth = millimetres along the pixel's ray (uint16, 0 = invalid: Research Mode's invalid AHAT readings, >= 4090,
become 0), the unit-plane lookup table lut[v, u] = (x / z, y / z), t_s = seconds since the first frame (integer ticks / 1e7), and ``camera_poses.csv``
(t_s, ticks, has_pose, T00..T33: T_world_cam = rig2world @ inv(rig -> camera)) when the recording has poses;
marker poses stay in the camera frame.  AHAT depth aliases beyond about 1 m (a marker at 1.1 m reads ~0.1 m);
it is not unwrapped (the detector's depth window keeps 100-900 mm).

Bad input raises :class:`~poseintegrity.tracking.io.recording.RecordingError` naming the file, the field and the
frame or packet: a missing, empty or truncated PGM, ``.bin`` or tar, a PGM header that is not a 16-bit P5, an AB
frame without its depth frame (or the reverse), frames of another size than the lookup table, a lookup table
with a non-finite entry or a pixel the headset could not map (z <= 0), timestamps that do not increase, an
extrinsics matrix that is not rigid, an hl2ss file of another version, port, mode or encoding.  The conversion
writes through :class:`~poseintegrity.tracking.io.recording.RecordingWriter`: on any error nothing is left behind.
"""

from __future__ import annotations

import contextlib
import re
import struct
import tarfile
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pandas as pd

from poseintegrity.errors import PoseIntegrityError, check_rotation, read_text_file
from poseintegrity.tracking.io.recording import RecordingError, RecordingWriter

TICKS_PER_SECOND = 10_000_000  # both recorders: 100 ns ticks
AHAT_INVALID_DEPTH = 4090  # Research Mode: an AHAT depth reading >= 4090 is invalid (StreamRecorder writes 0)
AHAT_SHAPE = (512, 512)  # hl2ss's fixed AHAT size (Parameters_RM_DEPTH_AHAT); StreamRecorder's comes from the PGM
STREAM_RECORDER_SENSOR = "Depth AHaT"
HL2SS_MAGIC = b"HL2SSV23"
HL2SS_PORT_AHAT = 3804
HL2SS_RAW = 0xFF  # VideoProfile.RAW
HL2SS_DEPTH_SAME = 0  # DepthProfile.SAME: depth sent like AB (raw when AB is raw)
HL2SS_PAYLOAD_PREFIX = 8  # bytes before the depth image in an AHAT payload (skipped by hl2ss's decoder too)
HL2SS_METADATA = 8  # the sensor ticks (uint64) after the AB image
POSE_COLUMNS = [f"T{i}{j}" for i in range(4) for j in range(4)]
_PGM_NAME = re.compile(r"^(\d+)(_ab)?\.pgm$")
_PGM_FIELD = re.compile(rb"\s*(#[^\n]*\n\s*)*(\S+)")  # a header field after whitespace and '#' comments


# ------------------------------------------------------------------------------------------------ StreamRecorder
def decode_pgm(data: bytes, name: str) -> np.ndarray:
    """A binary PGM (P5) as an (H, W) array: uint16 from big-endian words when maxval > 255 (the recorder writes
    65535), uint8 otherwise.  :class:`RecordingError` naming ``name`` for an empty file, a header that is not P5,
    or fewer / more pixel bytes than the header announces (a truncated write)."""
    if not data:
        raise RecordingError(f"{name}: the PGM file is empty (0 bytes)")
    fields, position = [], 0
    while len(fields) < 4:  # magic, width, height, maxval, separated by whitespace (and '#' comments)
        match = _PGM_FIELD.match(data, position)
        if match is None:
            raise RecordingError(f"{name}: PGM header ends after {len(fields)} of its 4 fields (magic, width, height, maxval)")
        fields.append(match.group(2))
        position = match.end()
    if fields[0] != b"P5":
        raise RecordingError(f"{name}: not a binary PGM (magic {fields[0][:8]!r}, expected b'P5')")
    try:
        width, height, maxval = (int(f) for f in fields[1:])
    except ValueError:
        raise RecordingError(f"{name}: PGM header width / height / maxval are not integers ({fields[1:]!r})") from None
    if width <= 0 or height <= 0 or not 0 < maxval < 65536:
        raise RecordingError(f"{name}: PGM header has width {width}, height {height}, maxval {maxval}")
    pixels = data[position + 1:]  # one whitespace byte ends the header
    dtype = np.dtype(">u2") if maxval > 255 else np.dtype("u1")
    expected = width * height * dtype.itemsize
    if len(pixels) != expected:
        raise RecordingError(f"{name}: PGM pixel data is {len(pixels)} bytes, the header ({width} x {height}, maxval "
                             f"{maxval}) announces {expected}: a truncated or corrupt frame")
    return np.frombuffer(pixels, dtype).reshape(height, width).astype(dtype.newbyteorder("="))


def _read_bytes(path: Path, what: str) -> bytes:
    try:
        return path.read_bytes()
    except OSError as error:
        raise RecordingError(f"{path}: cannot read the {what} ({error.strerror or error})") from None


def _pgm_frames(capture: Path, stack: contextlib.ExitStack) -> tuple[Path, list[tuple[int, str, str]], Callable[[str], bytes]]:
    """(where, [(ticks, depth name, ab name)] in time order, read(name) -> bytes) of the AHAT frames of a capture:
    the folder ``Depth AHaT`` if extracted, else the tarball ``Depth AHaT.tar`` (kept open by ``stack``)."""
    folder, tarball = capture / STREAM_RECORDER_SENSOR, capture / f"{STREAM_RECORDER_SENSOR}.tar"
    if folder.is_dir():
        names = [p.name for p in folder.iterdir() if p.is_file()]
        where = folder

        def read(name: str) -> bytes:
            return _read_bytes(folder / name, "PGM frame")
    elif tarball.is_file():
        try:
            archive = stack.enter_context(tarfile.open(tarball))  # members are read on demand, while converting
            members = {m.name.split("/")[-1]: m for m in archive.getmembers() if m.isfile()}
        except (tarfile.TarError, OSError, EOFError) as error:
            raise RecordingError(f"{tarball}: cannot read the tarball ({type(error).__name__}: {error})") from None
        names, where = list(members), tarball

        def read(name: str) -> bytes:
            try:
                return archive.extractfile(members[name]).read()
            except (tarfile.TarError, OSError, EOFError) as error:
                raise RecordingError(f"{tarball}: cannot read member {name} ({type(error).__name__}: {error})") from None
    else:
        raise RecordingError(f"{capture}: no AHAT frames: neither the folder {STREAM_RECORDER_SENSOR!r} nor "
                             f"{STREAM_RECORDER_SENSOR}.tar exists (is it a StreamRecorder capture with AHAT enabled?)")
    depth, ab = {}, {}
    for name in names:
        match = _PGM_NAME.match(name)
        if match:
            (ab if match.group(2) else depth)[int(match.group(1))] = name
    if not depth and not ab:
        raise RecordingError(f"{where}: holds no <ticks>.pgm / <ticks>_ab.pgm frames")
    for have, lack, suffix in ((depth, ab, "_ab.pgm"), (ab, depth, ".pgm")):
        orphans = sorted(set(have) - set(lack))
        if orphans:
            raise RecordingError(f"{where}: {len(orphans)} frame(s) lack their {suffix} file, e.g. {orphans[0]}{suffix}")
    return where, [(ticks, depth[ticks], ab[ticks]) for ticks in sorted(depth)], read


def _number_rows(path: Path, columns: int, what: str) -> list[list[str]]:
    """The rows of a comma-separated text file of numbers, each ``columns`` finite numbers (kept as text, so that
    integer ticks above 2**53 stay exact); RecordingError naming the file and row."""
    rows = []
    for k, line in enumerate(line for line in read_text_file(path, RecordingError, what).splitlines() if line.strip()):
        row = [v.strip() for v in line.split(",")]
        try:
            finite = len(row) == columns and all(np.isfinite(float(v)) for v in row)
        except ValueError:
            finite = False
        if not finite:
            raise RecordingError(f"{path}: row {k} of the {what} must be {columns} comma-separated finite numbers, got {line[:60]!r}")
        rows.append(row)
    return rows


def _rigid(path: Path, T: np.ndarray, what: str, row: int | None = None) -> np.ndarray:
    """T (4, 4) if it is a rigid transform (rotation to 1e-4: the recorders print 6 significant digits)."""
    where = f"{path}: {what}" + ("" if row is None else f" of row {row}")
    try:
        check_rotation(what, T[:3, :3], atol=1e-4)
    except PoseIntegrityError as error:
        raise RecordingError(f"{where} is not a rigid transform ({error})") from None
    if not np.allclose(T[3], [0.0, 0.0, 0.0, 1.0], atol=1e-6):
        raise RecordingError(f"{where}: last row must be [0, 0, 0, 1], got {T[3].tolist()}")
    return T


def unit_plane_from_rays(rays: np.ndarray, path: Path) -> np.ndarray:
    """The (H, W, 2) unit-plane table (x / z, y / z) of per-pixel rays (H, W, 3); RecordingError naming the file
    and the first pixel for a non-finite entry or a pixel the headset could not map (z <= 0: Research Mode's
    MapImagePointToCameraUnitPlane failed there; we do not guess its ray)."""
    bad = ~np.isfinite(rays).all(axis=-1)
    if bad.any():
        v, u = np.argwhere(bad)[0]
        raise RecordingError(f"{path}: the lookup table has {int(bad.sum())} non-finite pixel(s), e.g. (u {u}, v {v}): {rays[v, u].tolist()}")
    unmapped = rays[..., 2] <= 0
    if unmapped.any():
        v, u = np.argwhere(unmapped)[0]
        raise RecordingError(f"{path}: {int(unmapped.sum())} pixel(s) of the lookup table have no ray (z <= 0: the headset "
                             f"could not map them), e.g. (u {u}, v {v}); such a table is not read")
    return rays[..., :2] / rays[..., 2:]


def read_stream_recorder_lut(path: Path, shape: tuple[int, int]) -> np.ndarray:
    """``Depth AHaT_lut.bin`` as the unit-plane table (H, W, 2) of frames of ``shape`` (H, W): float32 (x, y, z)
    per pixel, row-major with rows = v, each the unit ray through the centre (u + 0.5, v + 0.5) of its pixel."""
    data = _read_bytes(path, "lookup table")
    H, W = shape
    if len(data) != H * W * 12:
        raise RecordingError(f"{path}: the lookup table is {len(data)} bytes; frames of {W} x {H} px need {H * W * 12} "
                             f"(3 float32 per pixel): a truncated table, or one of another camera")
    return unit_plane_from_rays(np.frombuffer(data, "<f4").reshape(H, W, 3).astype(float), path)


def read_stream_recorder_poses(capture: Path) -> tuple[np.ndarray, np.ndarray] | None:
    """(ticks (n,), T_world_cam (n, 4, 4)) from ``Depth AHaT_rig2world.txt`` and ``Depth AHaT_extrinsics.txt``
    (rig -> camera; camera -> world = rig2world @ inv(extrinsics)); None if the capture has neither file."""
    rig2world_path = capture / f"{STREAM_RECORDER_SENSOR}_rig2world.txt"
    extrinsics_path = capture / f"{STREAM_RECORDER_SENSOR}_extrinsics.txt"
    if not rig2world_path.exists() and not extrinsics_path.exists():
        return None
    for path in (rig2world_path, extrinsics_path):
        if not path.is_file():
            raise RecordingError(f"{path} is missing; the headset poses need both the rig2world and the extrinsics file")
    rig_to_cam = _rigid(extrinsics_path, np.array(_number_rows(extrinsics_path, 16, "extrinsics")[0], float).reshape(4, 4), "extrinsics")
    rows = _number_rows(rig2world_path, 17, "rig2world poses")
    if bad := [k for k, row in enumerate(rows) if not row[0].isdigit()]:
        raise RecordingError(f"{rig2world_path}: the timestamp (first column) of row {bad[0]} is not whole ticks: {rows[bad[0]][0]!r}")
    ticks = np.array([int(row[0]) for row in rows])
    back = np.flatnonzero(np.diff(ticks) <= 0)
    if back.size:
        raise RecordingError(f"{rig2world_path}: the timestamps (first column) must increase; they do not at row {back[0] + 1} "
                             f"({ticks[back[0]]} -> {ticks[back[0] + 1]})")
    rig_to_world = np.array([row[1:] for row in rows], float).reshape(-1, 4, 4)
    for k, T in enumerate(rig_to_world):
        _rigid(rig2world_path, T, "rig2world pose", k)
    return ticks, rig_to_world @ np.linalg.inv(rig_to_cam)


def convert_stream_recorder(capture: str | Path, folder: str | Path, overwrite: bool = False, frame_format: str = "npy") -> Path:
    """Convert the AHAT stream of a StreamRecorder capture folder into a recording folder (module docstring) and
    return ``folder``.  Frames are read and checked one by one while written; an error leaves no folder.
    frame_format : "npy" (default: as large as the PGM frames, fast to replay) or "png" (smaller, replayed at
    the speed of PNG decoding), see :class:`~poseintegrity.tracking.io.recording.RecordingWriter`."""
    capture = Path(capture)
    if not capture.is_dir():
        raise RecordingError(f"{capture}: the StreamRecorder capture folder does not exist")
    with contextlib.ExitStack() as stack:
        where, frames, read = _pgm_frames(capture, stack)
        first_depth = decode_pgm(read(frames[0][1]), f"{where}/{frames[0][1]}")
        lut = read_stream_recorder_lut(capture / f"{STREAM_RECORDER_SENSOR}_lut.bin", first_depth.shape)
        poses = read_stream_recorder_poses(capture)
        ticks = np.array([f[0] for f in frames])
        writer = stack.enter_context(RecordingWriter(folder, lut, overwrite=overwrite, frame_format=frame_format))
        for t, depth_name, ab_name in frames:
            depth, ab = (decode_pgm(read(name), f"{where}/{name}") for name in (depth_name, ab_name))
            _write_frame(writer, ticks[0], t, ab, depth_mm(depth), f"{where}/{ab_name}", f"{where}/{depth_name}")
        tables = {}
        if poses is not None:
            index = {int(t): k for k, t in enumerate(poses[0])}
            T = np.array([poses[1][index[t]] if t in index else np.full((4, 4), np.nan) for t in ticks])
            tables["camera_poses.csv"] = _pose_table(ticks, T)
        writer.close(tables=tables)
    return Path(folder)


def depth_mm(raw: np.ndarray, scale: float = 1000.0) -> np.ndarray:
    """AHAT depth readings (raw units, ``scale`` per metre) as uint16 millimetres along the ray, 0 where invalid
    (a reading >= 4090, Research Mode's invalid AHAT value)."""
    mm = raw if scale == 1000.0 else np.rint(raw * (1000.0 / scale))
    return np.where(raw >= AHAT_INVALID_DEPTH, 0, np.clip(mm, 0, np.iinfo(np.uint16).max)).astype(np.uint16)


def _write_frame(writer: RecordingWriter, t0: int, t: int, ab: np.ndarray, depth: np.ndarray, ab_name: str,
                 depth_name: str) -> None:
    """One AHAT frame (depth in mm) into the writer at t - t0 ticks, its shapes checked against the table."""
    for name, image in ((ab_name, ab), (depth_name, depth)):
        if image.shape != writer.lut.shape[:2]:
            raise RecordingError(f"{name}: the frame is {image.shape[1]} x {image.shape[0]} px, the lookup table "
                                 f"{writer.lut.shape[1]} x {writer.lut.shape[0]}")
    writer.add_frame((t - t0) / TICKS_PER_SECOND, ab.astype(np.uint16), depth)


def _pose_table(ticks: np.ndarray, T_world_cam: np.ndarray) -> pd.DataFrame:
    table = pd.DataFrame(T_world_cam.reshape(len(ticks), 16), columns=POSE_COLUMNS)
    table.insert(0, "has_pose", np.isfinite(T_world_cam).all(axis=(1, 2)))
    table.insert(0, "ticks", ticks)
    table.insert(0, "t_s", (ticks - ticks[0]) / TICKS_PER_SECOND)
    return table


# --------------------------------------------------------------------------------------------------------- hl2ss
def _unpack(file, fmt: str, path: Path, field: str) -> tuple:
    """The next struct ``fmt`` of an open file; RecordingError if the file ends inside it."""
    size = struct.calcsize(fmt)
    data = file.read(size)
    if len(data) < size:
        raise RecordingError(f"{path}: the file ends inside {field} ({len(data)} of {size} bytes): a truncated recording")
    return struct.unpack(fmt, data)


def read_hl2ss_ahat(path: str | Path) -> Iterator[tuple[int, np.ndarray, np.ndarray, np.ndarray | None]]:
    """(ticks, depth (512, 512) uint16, AB (512, 512) uint16, rig -> world pose (4, 4) float for row vectors or
    None) per packet of an hl2ss ``rm_depth_ahat.bin``, read one packet at a time (a raw recording is ~1 MB a
    frame).  The header and its configuration are checked before the first packet."""
    path = Path(path)
    try:
        file = path.open("rb")
    except OSError as error:
        raise RecordingError(f"{path}: cannot read the hl2ss recording ({error.strerror or error})") from None
    with file:
        if not file.peek(1):
            raise RecordingError(f"{path}: the hl2ss recording is empty (0 bytes)")
        magic, port, user_size = _unpack(file, "<8sHI", path, "the header")
        if magic != HL2SS_MAGIC:
            raise RecordingError(f"{path}: header magic is {magic!r}, expected {HL2SS_MAGIC!r} (another hl2ss version, or not an hl2ss file)")
        if port != HL2SS_PORT_AHAT:
            raise RecordingError(f"{path}: header port is {port}, not the RM depth AHAT stream ({HL2SS_PORT_AHAT})")
        _unpack(file, f"<{user_size}s", path, "the user data of the header")
        mode, _divisor, profile_z, profile_ab, _level, _bitrate, n_options = _unpack(file, "<BBBBBIB", path, "the configuration")
        _unpack(file, f"<{2 * n_options}Q", path, "the encoder options of the configuration")
        if mode not in (0, 1):
            raise RecordingError(f"{path}: configuration mode is {mode}; a frame stream is mode 0 or 1")
        if profile_ab != HL2SS_RAW or profile_z != HL2SS_DEPTH_SAME:
            raise RecordingError(f"{path}: configuration profile_z {profile_z}, profile_ab {profile_ab}: the frames are compressed "
                                 f"(H.264 / HEVC or Zdepth); only uncompressed frames (profile_ab RAW 255, profile_z SAME 0) are read")
        pixels = AHAT_SHAPE[0] * AHAT_SHAPE[1]
        payload_size = HL2SS_PAYLOAD_PREFIX + 4 * pixels + HL2SS_METADATA
        pose_size = 64 if mode == 1 else 0
        k = 0
        while file.peek(1):
            ticks, size = _unpack(file, "<QI", path, f"the header of packet {k}")
            if size != payload_size:
                raise RecordingError(f"{path}: packet {k} has a payload of {size} bytes; an uncompressed AHAT frame has {payload_size}")
            data = file.read(size + pose_size)
            if len(data) < size + pose_size:
                raise RecordingError(f"{path}: packet {k} is truncated ({len(data)} of {size + pose_size} bytes): an interrupted recording")
            depth = np.frombuffer(data, "<u2", pixels, HL2SS_PAYLOAD_PREFIX).reshape(AHAT_SHAPE)
            ab = np.frombuffer(data, "<u2", pixels, HL2SS_PAYLOAD_PREFIX + 2 * pixels).reshape(AHAT_SHAPE)
            pose = np.frombuffer(data, "<f4", 16, size).reshape(4, 4).astype(float) if pose_size else None
            yield ticks, depth, ab, pose
            k += 1


def read_hl2ss_calibration(folder: str | Path) -> tuple[np.ndarray, np.ndarray, float]:
    """(unit-plane table (512, 512, 2), rig -> camera extrinsics (4, 4) for row vectors, depth scale: raw units per
    metre) from hl2ss's calibration folder ``rm_depth_ahat`` (or the calibration root holding it)."""
    folder = Path(folder)
    if (folder / "rm_depth_ahat").is_dir():
        folder = folder / "rm_depth_ahat"
    arrays = {}
    for name, count in (("uv2xy.bin", AHAT_SHAPE[0] * AHAT_SHAPE[1] * 2), ("extrinsics.bin", 16), ("scale.bin", 1)):
        data = _read_bytes(folder / name, "hl2ss calibration file")
        if len(data) != 4 * count:
            raise RecordingError(f"{folder / name}: {len(data)} bytes, expected {4 * count} ({count} float32)")
        arrays[name] = np.frombuffer(data, "<f4").astype(float)
    uv2xy = arrays["uv2xy.bin"].reshape(*AHAT_SHAPE, 2)
    # hl2ss leaves (0, 0) where the headset's mapping failed: no ray (z = 0), refused by unit_plane_from_rays
    z = np.where((uv2xy == 0).all(axis=-1, keepdims=True), 0.0, 1.0)
    lut = unit_plane_from_rays(np.concatenate([uv2xy, z], axis=-1), folder / "uv2xy.bin")
    extrinsics = arrays["extrinsics.bin"].reshape(4, 4)
    if not np.isfinite(extrinsics).all():
        raise RecordingError(f"{folder / 'extrinsics.bin'}: non-finite entries {extrinsics.tolist()}")
    _rigid(folder / "extrinsics.bin", extrinsics.T, "extrinsics")  # row-vector convention: its transpose is rigid
    scale = float(arrays["scale.bin"][0])
    if not (np.isfinite(scale) and scale > 0):
        raise RecordingError(f"{folder / 'scale.bin'}: the depth scale must be a positive number, got {scale!r}")
    return lut, extrinsics, scale


def convert_hl2ss(recording: str | Path, calibration: str | Path, folder: str | Path, overwrite: bool = False,
                  frame_format: str = "npy") -> Path:
    """Convert an hl2ss ``rm_depth_ahat.bin`` with its calibration folder into a recording folder (module
    docstring) and return ``folder``.  Depth becomes millimetres (raw * 1000 / scale); the packet poses (mode 1)
    give camera_poses.csv.  An error leaves no folder.  frame_format : as for :func:`convert_stream_recorder`."""
    recording = Path(recording)
    lut, extrinsics, scale = read_hl2ss_calibration(calibration)
    cam_to_rig = np.linalg.inv(extrinsics)
    ticks, poses = [], []
    with RecordingWriter(folder, lut, overwrite=overwrite, frame_format=frame_format) as writer:
        for k, (t, depth, ab, pose) in enumerate(read_hl2ss_ahat(recording)):
            if ticks and t <= ticks[-1]:
                raise RecordingError(f"{recording}: packet timestamps must increase; packet {k} has {t} after {ticks[-1]}")
            ticks.append(t)
            name = f"{recording}: packet {k}"
            _write_frame(writer, ticks[0], t, ab, depth_mm(depth, scale), name, name)
            # hl2ss multiplies row vectors: p_world = p_cam @ inv(extrinsics) @ pose; transposed for column vectors
            valid = pose is not None and pose[3, 3] != 0 and np.isfinite(pose).all()
            poses.append((cam_to_rig @ pose).T if valid else np.full((4, 4), np.nan))
        if not ticks:
            raise RecordingError(f"{recording}: holds no frames (a header only)")
        tables = {"camera_poses.csv": _pose_table(np.array(ticks), np.array(poses))} if any(np.isfinite(p).all() for p in poses) else {}
        writer.close(tables=tables)
    return Path(folder)
