"""How the robot takes a dataset's images (Windsor et al. IV-D): it is driven to the protocol's commanded poses and
lands off them (:mod:`.robot`), and once it reports a stop the camera takes a burst of exposures while the arm rings
down (:mod:`.ringdown`). A :class:`Visit` is where the camera was at one stop; each image of the burst sees that view
turned by its own ring-down rotation, blurred along the path the rotation takes during the exposure."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.poses import pose_matrix
from poseintegrity.params.camera import CaptureParams
from poseintegrity.params.generate import GenerateParams
from poseintegrity.scenes.ringdown import Exposure, RingDown, ring_down
from poseintegrity.scenes.robot import PlacedRobot
from poseintegrity.seeding import keyed_rng

RATE_SAMPLES = 9  # instants of an exposure at which the ring-down's rate is taken (image_motion)


@dataclass(frozen=True)
class Visit:
    """The camera at one stop of the robot (or one model view): its actual T_world_cam (4, 4) when the controller
    reported the stop, and how the arm rings down from there."""

    T_world_cam: np.ndarray
    ring_down: RingDown


@dataclass(frozen=True)
class Route:
    """Where the camera of one dataset really was: the visits of its model pair and of its stops."""

    model: tuple[Visit, ...]
    stops: tuple[Visit, ...]


def visits(placed: PlacedRobot, path: list[np.ndarray], params: GenerateParams, *key) -> tuple[Visit, ...]:
    """One visit to each commanded pose of ``path`` in order, its repeatability and ring-downs drawn by ``key``."""
    actual = placed.moves(path, keyed_rng(params.seed, "visit", *key))
    return tuple(Visit(T, ring_down(params.robot.ring_down, keyed_rng(params.seed, "ring", *key, k)))
                 for k, T in enumerate(actual))


def exposure_times(capture: CaptureParams, image: int, delay_ms: float | None = None) -> tuple[float, float]:
    """(start, end) of image ``image``'s exposure, s after the robot reported its stop, the first ``delay_ms``
    (default ``capture.delay_ms``) after it."""
    start = ((capture.delay_ms if delay_ms is None else delay_ms) + image * capture.interval_ms) / 1000.0
    return start, start + capture.exposure_ms / 1000.0


def model_motion(visit: Visit, capture: CaptureParams, f_px: float) -> Exposure:
    """The ring-down during a model image's exposure: taken ``capture.model_settle_ms`` after the robot reported the
    model pose, once the arm has settled (III-B: the model is built from "two images of a static scene")."""
    return image_motion(visit, capture, 0, f_px, capture.model_settle_ms)


def image_motion(visit: Visit, capture: CaptureParams, image: int, f_px: float,
                 delay_ms: float | None = None) -> Exposure:
    """The ring-down during image ``image``'s exposure (the burst starting ``delay_ms`` after the stop, default
    ``capture.delay_ms``): its rotation at mid-exposure and a path sampled evenly in time
    so that consecutive samples move the image by at most ``capture.blur_step_px``: f_px |delta r| bounds the motion
    of a pixel under a small rotation r, and |delta r| <= the largest rate over the exposure x the time between
    samples (the rate taken at RATE_SAMPLES instants: a 5 ms exposure is a small part of a 10 Hz swing). One sample,
    the mid-exposure rotation, when the image moves less than that in the whole exposure."""
    t0, t1 = exposure_times(capture, image, delay_ms)
    rate = np.abs(visit.ring_down.angular_rate(np.linspace(t0, t1, RATE_SAMPLES))).max()
    extent_px = f_px * float(rate) * (t1 - t0)
    if extent_px <= capture.blur_step_px:
        mid = visit.ring_down.rotation(0.5 * (t0 + t1))
        return Exposure(mid, mid[None], np.array([0.5 * (t0 + t1)]))
    return visit.ring_down.exposure(t0, t1, math.ceil(extent_px / capture.blur_step_px) + 1)


def image_pose(visit: Visit, motion: Exposure) -> np.ndarray:
    """Actual T_world_cam (4, 4) of an image: the visit's pose turned by its mid-exposure rotation (camera frame)."""
    return visit.T_world_cam @ pose_matrix(Rotation.from_rotvec(motion.mid).as_matrix(), np.zeros(3))


def rotation_maps(K: np.ndarray, rotation: np.ndarray, map_x: np.ndarray, map_y: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Sampling maps of the view turned by ``rotation`` (3,) rad (camera frame): the canvas pixel p' an output
    pixel sees through (map_x, map_y) (h, w) is where the unturned camera saw that ray, p = K R K^-1 p' (pure
    rotation). Returns (h, w) float32 maps, computed in float64 (one compiled pass; the values of numpy's
    ``(H[0, 0] * map_x + H[0, 1] * map_y + H[0, 2]) / w`` to the bit)."""
    H = K @ Rotation.from_rotvec(rotation).as_matrix() @ np.linalg.inv(K)
    out_x, out_y = np.empty(np.shape(map_x), np.float32), np.empty(np.shape(map_x), np.float32)
    _homography_maps(H, map_x, map_y, out_x, out_y)
    return out_x, out_y


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA
def _homography_maps(H, map_x, map_y, out_x, out_y):
    """out = float32 of H (3, 3) applied to the points (map_x, map_y) (h, w), divided by their third coordinate, in
    float64 with numpy's order of operations (((a x + b y) + c) / w)."""
    for i in range(map_x.shape[0]):
        for j in range(map_x.shape[1]):
            x, y = np.float64(map_x[i, j]), np.float64(map_y[i, j])
            w = H[2, 0] * x + H[2, 1] * y + H[2, 2]
            out_x[i, j] = np.float32((H[0, 0] * x + H[0, 1] * y + H[0, 2]) / w)
            out_y[i, j] = np.float32((H[1, 0] * x + H[1, 1] * y + H[1, 2]) / w)