"""Speed of the marker-tracking library, as ratios against references measured in the same run.

1. One SR-UKF predict + update (4 markers + gyro) against filterpy's UnscentedKalmanFilter on the same
   model (eq. 10 per sigma point with the SVD Kabsch of Alg. 4), target >= 10x, and against pykalman's
   square-root UKF (pykalman.sqrt.AdditiveUnscentedKalmanFilter.filter_update) on the additive-noise model.
2. Detection + correspondence + Kabsch on one 512 x 512 frame (4 markers, one round phantom), in frames
   per second on one core, beside a bare OpenCV threshold + findContours on the same frame.  Target: >= 300.
3. Frame synthesis (render_frame, the same frame) against drawing its IR sensor noise alone (512 x 512 float32
   normals), the floor of any synthesis that draws this noise: stage 06 renders ~90 000 frames, and after the
   in-place IR and whole-millimetre depth (same bits) the noise draw is most of a frame.
4. A whole filter run (run_filter over a simulated recording with gyro, the stage-06 workload) against the same
   run with the SR-UKF computed one numpy / LAPACK call per step (benchmarks/srukf_reference.py, the
   implementation before the fused kernels), and the same run with the plain covariance-form UKF; the largest
   position difference of the two SR-UKF runs (rounding only) and whether their flags are identical.

Run: .venv/bin/python benchmarks/bench_tracking.py (from the repository root)
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core, and no thread start-up in tiny BLAS calls
os.environ.setdefault("OMP_NUM_THREADS", "1")

import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from poseintegrity.config import load_section  # noqa: E402
from poseintegrity.tracking.evaluation import detect_match_kabsch  # noqa: E402
from poseintegrity.tracking.frames import draw_phantoms, intrinsics, render_frame  # noqa: E402
from poseintegrity.tracking.geometry import MARKER_DIAMETER_M  # noqa: E402
from poseintegrity.tracking.peers import filter_speed  # noqa: E402
from poseintegrity.tracking.simulation import run_filter, simulate  # noqa: E402
from poseintegrity.tracking.srukf import SquareRootUKF  # noqa: E402
from poseintegrity.tracking.ukf import UnscentedKalmanFilter  # noqa: E402
from srukf_reference import StepwiseSquareRootUKF  # noqa: E402

RUN_DURATION_S = 20.0  # a third of the accuracy recording; a run costs the same per second of recording


def per_call_ms(fn, repeats):
    fn()
    start = time.perf_counter()
    for _ in range(repeats):
        fn()
    return (time.perf_counter() - start) / repeats * 1000.0


def main():
    cv2.setNumThreads(1)
    rng = np.random.default_rng(0)
    params = load_section(Path(__file__).resolve().parents[1] / "params.yaml", "track")
    geometry = np.array(params.markers_body)
    speed = filter_speed(geometry, params.filter, 400, rng)
    print("filter predict + update (4 markers + gyro, params.yaml constants)")
    for name in ("srukf", "ukf", "filterpy", "pykalman"):
        print(f"  {name:9s} {speed[name]:8.3f} ms")
    print(f"  SR-UKF speed-up over filterpy: {speed['speedup_vs_filterpy']:.1f}x (target >= 10x)")
    print(f"  SR-UKF speed-up over pykalman: {speed['speedup_vs_pykalman']:.1f}x")

    K = intrinsics(params.camera)
    markers = geometry + [0.02, -0.01, 0.45]
    ir, depth = render_frame(markers, draw_phantoms(1, params.camera, params.frames, 1.0, rng), params.camera, params.frames, MARKER_DIAMETER_M / 2, rng)
    assert np.isfinite(detect_match_kabsch(ir, depth, K, params, geometry)).all()
    chain = per_call_ms(lambda: detect_match_kabsch(ir, depth, K, params, geometry), 500)
    raw_threshold = params.detection.threshold * params.detection.ir_clip / 255.0
    bare = per_call_ms(lambda: cv2.findContours(cv2.compare(ir, raw_threshold, cv2.CMP_GT), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE), 500)
    print("detection + correspondence + Kabsch, one 512 x 512 frame")
    print(f"  full chain        {chain:8.3f} ms = {1000 / chain:7.0f} frames/s (target >= 300)")
    print(f"  threshold+contours{bare:8.3f} ms = {1000 / bare:7.0f} frames/s (reference); chain / reference = {chain / bare:.1f}")

    phantoms = draw_phantoms(1, params.camera, params.frames, 1.0, rng)
    synthesis = per_call_ms(lambda: render_frame(markers, phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng), 300)
    shape = (params.camera.height, params.camera.width)
    noise = per_call_ms(lambda: rng.standard_normal(shape, dtype=np.float32), 300)
    print("frame synthesis, one 512 x 512 IR + depth frame (4 markers, one round phantom)")
    print(f"  render_frame      {synthesis:8.3f} ms; its IR noise draw alone {noise:8.3f} ms; synthesis / noise = {synthesis / noise:.2f} (floor 1)")

    [sim] = simulate(params, np.random.default_rng(7), duration_s=RUN_DURATION_S)
    run_filter(sim, params, use_gyro=True)  # compile
    runs, seconds = {}, {}
    for name, cls in [("fused kernels", SquareRootUKF), ("stepwise SR-UKF", StepwiseSquareRootUKF), ("plain UKF", UnscentedKalmanFilter)]:
        start = time.perf_counter()
        runs[name], _ = run_filter(sim, params, use_gyro=True, filter_cls=cls)
        seconds[name] = time.perf_counter() - start
    fused, stepwise = runs["fused kernels"], runs["stepwise SR-UKF"]
    print(f"whole filter run, {RUN_DURATION_S:.0f} s recording with gyro ({len(fused)} events, {RUN_DURATION_S / params.filter.dt:.0f} filter steps)")
    for name in runs:
        print(f"  {name:16s} {seconds[name]:7.2f} s   run / fused = {seconds[name] / seconds['fused kernels']:5.1f}")
    diff = np.nanmax(np.abs(fused[["x_mm", "y_mm", "z_mm"]].to_numpy() - stepwise[["x_mm", "y_mm", "z_mm"]].to_numpy()))
    print(f"  fused vs stepwise: max |position difference| {diff:.2e} mm, flags identical: {fused.flag.equals(stepwise.flag)}")


if __name__ == "__main__":
    main()
