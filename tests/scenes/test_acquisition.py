"""How a stop's images are taken (scenes/acquisition.py): the rotation warp against OpenCV's perspective warp, the
burst's exposure times, the sub-exposures of the motion blur, and the image's pose against its ring-down."""

from dataclasses import replace

import cv2
import numba
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity.config import load_params
from poseintegrity.scenes.acquisition import (
    Visit, _homography_maps, exposure_times, image_motion, image_pose, model_motion, rotation_maps,
)
from poseintegrity.scenes.ringdown import RingDown
from repository import ROOT

CAPTURE = load_params(ROOT / "params.yaml").generate.capture
K = np.array([[500.0, 0.0, 160.0], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]])


def test_the_rotation_warp_is_the_homography_of_a_turned_camera():
    """With identity maps, remap by rotation_maps equals warpPerspective by H = K R K^-1 (its inverse map)."""
    image = cv2.GaussianBlur(np.random.default_rng(0).random((240, 320)).astype(np.float32), (0, 0), 2.0)
    x, y = np.meshgrid(np.arange(320, dtype=np.float32), np.arange(240, dtype=np.float32))
    rotation = np.array([0.01, -0.02, 0.03])
    ours = cv2.remap(image, *rotation_maps(K, rotation, x, y), cv2.INTER_LINEAR)
    H = K @ Rotation.from_rotvec(rotation).as_matrix() @ np.linalg.inv(K)
    reference = cv2.warpPerspective(image, H, (320, 240), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP)
    np.testing.assert_allclose(ours[20:-20, 20:-20], reference[20:-20, 20:-20], atol=2e-3)


def numpy_rotation_maps(K, rotation, map_x, map_y):
    """The numpy code rotation_maps replaced (the reference of its compiled pass)."""
    H = K @ Rotation.from_rotvec(rotation).as_matrix() @ np.linalg.inv(K)
    w = H[2, 0] * map_x + H[2, 1] * map_y + H[2, 2]
    return ((H[0, 0] * map_x + H[0, 1] * map_y + H[0, 2]) / w).astype(np.float32), (
        (H[1, 0] * map_x + H[1, 1] * map_y + H[1, 2]) / w).astype(np.float32)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_the_compiled_rotation_maps_are_numpys_to_the_bit(dtype):
    """Random rotations of ring-down size and larger, on distorted sensor maps like the lens' (float32, and float64):
    the compiled pass gives numpy's float64 arithmetic rounded to float32, bit for bit (no FMA, no reordering)."""
    rng = np.random.default_rng(3)
    x, y = np.meshgrid(np.arange(320.0), np.arange(240.0))
    r2 = ((x - 160) ** 2 + (y - 120) ** 2) / 500.0**2
    map_x = (x + (x - 160) * 0.06 * r2 + rng.normal(0, 1e-3, x.shape)).astype(dtype)
    map_y = (y + (y - 120) * 0.06 * r2).astype(dtype)
    for scale in (1e-4, 1e-3, 1e-2, 0.3):
        rotation = rng.normal(0.0, scale, 3)
        ours, reference = rotation_maps(K, rotation, map_x, map_y), numpy_rotation_maps(K, rotation, map_x, map_y)
        for a, b in zip(ours, reference):
            assert a.dtype == np.float32 and np.array_equal(a.view(np.uint32), b.view(np.uint32)), scale
    # Rounding to float32 hides almost every last-bit difference of the float64 values: a fused multiply-add would
    # flip one map value in ~10^9 (a handful per stage-01 run), too rare to see here. The machine code must have none.
    # numba shows no machine code of a kernel loaded from its cache: a fresh copy, compiled with the same options
    options = {key: value for key, value in _homography_maps.targetoptions.items() if key != "nopython"}
    fresh = numba.njit(**options)(_homography_maps.py_func)
    fresh(np.eye(3), map_x, map_y, np.empty(map_x.shape, np.float32), np.empty(map_x.shape, np.float32))
    assembly = fresh.inspect_asm(fresh.signatures[0]).lower()
    assert "vdiv" in assembly and not any(fused in assembly for fused in ("vfmadd", "vfmsub", "vfnmadd", "vfnmsub"))


def test_a_world_point_lands_where_the_turned_camera_sees_it():
    """The pose of an image is the visit's pose turned by the mid-exposure rotation (camera frame): a point straight
    ahead of the unturned camera appears at K R^T (0, 0, 1) in the turned one."""
    rotation = np.array([0.002, -0.001, 0.0005])
    visit = Visit(np.eye(4), RingDown(np.array([1.0, 0.0, 0.0]), 0.0, 0.0, 60.0, 0.05))
    motion = image_motion(visit, CAPTURE, 0, 500.0)
    T = image_pose(visit, replace(motion, mid=rotation))
    point_cam = np.linalg.inv(T) @ np.array([0.0, 0.0, 300.0, 1.0])
    pixel = K @ (point_cam[:3] / point_cam[2])
    expected = K @ Rotation.from_rotvec(rotation).as_matrix().T @ [0.0, 0.0, 1.0]
    np.testing.assert_allclose(pixel[:2], expected[:2] / expected[2], atol=1e-9)


def test_the_burst_and_its_sub_exposures():
    t0, t1 = exposure_times(CAPTURE, 3)
    assert t0 == pytest.approx((CAPTURE.delay_ms + 3 * CAPTURE.interval_ms) / 1000)
    assert t1 - t0 == pytest.approx(CAPTURE.exposure_ms / 1000)
    still = Visit(np.eye(4), RingDown(np.array([0.0, 0.0, 1.0]), 0.0, 0.0, 60.0, 0.05))
    assert len(image_motion(still, CAPTURE, 0, 1000.0).path) == 1  # no motion: one sub-exposure
    shaking = Visit(np.eye(4), RingDown(np.array([0.0, 1.0, 0.0]), np.radians(0.5), 1.0, 2 * np.pi * 10, 0.05))
    motion = image_motion(shaking, CAPTURE, 0, 1000.0)
    steps = np.linalg.norm(np.diff(motion.path, axis=0), axis=1) * 1000.0  # px moved between sub-exposures
    assert len(motion.path) > 2 and steps.max() <= CAPTURE.blur_step_px + 1e-9


def test_the_model_pair_is_exposed_once_the_arm_has_settled():
    """III-B: the model is built from two images of a static scene. A model image is exposed model_settle_ms after
    the reported stop, where the ring-down's envelope A exp(-zeta omega_n t) has decayed below 0.2 % of A (4e-5 deg
    for A = 0.02 deg: 600 x below the 0.024 deg the pair turned by when taken during the ring-down; the stops' first
    images, delay_ms after the stop, still turn by most of A), and it is a single sharp sub-exposure."""
    amplitude = np.radians(0.02)
    omega = 2 * np.pi * 10.0
    first_mid = (CAPTURE.delay_ms + CAPTURE.exposure_ms / 2) / 1000.0  # the burst's first image at a crest
    visit = Visit(np.eye(4), RingDown(np.array([0.0, 1.0, 0.0]), amplitude, -omega * np.sqrt(1 - 0.05**2) * first_mid,
                                      omega, 0.05))
    settled, burst = model_motion(visit, CAPTURE, 1024.0), image_motion(visit, CAPTURE, 0, 1024.0)
    envelope = np.exp(-0.05 * omega * CAPTURE.model_settle_ms / 1000.0)
    assert envelope < 2e-3 and np.linalg.norm(settled.mid) <= amplitude * envelope
    assert len(settled.path) == 1
    assert np.linalg.norm(burst.mid) > 100 * np.linalg.norm(settled.mid)
