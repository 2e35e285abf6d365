"""Accuracy and time of stage 01's camera calibration (scenes/calibration_views.py, poseintegrity/calibration.py) at
the scale of params.yaml: the ChArUco session rendered through the true lens, then calibrated as a user would.

Printed per world and per variant (k3 held at 0, as stage 01 does; k3 estimated too, for comparison):
    the reprojection RMS and its per-view spread, the views used;
    the errors of fx, fy, cx, cy (px and %) and of k1, k2, p1, p2, k3;
    the ray error of the estimated camera: |pi_est(ray_true(p)) - p| for p the image corners, the centre, and
    over every pixel (max, RMS), px: where the estimated camera projects the ray the true lens images at p;
    the same without the principal point's share (both cameras' rays compared after removing their mean offset);
    the time to render the views and to calibrate.

Measured with params.yaml (968 x 608 px, f = 1023.9 px, dist (-0.06, 0.02, 2e-4, -1e-4, 0), 25 views), its seed and
seeds 1-8, k3 held at 0: RMS 0.064 +- 0.003 px, all 25 views used; fx, fy errors 0.43 px std (0.04 % of f), cx 0.42 px,
cy 0.24 px std; the true rays of the image corners projected 0.78 px off on average (max 1.28), 0.31 px (max 0.59)
without the common offset, while the lens moves them ~10 px; estimating k3 too: 0.38 px (max 0.82). Render ~70 ms a
view once the process has compiled the renderer, calibrate (detection included) ~0.3 s.

Usage: PYTHONPATH=src .venv/bin/python benchmarks/bench_calibration.py [--params params.yaml] [--world main] [--seed N]
"""

from __future__ import annotations

import argparse
import time

import cv2
import numpy as np

from poseintegrity.calibration import calibrate, detect_corners
from poseintegrity.config import load_params
from poseintegrity.lens import Camera
from poseintegrity.scenes import calibration_views as views
from poseintegrity.scenes.camera import true_camera
from poseintegrity.seeding import keyed_rng


def rays(camera: Camera, pixels: np.ndarray) -> np.ndarray:
    """(n, 3) unit-z rays (x, y, 1) the camera images at ``pixels`` (n, 2)."""
    ideal = camera.undistort(pixels)
    return np.column_stack([(ideal - camera.K[:2, 2]) / camera.K[[0, 1], [0, 1]], np.ones(len(pixels))])


def ray_errors(true: Camera, estimate: Camera, pixels: np.ndarray) -> np.ndarray:
    """(n, 2) px: where the estimate projects the true rays of ``pixels``, minus ``pixels``."""
    projected, _ = cv2.projectPoints(rays(true, pixels), np.zeros(3), np.zeros(3), estimate.K, estimate.dist)
    return projected.reshape(-1, 2) - pixels


