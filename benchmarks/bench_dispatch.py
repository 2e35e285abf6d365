"""What the kernel pin (poseintegrity.kernel_pin: every library capped at AVX2, OpenBLAS on its Haswell kernels) costs,
on the two per-frame costs of the pipeline: rendering a stage-01 frame (the renderer's compiled kernels, the lens'
blur, the sensor) and CLAHE + SIFT on it (stage 02). Each setting runs in a fresh process (the libraries read the
setting when they load; the process imports poseintegrity before any of them), one thread, the settings interleaved
in rounds in one run; per setting the median CPU time per frame, the hashes of its images and of its SIFT output
(the same kernels give the same hashes), the OpenCV features line and OpenBLAS's kernel set; then the ratios against
the pinned row, paired per round.

    .venv/bin/python benchmarks/bench_dispatch.py [--frames 12] [--rounds 3]

Rows: pinned; native (every library's own choice, POSEINTEGRITY_CPU_DISPATCH=native); native with OpenCV's AVX2
group off (AVX: the cost of one level lower). Each child starts from the environment this script was started with,
less every variable the pin sets, so that no setting inherits another's. On a CPU without AVX-512 the pin disables
nothing of OpenCV and numpy, and pinned / native differs by OpenBLAS's kernel set alone.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

from poseintegrity.kernel_pin import FIXED, SWITCH  # before numpy, as everywhere (this process only starts the rows)

import numpy as np

PIN = (SWITCH, "OPENCV_CPU_DISABLE", "OPENBLAS_CORETYPE", *FIXED)  # what the pin sets, and its switch
SETTINGS = {
    "pinned": {},
    "native": {"POSEINTEGRITY_CPU_DISPATCH": "native"},
    "native, AVX2 off": {"POSEINTEGRITY_CPU_DISPATCH": "native", "OPENCV_CPU_DISABLE": "AVX2"},
}
TUNED = {"MALLOC_MMAP_THRESHOLD_": "33554432", "MALLOC_TRIM_THRESHOLD_": "1073741824"}  # as in the Makefile

CHILD = """
import poseintegrity  # first: the pin (or not) before numpy, OpenBLAS, OpenCV or numba load
import hashlib, json, sys, time
import cv2
import numpy as np
from poseintegrity.config import load_params
from poseintegrity.kernel_pin import openblas_cores
from poseintegrity.localization.features import detect_features
from poseintegrity.poses import inverse
from poseintegrity.scenes import optics, renderer, trajectories, world_cache
from poseintegrity.scenes.camera import true_camera
from poseintegrity.seeding import keyed_rng

cv2.setNumThreads(1)
everything = load_params(sys.argv[1])
params, protocol, extract = everything.generate, everything.protocol, everything.extract
world = world_cache.world(params, protocol, 0, "arc")
spec = params.scenes[0]
T_model = trajectories.model_pair(world.scene.aim, world.scene.view_dir, spec.distance_mm, params.model_baseline_mm)[0]
stops = trajectories.arc(T_model, world.scene.aim, params.arcs.azimuths_deg[0], protocol.arc_span_deg, int(sys.argv[2]))
lens = true_camera(params.camera)
K_canvas, width, height = lens.canvas


def shoot(stop):  # one image of a stop, as stage 01 takes it (without the ring-down's turn)
    frame = renderer.render(world.geometry, K_canvas, width, height, inverse(stop.T_world_cam))
    irradiance = optics.lens(frame.radiance, frame.depth_mm, spec.distance_mm, params.sensor.blur_sigma_px,
                             params.camera)
    sensor = cv2.remap(irradiance, *lens.sensor_maps, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return renderer.expose(sensor, params.sensor, keyed_rng(params.seed, "bench", round(stop.theta_deg * 1000)))


shoot(stops[0])  # numba's kernels compiled or loaded from its cache, outside the timing
start = time.process_time()
images = [shoot(stop) for stop in stops]
render = (time.process_time() - start) / len(images)
start = time.process_time()
features = [detect_features(image, extract.clahe, extract.sift) for image in images]
sift = (time.process_time() - start) / len(images)
image_hash = hashlib.sha256(b"".join(image.tobytes() for image in images)).hexdigest()[:12]
sift_hash = hashlib.sha256(b"".join(f.points.tobytes() + f.descriptors.tobytes() for f in features)).hexdigest()[:12]
print(json.dumps(dict(render=render, sift=sift, image_hash=image_hash, sift_hash=sift_hash,
                      opencv=cv2.getCPUFeaturesLine(), openblas=sorted(set(openblas_cores().values())))))
"""


def run(setting: dict, params: str, frames: int) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in PIN} | TUNED | setting
    out = subprocess.run([sys.executable, "-c", CHILD, params, str(frames)], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument("--frames", type=int, default=12, help="views along scene 0's first arc")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    results: dict[str, list[dict]] = {name: [] for name in SETTINGS}
    for _ in range(args.rounds):  # interleaved: the machine is shared and noisy
        for name, setting in SETTINGS.items():
            results[name].append(run(setting, args.params, args.frames))
    for name, rows in results.items():
        first = rows[0]
        same = all((r["image_hash"], r["sift_hash"]) == (first["image_hash"], first["sift_hash"]) for r in rows)
        print(f"{name:17s} CPU per frame: render {np.median([r['render'] for r in rows]) * 1e3:6.1f} ms, CLAHE + SIFT "
              f"{np.median([r['sift'] for r in rows]) * 1e3:6.1f} ms; images {first['image_hash']}, SIFT "
              f"{first['sift_hash']} ({'the same' if same else 'NOT the same'} in every round); OpenBLAS "
              f"{', '.join(first['openblas'])}; OpenCV: {first['opencv']}")
    for name in list(SETTINGS)[1:]:
        for part in ("render", "sift"):
            ratio = np.median([p[part] / n[part] for p, n in zip(results["pinned"], results[name])])
            print(f"pinned / {name}, {part}: {ratio:.3f} (paired median of {args.rounds})")


if __name__ == "__main__":
    main()
