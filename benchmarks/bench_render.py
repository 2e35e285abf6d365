"""Rendering speed of one frame at the paper-scale resolution, on one core, with the bone-foam surfaces.

Prints medians in ms and ratios against two references measured in the same run on the same frame:
SIFT detectAndCompute (the per-frame work stage 02 does next) and a flat-picture perspective warp
(cv2.warpPerspective), the cheap thing the renderer replaces. Target: render + sensor <= 100 ms. Also the PNG
encoding of one image (stage 01 renders once per stop, then exposes and encodes each of its images_per_stop).
Parameters: params.yaml (generate, protocol). Run: .venv/bin/python benchmarks/bench_render.py
"""

import time

import cv2
import numpy as np

from poseintegrity.config import load_params
from poseintegrity.scenes import dataset, renderer, trajectories
from poseintegrity.poses import inverse
from poseintegrity.scenes.camera import Intrinsics

cv2.setNumThreads(1)
everything = load_params("params.yaml")
params, protocol = everything.generate, everything.protocol
cam = Intrinsics.from_params(params.camera)
sift = cv2.SIFT_create()


def median_ms(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return 1000 * float(np.median(times))


for scene_index in (0, 1, 2, 4):  # a scapula, the drilled scapula, a block, a scapula + block
    world = dataset.world(params, scene_index)
    spec = params.scenes[scene_index]
    T0 = trajectories.model_pair(world.scene.aim, world.scene.view_dir, spec.distance_mm, params.model_baseline_mm)[0]
    azimuth = params.arcs.azimuths_deg[min(1, len(params.arcs.azimuths_deg) - 1)]  # 90: down towards the table
    stop = trajectories.arc(T0, world.scene.aim, azimuth, protocol.arc_span_deg, params.arcs.n_stops)[
        params.arcs.n_stops // 4]
    T_cam_world = inverse(stop.T_world_cam)
    rng = np.random.default_rng(0)
    renderer.render(world.geometry, cam.K, cam.width, cam.height, T_cam_world)  # compile / warm up
    frame = renderer.render(world.geometry, cam.K, cam.width, cam.height, T_cam_world)
    image = renderer.expose(renderer.optics(frame.radiance, params.sensor), params.sensor, rng)
    H = np.array([[1.02, 0.05, -10], [0.01, 0.98, 5], [1e-5, 2e-5, 1]])

    render_ms = median_ms(lambda: renderer.render(world.geometry, cam.K, cam.width, cam.height, T_cam_world), 15)
    full_ms = median_ms(lambda: renderer.expose(renderer.optics(
        renderer.render(world.geometry, cam.K, cam.width, cam.height, T_cam_world).radiance, params.sensor),
        params.sensor, rng), 15)
    sift_ms = median_ms(lambda: sift.detectAndCompute(image, None), 7)
    warp_ms = median_ms(lambda: cv2.warpPerspective(image, H, (cam.width, cam.height)), 15)
    png_ms = median_ms(lambda: cv2.imencode(".png", image, dataset.PNG_FLAGS), 15)
    print(f"{spec.name} ({'+'.join(spec.targets)}, {len(world.geometry.faces)} triangles, {cam.width}x{cam.height})")
    print(f"  render {render_ms:6.1f} ms | render + sensor {full_ms:6.1f} ms (target <= 100)")
    print(f"  SIFT detectAndCompute {sift_ms:6.1f} ms -> render + sensor = {full_ms / sift_ms:.2f} x SIFT")
    print(f"  warpPerspective {warp_ms:6.2f} ms -> render + sensor = {full_ms / warp_ms:.0f} x a flat warp")
    print(f"  PNG encoding {png_ms:6.1f} ms per image")
