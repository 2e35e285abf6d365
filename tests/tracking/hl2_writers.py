"""Writers of the two HoloLens 2 recorders' AHAT formats for the tests, written from their definitions
(docs/references.md, "HoloLens 2 AHAT recordings") independently of the readers in
poseintegrity.tracking.io.hl2_recordings: StreamRecorder's PGM frames, lookup table, extrinsics and rig2world files,
and hl2ss's rm_depth_ahat.bin with its calibration folder."""

from __future__ import annotations

import io
import struct
import tarfile
from pathlib import Path

import numpy as np

from poseintegrity.tracking.simulation.frames import intrinsics, unit_plane_lut
from poseintegrity.tracking.simulation.simulate import simulate

T0_TICKS = 133_456_789_012_345_678  # a FILETIME of 2023 in 100 ns ticks, beyond float64's exact integers


def simulated_frames(params, n_frames: int, seed: int = 0) -> tuple[np.ndarray, list[tuple[int, np.ndarray, np.ndarray]]]:
    """(unit-plane LUT (H, W, 2), [(ticks, ir uint16, depth uint16 mm)]) of the first n_frames of a simulated
    recording (the tool moving, seeded)."""
    frames = []
    simulate(params, np.random.default_rng(seed), duration_s=0.05 * n_frames + 1.0, n_frames=n_frames,
             sink=lambda t, ir, depth: frames.append((T0_TICKS + round(t * 1e7), ir.copy(), depth.copy())))
    camera = params.camera
    return unit_plane_lut(intrinsics(camera), camera.width, camera.height), frames


def pgm(image: np.ndarray) -> bytes:
    """A 16-bit binary PGM as StreamRecorder writes it: header "P5\\n<W> <H>\\n65535\\n", big-endian words."""
    return f"P5\n{image.shape[1]} {image.shape[0]}\n65535\n".encode() + image.astype(">u2").tobytes()


def rays(lut: np.ndarray) -> np.ndarray:
    """StreamRecorder's LUT entries: the unit-length ray (x, y, 1) / norm of every pixel, float32, rows = v."""
    xyz = np.concatenate([lut, np.ones(lut.shape[:2] + (1,))], axis=-1)
    return (xyz / np.linalg.norm(xyz, axis=-1, keepdims=True)).astype("<f4")


def matrix_text(T: np.ndarray) -> str:
    return ",".join(f"{v:.9g}" for v in T.reshape(-1))


def write_stream_recorder(capture: Path, lut: np.ndarray, frames, tar: bool = False, rig_to_cam: np.ndarray | None = None,
                          rig_to_world: list[np.ndarray] | None = None) -> Path:
    """A capture folder with the AHAT stream (a "Depth AHaT" folder, or "Depth AHaT.tar"), its LUT and, if given,
    extrinsics (rig -> camera, column vectors) and one rig -> world pose per frame."""
    capture.mkdir(parents=True, exist_ok=True)
    members = {}
    for ticks, ir, depth in frames:
        members[f"{ticks}.pgm"] = pgm(depth)
        members[f"{ticks}_ab.pgm"] = pgm(ir)
    if tar:
        with tarfile.open(capture / "Depth AHaT.tar", "w") as archive:
            for name, data in members.items():
                info = tarfile.TarInfo(name)
                info.size = len(data)
                archive.addfile(info, io.BytesIO(data))
    else:
        (capture / "Depth AHaT").mkdir()
        for name, data in members.items():
            (capture / "Depth AHaT" / name).write_bytes(data)
    (capture / "Depth AHaT_lut.bin").write_bytes(rays(lut).tobytes())
    if rig_to_cam is not None:
        (capture / "Depth AHaT_extrinsics.txt").write_text(matrix_text(rig_to_cam) + "\n")
        lines = [f"{ticks},{matrix_text(T)}" for (ticks, _, _), T in zip(frames, rig_to_world)]
        (capture / "Depth AHaT_rig2world.txt").write_text("\n".join(lines) + "\n")
    return capture


def write_hl2ss(path: Path, calibration: Path, lut: np.ndarray, frames, rig_to_cam: np.ndarray | None = None,
                rig_to_world: list[np.ndarray] | None = None, scale: float = 1000.0, profile_ab: int = 0xFF) -> Path:
    """rm_depth_ahat.bin as hl2ss's recorder writes it (mode 1 with poses, else mode 0; depth profile SAME,
    AB profile RAW unless given) and the calibration folder calibration/rm_depth_ahat.  Matrices are given for
    column vectors and written transposed, as hl2ss (row vectors) stores them."""
    mode = 1 if rig_to_world is not None else 0
    header = b"HL2SSV23" + struct.pack("<HI", 3804, 4) + b"user"
    configuration = struct.pack("<BBBBBIB", mode, 1, 0, profile_ab, 0xFF, 0, 1) + struct.pack("<QQ", 7, 9)
    packets = []
    for k, (ticks, ir, depth) in enumerate(frames):
        raw = np.rint(depth.astype(float) * scale / 1000.0).astype("<u2")
        payload = struct.pack("<II", 0, 0) + raw.tobytes() + ir.astype("<u2").tobytes() + struct.pack("<Q", ticks // 10)
        pose = rig_to_world[k].T.astype("<f4").tobytes() if mode == 1 else b""
        packets.append(struct.pack("<QI", ticks, len(payload)) + payload + pose)
    path.write_bytes(header + configuration + b"".join(packets))
    folder = calibration / "rm_depth_ahat"
    folder.mkdir(parents=True, exist_ok=True)
    lut.astype("<f4").tofile(folder / "uv2xy.bin")
    (np.eye(4) if rig_to_cam is None else rig_to_cam).T.astype("<f4").tofile(folder / "extrinsics.bin")
    np.array([scale], "<f4").tofile(folder / "scale.bin")
    np.array([1055.0], "<f4").tofile(folder / "alias.bin")
    return path
