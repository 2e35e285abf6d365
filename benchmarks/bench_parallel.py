"""Dask LocalCluster (2 workers) vs the local backend (2 loky processes) on the same per-frame work, in one run.

Issue 13's figure "Dask LocalCluster with 2 workers vs local backend on stage 02 tiny (ratio)". Per frame, stage
02's floor: read the image, CLAHE + SIFT, a digest of the descriptors; over every frame of the datasets in
--data-dir (stage 01 output). Each measurement is a fresh process, as each stage is a fresh kernel, and times
- "start": opening the workers and the first map over all frames (what a stage pays: a LocalCluster starts its
  processes on opening, loky in the first map);
- "warm": a second map over the same frames on the same workers (the per-task cost once running).
Backends alternate over --rounds rounds (the machine is shared); the results of both must be identical. Run it
with the Makefile's malloc settings (as below): without them, Dask's workers default to MALLOC_TRIM_THRESHOLD_=65536
and SIFT pays its page faults again (benchmarks/bench_malloc.py), which is not what `make repro` sees.

    .venv/bin/python -m poseintegrity.stage notebooks/01_generate_datasets.ipynb --params tests/params_tiny.yaml \\
        --data /tmp/tiny/data --reports /tmp/tiny/reports          # stage 01 tiny, if there is no data yet
    MALLOC_MMAP_THRESHOLD_=33554432 MALLOC_TRIM_THRESHOLD_=1073741824 \\
        .venv/bin/python benchmarks/bench_parallel.py --data-dir /tmp/tiny/data [--rounds 3]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from poseintegrity.localization.dataset import load_dataset, load_index
from poseintegrity.localization.features import detect_features, read_gray
from poseintegrity.localization.params import ExtractParams
from poseintegrity.parallel import ParallelParams, Workers

BACKENDS = {"local": ParallelParams(backend="local", n_jobs=2), "dask": ParallelParams(backend="dask", n_jobs=2)}


def sift_frame(path: str) -> str:
    """Stage 02's per-frame floor for one image file: CLAHE + SIFT; the digest of its keypoints and descriptors."""
    params = ExtractParams()
    features = detect_features(read_gray(path), params.clahe, params.sift)
    return hashlib.sha256(features.points.tobytes() + features.descriptors.tobytes()).hexdigest()


def frame_files(data_dir: Path) -> list[str]:
    """Every frame image of every dataset of ``data_dir``."""
    index = load_index(data_dir)
    files = []
    for folder in index["path"]:
        dataset = load_dataset(data_dir, folder)
        files += [str(dataset.path(name)) for name in dataset.frames["file"]]
    return files


def measure(backend: str, data_dir: Path) -> dict:
    """One backend in this process: seconds of start (open + first map) and of a warm map, the results' digest."""
    files = frame_files(data_dir)
    start = time.perf_counter()
    with Workers(BACKENDS[backend]) as workers:
        digests = workers.map(sift_frame, files, progress=False)
        started = time.perf_counter()
        workers.map(sift_frame, files, progress=False)
        warm = time.perf_counter()
    return {"start_s": started - start, "warm_s": warm - started, "frames": len(files),
            "digest": hashlib.sha256("".join(digests).encode()).hexdigest()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-dir", type=Path, default=Path("data"))
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--measure", choices=sorted(BACKENDS), help=argparse.SUPPRESS)  # the child process
    args = parser.parse_args()
    if args.measure:
        print(json.dumps(measure(args.measure, args.data_dir)))
        return
    runs = {backend: [] for backend in BACKENDS}
    for _ in range(args.rounds):
        for backend in BACKENDS:
            child = [sys.executable, __file__, "--measure", backend, "--data-dir", str(args.data_dir)]
            output = subprocess.run(child, check=True, capture_output=True, text=True).stdout
            runs[backend].append(json.loads(output.strip().splitlines()[-1]))
    assert len({run["digest"] for rows in runs.values() for run in rows}) == 1, "backends disagree"
    print(f"{runs['local'][0]['frames']} frames of {args.data_dir}, {args.rounds} rounds, identical results")
    for backend, rows in runs.items():
        print(f"{backend:5s} start {np.median([run['start_s'] for run in rows]):6.2f} s   "
              f"warm {np.median([run['warm_s'] for run in rows]):6.2f} s   (medians)")
    pairs = list(zip(runs["dask"], runs["local"]))  # same round: same machine load
    for key in ("start_s", "warm_s"):
        ratio = np.median([dask[key] / local[key] for dask, local in pairs])
        print(f"dask LocalCluster / local wall time, {key[:-2]}: {ratio:.2f}")

if __name__ == "__main__":
    main()
