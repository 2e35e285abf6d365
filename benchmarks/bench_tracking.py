"""Speed of the marker-tracking library, as ratios against references measured in the same run.

1. One SR-UKF predict + update (4 markers + gyro) against filterpy's UnscentedKalmanFilter on the same
   model (eq. 10 per sigma point with the SVD Kabsch of Alg. 4), target >= 10x, and against pykalman's
   square-root UKF (pykalman.sqrt.AdditiveUnscentedKalmanFilter.filter_update) on the additive-noise model.
2. Detection + correspondence + Kabsch on one 512 x 512 frame (4 markers, one round phantom), in frames
   per second on one core, beside a bare OpenCV threshold + findContours on the same frame.  Target: >= 300.
3. Frame synthesis (render_frame, the same frame; stage 06 renders ~80 000) against the previous synthesis
   (:func:`reference_render_frame` below: numpy ray casting and a float32 normal drawn for every pixel, the
   same depth and reflections to the bit, and the same distribution of the IR noise), and against its former
   floor, drawing the 512 x 512 float32 normals alone.
5. The argument checks of the public entry points (kabsch, the filter's predict_steps / update, the tracker's
   frame): each checked call against its unchecked inner call on the same input, timed alternately in this run
   (paired medians), as a ratio; the hot paths (run_filter, detect_match_kabsch, correspondence) call the inner ones.
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
from poseintegrity.tracking.experiments.study import detect_match_kabsch  # noqa: E402
from poseintegrity.tracking.simulation.frames import draw_phantoms, intrinsics, render_frame  # noqa: E402
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M  # noqa: E402
from poseintegrity.tracking.experiments.peers import filter_speed  # noqa: E402
from poseintegrity.tracking.simulation.simulate import run_filter, simulate  # noqa: E402
from poseintegrity.tracking.filter.srukf import SquareRootUKF  # noqa: E402
from poseintegrity.tracking.filter.ukf import UnscentedKalmanFilter  # noqa: E402
from poseintegrity.tracking.markers.kabsch import kabsch, kabsch_unchecked  # noqa: E402
from poseintegrity.tracking.filter.tracker import MarkerTracker  # noqa: E402
from srukf_reference import StepwiseSquareRootUKF  # noqa: E402
from timing import paired_medians  # noqa: E402

RUN_DURATION_S = 20.0  # a third of the accuracy recording; a run costs the same per second of recording


def reference_render_frame(markers_cam, phantoms, camera, frames, marker_radius_m, rng):
    """The previous render_frame: per-patch numpy ray casting and IR noise drawn as a float32 normal per pixel."""
    H, W, s = camera.height, camera.width, frames.supersampling
    K = intrinsics(camera)
    offsets = (np.arange(s) + 0.5) / s - 0.5
    du, dv = (g.ravel() for g in np.meshgrid(offsets, offsets))

    def grid(u0, v0, u1, v1):
        return np.broadcast_arrays(np.arange(u0, u1, dtype=float)[None, :, None] + du, np.arange(v0, v1, dtype=float)[:, None, None] + dv)

    def to_mm(x):
        return np.clip(np.rint(x), 0, 65535).astype(np.uint16)

    brightness = np.zeros((H, W), dtype=np.float32)
    depth = np.full((H, W), to_mm(frames.background_depth_mm), dtype=np.uint16)
    frame_bias = rng.normal(0.0, frames.frame_depth_bias_std_mm)
    for c in markers_cam[np.argsort(-markers_cam[:, 2])]:
        u_c, v_c = K[0, 0] * c[0] / c[2] + K[0, 2], K[1, 1] * c[1] / c[2] + K[1, 2]
        rho = camera.focal_px * marker_radius_m / np.sqrt(c[2] ** 2 - marker_radius_m**2) + 2.0
        u0, u1, v0, v1 = max(int(u_c - rho), 0), min(int(u_c + rho) + 2, W), max(int(v_c - rho), 0), min(int(v_c + rho) + 2, H)
        uu, vv = grid(u0, v0, u1, v1)
        rays = np.stack([(uu - K[0, 2]) / K[0, 0], (vv - K[1, 2]) / K[1, 1], np.ones_like(uu)], axis=-1)
        rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
        proj = rays @ c
        disc = marker_radius_m**2 - (c @ c - proj**2)
        hit = disc > 0
        near = np.where(hit, (proj - np.sqrt(np.where(hit, disc, 0.0))) * 1000.0, np.inf).min(axis=-1)
        cover = hit.mean(axis=-1)
        bias = frame_bias + rng.normal(0.0, frames.depth_bias_std_mm)
        noisy = to_mm(near + bias + rng.normal(0.0, frames.depth_noise_mm, near.shape))
        patch = (slice(v0, v1), slice(u0, u1))
        depth[patch] = np.where(cover > 0, np.minimum(depth[patch], noisy), depth[patch])
        brightness[patch] = np.maximum(brightness[patch], (frames.marker_ir + rng.normal(0.0, frames.marker_ir_std)) * cover)
    for p in phantoms:
        extent = p.radius_px * p.elongation + 2.0
        u0, u1 = max(int(p.u - extent), 0), min(int(p.u + extent) + 2, W)
        v0, v1 = max(int(p.v - extent), 0), min(int(p.v + extent) + 2, H)
        uu, vv = grid(u0, v0, u1, v1)
        a = ((uu - p.u) * np.cos(p.angle) + (vv - p.v) * np.sin(p.angle)) / (p.radius_px * p.elongation)
        b = (-(uu - p.u) * np.sin(p.angle) + (vv - p.v) * np.cos(p.angle)) / p.radius_px
        cover = (a * a + b * b <= 1.0).mean(axis=-1)
        patch = (slice(v0, v1), slice(u0, u1))
        noisy = to_mm(p.depth_mm + rng.normal(0.0, frames.depth_noise_mm, cover.shape))
        depth[patch] = np.where(cover > 0, np.minimum(depth[patch], noisy), depth[patch])
        brightness[patch] = np.maximum(brightness[patch], (frames.marker_ir + rng.normal(0.0, frames.marker_ir_std)) * cover)
    ir = rng.standard_normal((H, W), dtype=np.float32)
    ir *= np.float32(frames.ir_noise_std)
    ir += np.float32(frames.ir_background)
    ir += brightness
    return np.clip(np.rint(ir, out=ir), 0, 65535, out=ir).astype(np.uint16), depth


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
    args = (markers, phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2)
    (_, depth), (_, ref_depth) = render_frame(*args, np.random.default_rng(1)), reference_render_frame(*args, np.random.default_rng(1))
    assert np.array_equal(depth, ref_depth)  # the same draws in the same order up to the IR noise
    synthesis = per_call_ms(lambda: render_frame(*args, rng), 300)
    reference = per_call_ms(lambda: reference_render_frame(*args, rng), 300)
    shape = (params.camera.height, params.camera.width)
    noise = per_call_ms(lambda: rng.standard_normal(shape, dtype=np.float32), 300)
    print("frame synthesis, one 512 x 512 IR + depth frame (4 markers, one round phantom)")
    print(f"  render_frame      {synthesis:8.3f} ms; previous synthesis {reference:8.3f} ms: {reference / synthesis:.1f}x faster")
    print(f"  float32 normals for every pixel alone {noise:8.3f} ms = {noise / synthesis:.1f} x render_frame")

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

    check_overhead(params, geometry, rng)


def check_overhead(params, geometry, rng):
    """Checked public call / unchecked inner call, paired medians over the same inputs."""
    markers = geometry + [0.02, -0.01, 0.45]
    z = np.r_[(markers + rng.normal(0, 0.001, markers.shape)).ravel(), rng.normal(0, 0.5, 3)]
    observed = np.ones(len(geometry), dtype=bool)
    f = SquareRootUKF(geometry, params.filter)
    f.initialize(markers)
    tracker = MarkerTracker(geometry, params.filter, params.matching)
    clock = iter(np.arange(1, 10**7) * params.filter.dt * 4)
    tracker.frame(0.0, markers)
    pairs = {
        "kabsch (4 points)": (lambda: kabsch_unchecked(markers, geometry), lambda: kabsch(markers, geometry)),
        "SR-UKF predict_steps(1)": (lambda: f._predict_steps(1, params.filter.dt, None), lambda: f.predict_steps(1, params.filter.dt)),
        "SR-UKF update (4 markers + gyro)": (lambda: f._update(z, observed, True), lambda: f.update(z, observed, True)),
        "tracker frame (4 markers)": (lambda: tracker._frame(float(next(clock)), markers), lambda: tracker.frame(float(next(clock)), markers)),
    }
    print("argument checks: checked public call / unchecked inner call (paired medians, same run)")
    for name, (inner, public) in pairs.items():
        inner(), public()
        t_inner, t_public = paired_medians(inner, public, 3000)
        print(f"  {name:34s} inner {t_inner * 1e6:8.2f} us  checked {t_public * 1e6:8.2f} us  ratio {t_public / t_inner:5.3f}")


if __name__ == "__main__":
    main()
