"""Why every worker task runs with one OpenCV thread (:func:`poseintegrity.workers.run_single_threaded`): stage 02's
CLAHE + SIFT on two worker processes (one per core, as ``parallel.n_jobs: 2`` gives), each with OpenCV's default
thread pool (one thread per core) vs with one thread, in one run.

joblib and Dask limit the BLAS/OpenMP threads of their workers, not OpenCV's own pthreads pool, so without the limit
two workers start four SIFT threads on two cores. Prints seconds per frame of each setting (rounds alternate; the
machine is shared) and their ratio.

    MALLOC_MMAP_THRESHOLD_=33554432 MALLOC_TRIM_THRESHOLD_=1073741824 \\
        .venv/bin/python benchmarks/bench_opencv_threads.py [--data-dir data] [--frames 16] [--rounds 3]
"""

from __future__ import annotations

import argparse
import time
from multiprocessing import get_context

import cv2
import numpy as np

from poseintegrity.config import load_section
from poseintegrity.localization.dataset import load_dataset, load_index
from poseintegrity.localization.features import detect_features, read_gray


def sift_frames(threads: int | None, files: list[str], params_path: str) -> None:
    """CLAHE + SIFT on every file, with ``threads`` OpenCV threads (None: OpenCV's default)."""
    if threads is not None:
        cv2.setNumThreads(threads)
    params = load_section(params_path, "extract")
    for file in files:
        detect_features(read_gray(file), params.clahe, params.sift)


def seconds_per_frame(threads: int | None, files: list[str], params_path: str, workers: int) -> float:
    """Wall seconds per frame of ``workers`` fresh processes sharing ``files``."""
    chunks = [files[i::workers] for i in range(workers)]
    with get_context("spawn").Pool(workers) as pool:
        pool.starmap(sift_frames, [(threads, chunk[:1], params_path) for chunk in chunks])  # imports, first frame
        start = time.perf_counter()
        pool.starmap(sift_frames, [(threads, chunk, params_path) for chunk in chunks])
        return (time.perf_counter() - start) / len(files)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-dir", default="data")
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument("--frames", type=int, default=16)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    row = load_index(args.data_dir).iloc[0]
    dataset = load_dataset(args.data_dir, row.path, row.dataset)
    files = [str(dataset.path(name)) for name in dataset.frames["file"].iloc[: args.frames]]
    times: dict[str, list[float]] = {"default": [], "one": []}
    for _ in range(args.rounds):
        times["default"].append(seconds_per_frame(None, files, args.params, args.workers))
        times["one"].append(seconds_per_frame(1, files, args.params, args.workers))
    default, one = np.median(times["default"]), np.median(times["one"])
    print(f"{args.workers} workers, {len(files)} frames of {row.dataset}, median of {args.rounds} rounds")
    print(f"  OpenCV default threads ({cv2.getNumThreads()} per worker): {default:.3f} s/frame")
    print(f"  one OpenCV thread per worker:            {one:.3f} s/frame")
    print(f"  default / one = {default / one:.2f}")


if __name__ == "__main__":
    main()
