"""Rendering speed of one frame at the paper-scale resolution, on one core, with the bone-foam surfaces, and the
cost of one robot stop of stage 01 against the way it was done before, measured in the same run.

Per frame: medians in ms and ratios against two references on the same frame: SIFT detectAndCompute (the per-frame
work stage 02 does next) and a flat-picture perspective warp (cv2.warpPerspective), the cheap thing the renderer
replaces. Target: render + sensor <= 100 ms.
Per stop (stage 01 renders once per stop, then exposes and encodes each of its images_per_stop images), timed
alternately against a reference stop: the sensor as whole-array numpy operations and PNG at zlib level 3 with
adaptive filters (the files are then byte-different, the pixels identical: checked here).
Parameters: params.yaml (generate, protocol). Run: .venv/bin/python benchmarks/bench_render.py
"""

import time

import cv2
import numpy as np
from paired_timing import paired_medians  # benchmarks/paired_timing.py

from poseintegrity.config import load_params
from poseintegrity.poses import inverse
from poseintegrity.scenes import optics, renderer, shots, trajectories, world_cache
from poseintegrity.scenes.acquisition import rotation_maps
from poseintegrity.scenes.camera import Intrinsics, true_camera

cv2.setNumThreads(1)
everything = load_params("params.yaml")
params, protocol = everything.generate, everything.protocol
cam = Intrinsics.from_params(params.camera)
sift = cv2.SIFT_create()
REFERENCE_PNG_FLAGS = [cv2.IMWRITE_PNG_COMPRESSION, 3]


def reference_expose(irradiance, sensor, rng):
    """The sensor model as whole-array numpy float32 operations (same draws, same pixels as renderer.expose)."""
    gain = sensor.exposure * (1.0 + sensor.flicker * rng.standard_normal())
    dn = irradiance * np.float32(gain)
    noise = rng.standard_normal(dn.shape, dtype=np.float32)
    noise *= np.sqrt(np.float32(sensor.read_noise_dn**2) + np.float32(sensor.shot_noise_dn_per_dn) * np.maximum(dn, 0))
    dn += noise
    np.rint(dn, out=dn)
    np.clip(dn, 0, 255, out=dn)
    return dn.astype(np.uint8)


def pinhole_optics(radiance):
    """The previous optics: one Gaussian (the lens' own blur) for the whole frame, no lens distortion."""
    return cv2.GaussianBlur(radiance, (0, 0), params.sensor.blur_sigma_px)


def stop(world, T_cam_world, expose, png_flags) -> list[bytes]:
    """One stop of the previous stage 01 without the file writes: a pinhole render, one blur, then expose and encode
    every image."""
    frame = renderer.render(world.geometry, cam.K, cam.width, cam.height, T_cam_world)
    irradiance = pinhole_optics(frame.radiance)
    return [cv2.imencode(".png", expose(irradiance, params.sensor, np.random.default_rng([0, i])), png_flags)[1]
            for i in range(params.images_per_stop)]


def realistic_stop(world, T_cam_world, focus_mm) -> list[bytes]:
    """One stop of today's stage 01 (scenes/shots.take_shot without the writes): the lens' ideal canvas, depth of
    field per pixel, per image the ring-down warp and the lens distortion onto the sensor, expose, encode."""
    lens = true_camera(params.camera)
    K_canvas, width, height = lens.canvas
    frame = renderer.render(world.geometry, K_canvas, width, height, T_cam_world)
    irradiance = optics.lens(frame.radiance, frame.depth_mm, focus_mm, params.sensor.blur_sigma_px, params.camera)
    images = []
    for i in range(params.images_per_stop):
        rotation = np.array([1e-4, -2e-4, 5e-5]) * np.exp(-i / 5)  # a ring-down's turn (rad), one sub-exposure
        sensor = cv2.remap(irradiance, *rotation_maps(K_canvas, rotation, *lens.sensor_maps), cv2.INTER_LINEAR,
                           borderMode=cv2.BORDER_REPLICATE)
        images.append(cv2.imencode(".png", renderer.expose(sensor, params.sensor, np.random.default_rng([0, i])),
                                   shots.IMAGE_PNG_FLAGS)[1])
    return images


