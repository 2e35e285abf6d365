"""Per-frame and per-step cost of the tracking hot paths, for comparing two versions of the package (before and after
the boundary checks of docs/errors.md) in one paired run.

Prints one line per path, microseconds per call (median of 7 repeats after a warm-up):
1. detection + correspondence + Kabsch on one 512 x 512 frame (4 markers, one phantom): the no-filter chain of
   stage 06 (``evaluation.detect_match_kabsch``);
2. one SR-UKF step through the public methods (``predict(dt)`` + ``update(z, observed, gyro=False)``, 4 markers);
3. one ``MarkerTracker.frame`` on measured points (matching + SR-UKF), the per-frame call a user makes.

Run both versions alternately and take the ratio of their medians, e.g. with a worktree of the old commit at
/tmp/base:

    for i in 1 2 3 4 5; do
      .venv/bin/python benchmarks/bench_boundary_checks.py >> /tmp/new.txt
      PYTHONPATH=/tmp/base/src .venv/bin/python benchmarks/bench_boundary_checks.py >> /tmp/old.txt
    done
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

import poseintegrity  # noqa: E402
from poseintegrity.config import load_section  # noqa: E402
from poseintegrity.tracking.experiments.compute_time import detect_match_kabsch  # noqa: E402
from poseintegrity.tracking.filter.srukf import SquareRootUKF  # noqa: E402
from poseintegrity.tracking.filter.tracker import MarkerTracker  # noqa: E402
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M, transform_points  # noqa: E402
from poseintegrity.tracking.simulation.frames import draw_phantoms, intrinsics, render_frame  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def per_call_us(function, calls: int) -> float:
    """Median over 7 repeats of the time per call of function(), microseconds."""
    function()
    times = []
    for _ in range(7):
        start = time.perf_counter()
        for _ in range(calls):
            function()
        times.append((time.perf_counter() - start) / calls * 1e6)
    return float(np.median(times))


def main() -> None:
    track = load_section(ROOT / "params.yaml", "track")
    geometry = np.array(track.markers_body)
    rng = np.random.default_rng(0)
    R = Rotation.from_rotvec([0.3, 0.2, 0.1]).as_matrix()
    markers = geometry @ R.T + [0.02, -0.01, 0.45]
    phantoms = draw_phantoms(1, track.camera, track.frames, 1.0, rng)
    ir, depth = render_frame(markers, phantoms, track.camera, track.frames, MARKER_DIAMETER_M / 2, rng)
    K = intrinsics(track.camera)
    chain = per_call_us(lambda: detect_match_kabsch(ir, depth, K, track, geometry), 100)

    srukf = SquareRootUKF(geometry, track.filter)
    srukf.initialize(markers)
    z, observed = markers.ravel().copy(), np.ones(len(geometry), dtype=bool)

    def step():
        srukf.predict(0.0025)
        srukf.update(z, observed, False)

    filter_step = per_call_us(step, 2000)

    tracker = MarkerTracker(geometry, track.filter, track.matching, use_gyro=False)
    frames = [transform_points(np.eye(4), markers) + rng.normal(0, 0.0005, markers.shape) for _ in range(50)]
    clock = iter(np.arange(1_000_000) * 0.011)

    def frame():
        for points in frames:
            tracker.frame(float(next(clock)), points)

    tracker_frame = per_call_us(frame, 20) / len(frames)
    print(f"{poseintegrity.__file__}\ndetect+match+kabsch_us {chain:.2f}\nsrukf_step_us {filter_step:.3f}\n"
          f"tracker_frame_us {tracker_frame:.2f}", flush=True)


if __name__ == "__main__":
    main()
