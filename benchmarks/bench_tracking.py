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
6. Stage 06's per-frame and per-step paths against their previous code, kept below as references (same run,
   same inputs, results equal to the bit): detection of rendered motion (a) / (b) frames as record() ran it
   (validate_frame, then split_by_depth's and lookup_depth's numpy paths: :func:`reference_split_by_depth`,
   :func:`reference_lookup_depth`), the SR-UKF's QR (:func:`reference_lower_factor`, one row at a time) and the
   turns of motion (a) (:func:`reference_full_turns`).
7. The whole study (run_study, every experiment of stage 06) at success_frames = --study-frames, one process:
   CPU-seconds of the code at --reference (a commit, extracted with git archive) and of this tree, each after a
   warm-up run that fills numba's cache, and whether their metrics agree.

Run: .venv/bin/python benchmarks/bench_tracking.py [--study-frames 1000] [--reference 38937b0] (from the repository
root, with MALLOC_MMAP_THRESHOLD_=33554432 MALLOC_TRIM_THRESHOLD_=1073741824 as the stages run)
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core, and no thread start-up in tiny BLAS calls
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from unittest import mock  # noqa: E402

import cv2  # noqa: E402
import numba  # noqa: E402
import numpy as np  # noqa: E402

from poseintegrity.config import load_section  # noqa: E402
from poseintegrity.report.metrics import metrics_differences  # noqa: E402
from poseintegrity.tracking.experiments.compute_time import detect_match_kabsch  # noqa: E402
from poseintegrity.tracking.experiments.peers import filter_speed  # noqa: E402
from poseintegrity.tracking.filter.cholesky import lower_factor  # noqa: E402
from poseintegrity.tracking.filter.model import process_model_kernel, noise_sqrt_kernel  # noqa: E402
from poseintegrity.tracking.filter.srukf import _square_root_of_spread  # noqa: E402
from poseintegrity.tracking.filter.srukf import SquareRootUKF  # noqa: E402
from poseintegrity.tracking.filter.tracker import MarkerTracker  # noqa: E402
from poseintegrity.tracking.filter.ukf import UnscentedKalmanFilter  # noqa: E402
from poseintegrity.tracking.filter.unscented import _sigma_points_kernel  # noqa: E402
from poseintegrity.tracking.markers import detection  # noqa: E402
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M  # noqa: E402
from poseintegrity.tracking.markers.kabsch import kabsch, kabsch_unchecked  # noqa: E402
from poseintegrity.tracking.simulation.frames import draw_phantoms, intrinsics, render_frame  # noqa: E402
from poseintegrity.tracking.simulation.motion import full_turns  # noqa: E402
from poseintegrity.tracking.simulation.simulate import run_filter, simulate  # noqa: E402
from srukf_reference import StepwiseSquareRootUKF  # noqa: E402
from paired_timing import paired_medians  # noqa: E402

RUN_DURATION_S = 20.0  # a third of the accuracy recording; a run costs the same per second of recording
REFERENCE_COMMIT = "38937b0"  # stage 06 before the per-frame speed-up (section 7)


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


SPLIT_BY_DEPTH = detection.split_by_depth  # this tree's, which the reference below patches over


def reference_split_by_depth(pixels, depth_mm, detection_params):
    """The previous split_by_depth's test for a depth gap, in numpy (about 15 calls a blob); a blob with a gap goes
    on to split_by_depth (which repeats the test compiled: ~1 us on the rare blobs with a gap)."""
    d_all = np.asarray(depth_mm[pixels[:, 1], pixels[:, 0]], dtype=float)
    valid = np.isfinite(d_all) & (d_all >= detection_params.depth_min_mm) & (d_all <= detection_params.depth_max_mm)
    if valid.sum() < 2:
        return np.zeros((0, 2)), np.zeros(0)
    gaps = np.diff(np.sort(d_all[valid]))
    if gaps[int(np.argmax(gaps))] < detection_params.depth_split_mm:
        return np.zeros((0, 2)), np.zeros(0)
    return SPLIT_BY_DEPTH(pixels, depth_mm, detection_params)


def reference_lookup_depth(depth_mm, uv, detection_params):
    """The previous lookup_depth: a numpy window and small_median per centre."""
    w = detection_params.depth_window
    H, W = depth_mm.shape
    out = np.full(len(uv), np.nan)
    for k, (u, v) in enumerate(np.rint(uv).astype(int)):
        if not (0 <= u < W and 0 <= v < H):
            continue
        patch = np.asarray(depth_mm[max(v - w, 0) : v + w + 1, max(u - w, 0) : u + w + 1], dtype=float)
        valid = patch[np.isfinite(patch) & (patch >= detection_params.depth_min_mm) & (patch <= detection_params.depth_max_mm)]
        if valid.size:
            out[k] = detection.small_median(valid)
    return out