def median_ms(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return 1000 * float(np.median(times))


for scene_index in (0, 1, 2, 4):  # a scapula, the drilled scapula, a block, a scapula + block
    world = world_cache.world(params, scene_index)
    spec = params.scenes[scene_index]
    T0 = trajectories.model_pair(world.scene.aim, world.scene.view_dir, spec.distance_mm, params.model_baseline_mm)[0]
    azimuth = params.arcs.azimuths_deg[min(1, len(params.arcs.azimuths_deg) - 1)]  # 90: down towards the table
    T_cam_world = inverse(trajectories.arc(T0, world.scene.aim, azimuth, protocol.arc_span_deg, params.arcs.n_stops)[
        params.arcs.n_stops // 4].T_world_cam)
    rng = np.random.default_rng(0)
    frame = renderer.render(world.geometry, cam.K, cam.width, cam.height, T_cam_world)  # compile / warm up
    image = renderer.expose(pinhole_optics(frame.radiance), params.sensor, rng)
    H = np.array([[1.02, 0.05, -10], [0.01, 0.98, 5], [1e-5, 2e-5, 1]])

    render_ms = median_ms(lambda: renderer.render(world.geometry, cam.K, cam.width, cam.height, T_cam_world), 15)
    full_ms = median_ms(lambda: renderer.expose(pinhole_optics(
        renderer.render(world.geometry, cam.K, cam.width, cam.height, T_cam_world).radiance), params.sensor, rng), 15)
    sift_ms = median_ms(lambda: sift.detectAndCompute(image, None), 7)
    warp_ms = median_ms(lambda: cv2.warpPerspective(image, H, (cam.width, cam.height)), 15)
    print(f"{spec.name} ({'+'.join(spec.targets)}, {len(world.geometry.faces)} triangles, {cam.width}x{cam.height})")
    print(f"  render {render_ms:6.1f} ms | render + sensor {full_ms:6.1f} ms (target <= 100)")
    print(f"  SIFT detectAndCompute {sift_ms:6.1f} ms -> render + sensor = {full_ms / sift_ms:.2f} x SIFT")
    print(f"  warpPerspective {warp_ms:6.2f} ms -> render + sensor = {full_ms / warp_ms:.0f} x a flat warp")

    reference = lambda: stop(world, T_cam_world, reference_expose, REFERENCE_PNG_FLAGS)  # noqa: E731
    current = lambda: stop(world, T_cam_world, renderer.expose, shots.IMAGE_PNG_FLAGS)  # noqa: E731
    assert all((cv2.imdecode(a, cv2.IMREAD_UNCHANGED) == cv2.imdecode(b, cv2.IMREAD_UNCHANGED)).all()
               for a, b in zip(reference(), current())), "the pixels of a stop changed"
    sensor_ref, sensor_now = paired_medians(lambda: reference_expose(frame.radiance, params.sensor, rng),
                                            lambda: renderer.expose(frame.radiance, params.sensor, rng), 15)
    png_ref, png_now = paired_medians(lambda: cv2.imencode(".png", image, REFERENCE_PNG_FLAGS),
                                      lambda: cv2.imencode(".png", image, shots.IMAGE_PNG_FLAGS), 15)
    stop_ref, stop_now = paired_medians(reference, current, 5)
    size_ref, size_now = (len(cv2.imencode(".png", image, flags)[1])
                          for flags in (REFERENCE_PNG_FLAGS, shots.IMAGE_PNG_FLAGS))
    print(f"  sensor {1000 * sensor_now:5.1f} ms vs numpy {1000 * sensor_ref:5.1f} ms: {sensor_ref / sensor_now:.2f} x")
    print(f"  PNG {1000 * png_now:5.1f} ms vs zlib level 3 {1000 * png_ref:5.1f} ms: {png_ref / png_now:.2f} x; "
          f"{size_now / 1e3:.0f} kB vs {size_ref / 1e3:.0f} kB")
    print(f"  one stop of {params.images_per_stop} images {1000 * stop_now:5.0f} ms vs {1000 * stop_ref:5.0f} ms: "
          f"{stop_ref / stop_now:.2f} x (pixels identical)")
    realistic = lambda: realistic_stop(world, T_cam_world, spec.distance_mm)  # noqa: E731
    pinhole, lensed = paired_medians(current, realistic, 5)
    print(f"  the real lens (canvas, depth of field, distortion, ring-down warp): one stop {1000 * lensed:5.0f} ms vs "
          f"{1000 * pinhole:5.0f} ms pinhole: {lensed / pinhole:.2f} x")
