"""Why the Makefile exports MALLOC_MMAP_THRESHOLD_ / MALLOC_TRIM_THRESHOLD_: CLAHE + SIFT per frame with glibc's
default malloc settings vs the Makefile's, each in a fresh process (glibc reads them at start-up), in one run.

By default glibc serves SIFT's large scale-space buffers with mmap and unmaps them on free, so every frame
page-faults ~100 MB in again (system time). The tuned settings keep freed memory for reuse.

    .venv/bin/python benchmarks/bench_malloc.py [--data-dir data] [--frames 40] [--rounds 3]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from poseintegrity.localization.dataset import load_dataset, load_index

TUNED = {"MALLOC_MMAP_THRESHOLD_": "33554432", "MALLOC_TRIM_THRESHOLD_": "1073741824"}  # as in the Makefile

CHILD = """
import json, resource, sys, time
from poseintegrity.config import load_section
from poseintegrity.localization.features import detect_features, read_gray
params = load_section(sys.argv[1], "extract")
files = json.loads(sys.argv[2])
images = [read_gray(f) for f in files]
before, start = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
for image in images:
    detect_features(image, params.clahe, params.sift)
wall, after = time.perf_counter() - start, resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps(dict(wall=wall / len(images), sys=(after.ru_stime - before.ru_stime) / len(images),
                      faults=(after.ru_minflt - before.ru_minflt) / len(images))))
"""


def frame_files(data_dir: Path, n_frames: int) -> list[str]:
    """n_frames images spread over the first arc dataset of data_dir (stage 01 output)."""
    index = load_index(data_dir)
    dataset = load_dataset(data_dir, index[index["trajectory"] == "arc"].iloc[0]["path"])
    files = dataset.frames["file"].to_numpy()
    return [str(dataset.path(f)) for f in files[np.linspace(0, len(files) - 1, n_frames).astype(int)]]


def run(env_extra: dict, params: str, files: list[str]) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")} | env_extra
    out = subprocess.run([sys.executable, "-c", CHILD, params, json.dumps(files)], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-dir", default="data", type=Path)
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument("--frames", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    files = frame_files(args.data_dir, args.frames)
    results = {"default": [], "tuned": []}
    for _ in range(args.rounds):  # interleaved: the machine is shared and noisy
        results["default"].append(run({}, args.params, files))
        results["tuned"].append(run(TUNED, args.params, files))
    for name, rows in results.items():
        print(f"{name:8s} wall {np.median([r['wall'] for r in rows]) * 1e3:6.1f} ms/frame, "
              f"system {np.median([r['sys'] for r in rows]) * 1e3:5.1f} ms/frame, "
              f"page faults {np.median([r['faults'] for r in rows]):8.0f}/frame")
    ratio = np.median([t["wall"] / d["wall"] for d, t in zip(results["default"], results["tuned"])])
    print(f"tuned / default wall time per frame: {ratio:.2f}")


if __name__ == "__main__":
    main()