def reference_detect_markers(ir, depth_mm, K, detection_params, T_world_cam=None):
    """Detection as record() ran it before: the public detect_markers (validate_frame on every rendered frame) with
    the numpy split_by_depth test and lookup_depth above."""
    with mock.patch.object(detection, "split_by_depth", reference_split_by_depth), mock.patch.object(detection, "lookup_depth", reference_lookup_depth):
        return detection.detect_markers(ir, depth_mm, K, detection_params, T_world_cam=T_world_cam)


@numba.njit(cache=True)
def reference_lower_factor(A):  # pragma: no cover - compiled
    """The previous lower_factor: the Householder LQ of A (N, p) reflecting one row at a time."""
    N, p = A.shape
    W = A.copy()
    for k in range(N):
        tail2 = 0.0
        for j in range(k + 1, p):
            tail2 += W[k, j] * W[k, j]
        if not (tail2 > 0.0):
            if not np.isfinite(tail2):
                W[k, k] = np.nan
            continue
        norm2 = W[k, k] * W[k, k] + tail2
        beta = -np.sqrt(norm2) if W[k, k] >= 0.0 else np.sqrt(norm2)
        v0 = W[k, k] - beta
        scale = 2.0 / (v0 * v0 + tail2)
        for i in range(k + 1, N):
            dot = W[i, k] * v0
            for j in range(k + 1, p):
                dot += W[i, j] * W[k, j]
            dot *= scale
            W[i, k] -= dot * v0
            for j in range(k + 1, p):
                W[i, j] -= dot * W[k, j]
        W[k, k] = beta
    S = np.zeros((N, N))
    for j in range(N):
        sign = -1.0 if W[j, j] < 0.0 else 1.0
        for i in range(j, N):
            S[i, j] = W[i, j] * sign
    return S


def reference_full_turns(t, hand, rng):
    """The previous full_turns: each turn's samples found by comparing the whole time grid."""
    omega = np.zeros((len(t), 3))
    start, axis = rng.uniform(*hand.pause_s), 0
    while start < t[-1]:
        duration = rng.uniform(*hand.turn_s)
        inside = (t >= start) & (t < start + duration)
        tau = t[inside] - start
        omega[inside, axis] = rng.choice([-1.0, 1.0]) * 4 * np.pi / duration * np.sin(np.pi * tau / duration) ** 2
        start += duration + rng.uniform(*hand.pause_s)
        axis = (axis + 1) % 3
    return omega


def per_call_ms(fn, repeats):
    fn()
    start = time.perf_counter()
    for _ in range(repeats):
        fn()
    return (time.perf_counter() - start) / repeats * 1000.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--study-frames", type=int, default=1000, help="success_frames of the whole-study comparison (0: skip it)")
    parser.add_argument("--reference", default=REFERENCE_COMMIT, help="commit whose stage-06 code the whole study is compared with")
    options = parser.parse_args()
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
    stage06_paths(params)
    if options.study_frames:
        whole_study(options.study_frames, options.reference)


def best_of(fn, repeats=3):
    """Least CPU-seconds of repeated calls of fn (the machine's other load only adds)."""
    times = []
    for _ in range(repeats):
        start = time.process_time()
        fn()
        times.append(time.process_time() - start)
    return min(times)


def stage06_paths(params):
    """Section 6: detection, the SR-UKF's QR and motion (a)'s turns against their references, same run."""
    frames = []
    for omega_std in (None, 2.0):  # the accuracy motion and motion (b), the stress test (touching blobs)
        simulate(params, np.random.default_rng(11), omega_std=omega_std, duration_s=7.0, sink=lambda t, ir, depth: frames.append((ir, depth)))
    K, T_wc = intrinsics(params.camera), np.eye(4)
    new = [detection.detect_markers_unchecked(ir, depth, K, params.detection, T_wc) for ir, depth in frames]
    old = [reference_detect_markers(ir, depth, K, params.detection, T_wc) for ir, depth in frames]
    assert all(np.array_equal(a, b) for a, b in zip(new, old))
    t_new = best_of(lambda: [detection.detect_markers_unchecked(ir, depth, K, params.detection, T_wc) for ir, depth in frames])
    t_old = best_of(lambda: [reference_detect_markers(ir, depth, K, params.detection, T_wc) for ir, depth in frames])
    print("stage 06 paths against their previous code (same run, results equal to the bit)")
    print(f"  detection of {len(frames)} rendered frames: {t_old / len(frames) * 1e6:7.1f} -> {t_new / len(frames) * 1e6:7.1f} us a frame, "
          f"{t_old / t_new:.2f}x")

    geometry = np.array(params.markers_body)
    f = SquareRootUKF(geometry, params.filter)
    f.initialize(geometry + [0.02, -0.01, 0.45], np.array([1.0, 2.0, 0.5]))
    f.predict_steps(50, params.filter.dt)
    X_f, R = process_model_kernel(_sigma_points_kernel(f.x, f.S, f.gamma), params.filter.dt, f.ell)
    B = noise_sqrt_kernel(R, f.x, params.filter.dt, f.ell, params.filter.sigma_c, params.filter.sigma_alpha)
    dev = X_f - (X_f @ f.Wm)[:, None]
    A = np.ascontiguousarray(np.hstack([np.sqrt(f.Wc[1]) * dev[:, 1:], B]))
    assert np.array_equal(lower_factor(A), reference_lower_factor(A))
    assert np.array_equal(_square_root_of_spread(dev, np.sqrt(f.Wc[1]), B), reference_lower_factor(A))
    t_old, t_new = paired_medians(lambda: reference_lower_factor(A), lambda: lower_factor(A), 3000)
    print(f"  SR-UKF QR of the time update ({A.shape[0]} x {A.shape[1]}): {t_old * 1e6:6.2f} -> {t_new * 1e6:6.2f} us, {t_old / t_new:.2f}x")

    duration = params.evaluation.success_frames * params.motion.frame_interval_s * 1.2 + 1.0
    t = np.arange(int(round(duration / params.motion.sim_dt)) + 1) * params.motion.sim_dt
    assert np.array_equal(full_turns(t, params.hand, np.random.default_rng(3)), reference_full_turns(t, params.hand, np.random.default_rng(3)))
    t_new = best_of(lambda: full_turns(t, params.hand, np.random.default_rng(3)))
    t_old = best_of(lambda: reference_full_turns(t, params.hand, np.random.default_rng(3)))
    print(f"  full_turns over {duration:.0f} s of motion (a): {t_old * 1e3:6.1f} -> {t_new * 1e3:6.1f} ms, {t_old / t_new:.1f}x")