def report(name: str, true: Camera, estimate: Camera, rms: float, per_view: np.ndarray, n_used: int, n_views: int,
           seconds: float) -> None:
    K, Kt = estimate.K, true.K
    print(f"  [{name}] RMS {rms:.4f} px (per view {per_view.min():.3f}-{per_view.max():.3f}), "
          f"views used {n_used} / {n_views}, calibrate {seconds:.2f} s")
    for label, (i, j) in {"fx": (0, 0), "fy": (1, 1), "cx": (0, 2), "cy": (1, 2)}.items():
        error = K[i, j] - Kt[i, j]
        print(f"    {label}: {K[i, j]:.3f} (true {Kt[i, j]:.3f}), error {error:+.3f} px = {100 * error / Kt[0, 0]:+.4f} % "
              f"of f" + (f" = {100 * error / Kt[i, j]:+.4f} %" if label.startswith("f") else ""))
    print("    dist:", np.round(estimate.dist, 5).tolist(), "true:", np.round(true.dist, 5).tolist())
    w, h = true.width, true.height
    corners = np.array([[0, 0], [w - 1, 0], [0, h - 1], [w - 1, h - 1]], float)
    centre = np.array([[(w - 1) / 2, (h - 1) / 2]])
    u, v = np.meshgrid(np.arange(0, w, 4, dtype=float), np.arange(0, h, 4, dtype=float))
    grid = np.column_stack([u.ravel(), v.ravel()])
    e_corners = np.linalg.norm(ray_errors(true, estimate, corners), axis=1)
    e_centre = np.linalg.norm(ray_errors(true, estimate, centre), axis=1)
    e_grid = ray_errors(true, estimate, grid)
    n_grid = np.linalg.norm(e_grid, axis=1)
    n_shape = np.linalg.norm(e_grid - e_grid.mean(axis=0), axis=1)
    true_shift = np.linalg.norm(corners - true.undistort(corners), axis=1)
    print(f"    ray error at the corners {np.round(e_corners, 3).tolist()} px, centre {e_centre[0]:.3f} px, "
          f"image max {n_grid.max():.3f} / RMS {np.sqrt(np.mean(n_grid ** 2)):.3f} px; without the mean offset: "
          f"max {n_shape.max():.3f} / RMS {np.sqrt(np.mean(n_shape ** 2)):.3f} px (the true lens moves the corners "
          f"{true_shift.min():.1f}-{true_shift.max():.1f} px)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument("--world", default="main")
    parser.add_argument("--seed", type=int, help="replaces the world's seed (another session: other poses, noise)")
    args = parser.parse_args()
    params = load_params(args.params).generate.world(args.world)
    if args.seed is not None:
        params = params.model_copy(update={"seed": args.seed})
    session, true = params.calibration, true_camera(params.camera)
    spec = views.charuco_spec(params)
    print(f"world {args.world}: {true.width} x {true.height} px, f = {true.K[0, 0]:.1f} px, {session.n_views} views, "
          f"board {spec.squares_x} x {spec.squares_y} x {spec.square_mm:g} mm, {session.distance_mm} mm, "
          f"tilt <= {session.max_tilt_deg:g} deg")
    start = time.perf_counter()
    poses = [views.view_pose(true, spec, session.distance_mm, session.max_tilt_deg,
                             keyed_rng(params.seed, "calibration", i)) for i in range(session.n_views)]
    images = [views.render_view(params, T, keyed_rng(params.seed, "calibration noise", i)) for i, T in enumerate(poses)]
    render_s = time.perf_counter() - start
    print(f"  render {render_s:.2f} s ({render_s / len(images) * 1000:.0f} ms per view)")
    start = time.perf_counter()
    found = [detect_corners(image, spec) for image in images]
    detect_s = time.perf_counter() - start
    covered = np.concatenate([img for _, img in found])
    print(f"  detection {detect_s:.2f} s; corners per view {[len(o) for o, _ in found]}; corners reach "
          f"x {covered[:, 0].min():.0f}-{covered[:, 0].max():.0f}, y {covered[:, 1].min():.0f}-"
          f"{covered[:, 1].max():.0f} px")
    start = time.perf_counter()
    calibration = calibrate(images, spec, session.max_rms_px, "generate.calibration.max_rms_px")
    calibrate_s = time.perf_counter() - start
    report("stage 01: k3 = 0", true, calibration.camera, calibration.rms_px, np.array(calibration.per_view_rms_px),
           len(calibration.views_used), len(images), calibrate_s)
    # the same corners with k3 estimated too (calibrate fixes it)
    used = [(o.astype(np.float32), i.astype(np.float32)) for o, i in found if len(o) >= 8]
    start = time.perf_counter()
    rms, K, dist, *_, per_view = cv2.calibrateCameraExtended([o for o, _ in used], [i for _, i in used],
                                                             (true.width, true.height), None, None)[:8]
    report("k3 estimated", true, Camera(K, dist.ravel()[:5], true.width, true.height), rms, per_view.ravel(),
           len(used), len(images), time.perf_counter() - start)


if __name__ == "__main__":
    main()
