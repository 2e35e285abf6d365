"""What the AVX2 pin (poseintegrity.dispatch) costs: CLAHE + SIFT per stage-02 frame, pinned against the libraries'
own choice (POSEINTEGRITY_CPU_DISPATCH=native), each in a fresh process (the libraries read the setting when they
load), interleaved in pairs in one run. Also one level lower (native with OPENCV_CPU_DISABLE=AVX2: AVX), the cost of a
level on this machine, and the SIFT hash of each setting (the same frames give the same hash when the level is the
same).

    .venv/bin/python benchmarks/bench_dispatch.py [--data-dir data] [--frames 30] [--rounds 3]

On a CPU without AVX-512 the pin disables nothing of OpenCV, and pinned / native is ~1 by construction.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from bench_malloc import TUNED, frame_files  # noqa: E402

SETTINGS = {
    "pinned": {"POSEINTEGRITY_CPU_DISPATCH": "pinned"},
    "native": {"POSEINTEGRITY_CPU_DISPATCH": "native", "OPENCV_CPU_DISABLE": ""},
    "native, AVX2 off": {"POSEINTEGRITY_CPU_DISPATCH": "native", "OPENCV_CPU_DISABLE": "AVX2"},
}

CHILD = """
import hashlib, json, sys, time
import cv2
from poseintegrity.config import load_section
from poseintegrity.localization.features import detect_features, read_gray
params = load_section(sys.argv[1], "extract")
images = [read_gray(f) for f in json.loads(sys.argv[2])]
digest = hashlib.sha256()
start = time.process_time()
for image in images:
    features = detect_features(image, params.clahe, params.sift)
    digest.update(features.points.tobytes() + features.descriptors.tobytes())
cpu = time.process_time() - start
print(json.dumps(dict(cpu=cpu / len(images), hash=digest.hexdigest()[:16], features=cv2.getCPUFeaturesLine())))
"""


def run(setting: dict, params: str, files: list[str]) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "OPENCV_CPU_DISABLE"} | TUNED | setting
    out = subprocess.run([sys.executable, "-c", CHILD, params, json.dumps(files)], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-dir", default="data", type=Path)
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument("--frames", type=int, default=30)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    files = frame_files(args.data_dir, args.frames)
    results: dict[str, list[dict]] = {name: [] for name in SETTINGS}
    for _ in range(args.rounds):  # interleaved: the machine is shared and noisy
        for name, setting in SETTINGS.items():
            results[name].append(run(setting, args.params, files))
    for name, rows in results.items():
        print(f"{name:17s} CPU {np.median([r['cpu'] for r in rows]) * 1e3:6.1f} ms/frame, SIFT hash "
              f"{rows[0]['hash']}, OpenCV: {rows[0]['features']}")
    for name in ("native", "native, AVX2 off"):
        ratio = np.median([p["cpu"] / n["cpu"] for p, n in zip(results["pinned"], results[name])])
        print(f"pinned / {name}: {ratio:.3f} (paired median of {args.rounds})")


if __name__ == "__main__":
    main()