STUDY = """
import json, sys, tempfile, time
from pathlib import Path
from poseintegrity.config import load_section
from poseintegrity.report.metrics import json_ready
try:
    from poseintegrity.workers import Workers
except ModuleNotFoundError:  # a commit from before parallel.py was named after its workers
    from poseintegrity.parallel import Workers
try:
    from poseintegrity.tracking.experiments.study import run_study
except ModuleNotFoundError:  # a commit from before the tracking package was split into sub-packages
    from poseintegrity.tracking.evaluation import run_study
params_path, frames, out = Path(sys.argv[1]), int(sys.argv[2]), Path(sys.argv[3])
params = load_section(params_path, "track")
params = params.model_copy(update={"evaluation": params.evaluation.model_copy(update={"success_frames": frames})})
start = time.process_time()
with tempfile.TemporaryDirectory() as folder, Workers(load_section(params_path, "parallel").model_copy(update={"n_jobs": 1})) as workers:
    study = run_study(params, Path(folder) / "replay", workers)
out.write_text(json.dumps({"cpu_s": time.process_time() - start, "metrics": json_ready(study.metrics)}))
"""


def study_cpu_seconds(src: Path, frames: int, out: Path) -> dict:
    """run_study of the package at src on params.yaml at success_frames = frames, in a fresh process of one core."""
    params = Path(__file__).resolve().parents[1] / "params.yaml"
    env = {**os.environ, "PYTHONPATH": str(src), "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    subprocess.run([sys.executable, "-c", STUDY, str(params), str(frames), str(out)], env=env, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    return json.loads(out.read_text())


def whole_study(frames: int, reference: str) -> None:
    """Section 7: the whole study at success_frames = frames, the code at the reference commit against this tree."""
    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        archive = subprocess.run(["git", "-C", str(root), "archive", reference, "src"], check=True, capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
        runs = {}
        for name, src in (("reference", folder / "src"), ("this tree", root / "src")):
            study_cpu_seconds(src, 25, folder / "warm.json")  # numba compiles and caches the kernels of that source
            runs[name] = study_cpu_seconds(src, frames, folder / f"{name}.json")
    old, new = runs["reference"]["cpu_s"], runs["this tree"]["cpu_s"]
    differences = metrics_differences(runs["reference"]["metrics"], runs["this tree"]["metrics"])  # no time in a metrics file
    print(f"whole study (run_study, success_frames {frames}, one process): CPU-seconds {reference} {old:.1f} s, this tree {new:.1f} s: "
          f"{new / old:.0%} of the reference ({old / new:.2f}x)")
    print(f"  metrics: {'identical' if not differences else f'{len(differences)} differ, e.g. ' + differences[0]}")


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
        "tracker frame (4 markers)": (lambda: tracker.frame_unchecked(float(next(clock)), markers), lambda: tracker.frame(float(next(clock)), markers)),
    }
    print("argument checks: checked public call / unchecked inner call (paired medians, same run)")
    for name, (inner, public) in pairs.items():
        inner(), public()
        t_inner, t_public = paired_medians(inner, public, 3000)
        print(f"  {name:34s} inner {t_inner * 1e6:8.2f} us  checked {t_public * 1e6:8.2f} us  ratio {t_public / t_inner:5.3f}")


if __name__ == "__main__":
    main()
