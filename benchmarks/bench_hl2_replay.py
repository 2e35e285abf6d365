"""Replay speed of a converted HoloLens 2 recording, as ratios against references measured in the same run.

A simulated AHAT recording (paper-scale params.yaml, 512 x 512 frames, the tool of the paper moving) is written
as a StreamRecorder capture (PGM frames, lut.bin; tests/tracking/hl2_writers.py) and by RecordingWriter in
our layout (.npy and PNG frames).  Printed, in frames per second on one core:

1. the conversion of the capture (convert_stream_recorder: PGM decoding, PNG encoding, the manifest);
2. track_recording on the converted folder against track_recording on our own folder of the same frames (.npy
   frames, as the conversion writes them), timed alternately (median of the repeats), and their ratio (target: 1);
   and on our folder with 16-bit PNG frames (RecordingWriter's default), where PNG decoding dominates;
3. detection + correspondence + Kabsch on the same frames in memory (detect_match_kabsch, the bound that
   benchmarks/bench_tracking.py holds to >= 300 frames/s): what the replay adds is PNG decoding and the filter.

Run: .venv/bin/python benchmarks/bench_hl2_replay.py [n_frames] (from the repository root)
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core
os.environ.setdefault("OMP_NUM_THREADS", "1")

import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the recorders' test writers

from poseintegrity.config import load_section  # noqa: E402
from poseintegrity.tracking.experiments.compute_time import detect_match_kabsch  # noqa: E402
from poseintegrity.tracking.filter.recording_replay import track_recording  # noqa: E402
from poseintegrity.tracking.io.hl2_recordings import convert_stream_recorder  # noqa: E402
from poseintegrity.tracking.io.recording import RecordingWriter, read_recording  # noqa: E402
from poseintegrity.tracking.simulation.frames import intrinsics  # noqa: E402
from tracking.hl2_writers import simulated_frames, write_stream_recorder  # noqa: E402

cv2.setNumThreads(1)


def frames_per_s(fn, n_frames: int) -> float:
    start = time.perf_counter()
    fn()
    return n_frames / (time.perf_counter() - start)


def main(n_frames: int = 300, repeats: int = 3) -> None:
    params = load_section(ROOT / "params.yaml", "track")
    geometry = np.array(params.markers_body)
    lut, frames = simulated_frames(params, n_frames)
    n_frames = len(frames)
    tools = {"probe": geometry}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        capture = write_stream_recorder(tmp / "capture", lut, frames)
        for frame_format in ("npy", "png"):
            with RecordingWriter(tmp / f"own_{frame_format}", lut, frame_format=frame_format) as writer:
                for ticks, ir, depth in frames:
                    writer.add_frame((ticks - frames[0][0]) / 1e7, ir, depth)
                writer.close()
        convert_fps = frames_per_s(lambda: convert_stream_recorder(capture, tmp / "converted"), n_frames)  # .npy frames
        recordings = {name: read_recording(tmp / name) for name in ("converted", "own_npy", "own_png")}
        tables, rates = {}, {name: [] for name in recordings}
        for _ in range(repeats):  # alternately, so that all see the same machine load
            for name, recording in recordings.items():
                rates[name].append(frames_per_s(lambda r=recording, n=name: tables.__setitem__(n, track_recording(r, tools, params)), n_frames))
    K = intrinsics(params.camera)
    chain_fps = frames_per_s(lambda: [detect_match_kabsch(ir, depth, K, params, geometry) for _, ir, depth in frames], n_frames)
    same = tables["converted"].flag.equals(tables["own_npy"].flag)
    diff = np.nanmax(np.abs(tables["converted"][["x_mm", "y_mm", "z_mm"]].to_numpy() - tables["own_npy"][["x_mm", "y_mm", "z_mm"]].to_numpy()))
    fps = {name: statistics.median(values) for name, values in rates.items()}
    print(f"{n_frames} simulated AHAT frames (512 x 512), one core, median of {repeats} alternating runs")
    print(f"  convert_stream_recorder (PGM -> our layout, .npy frames)  {convert_fps:8.0f} frames/s")
    print(f"  replay of the converted recording                         {fps['converted']:8.0f} frames/s")
    print(f"  replay of the same frames in our layout (.npy)            {fps['own_npy']:8.0f} frames/s")
    print(f"  ratio converted / own                                     {fps['converted'] / fps['own_npy']:8.2f}")
    print(f"  replay of the same frames in our layout (16-bit PNG)      {fps['own_png']:8.0f} frames/s")
    print(f"  detection + matching + Kabsch in memory                   {chain_fps:8.0f} frames/s (bench_tracking: >= 300)")
    print(f"  same flags {same}, largest position difference {diff:.2e} mm (float32 lookup table)")

if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
