"""The camera's lens and its calibration file: Brown-Conrady distortion as OpenCV models it, the ideal pinhole
canvas a renderer draws on before distorting onto the sensor, and ``camera.yaml`` in the ROS camera_info convention.

Distortion (docs/references.md, "OpenCV 5", calib3d camera model; "plumb_bob" in ROS): a ray through the normalized
ideal point (x, y) = (X / Z, Y / Z) reaches the sensor at

    r^2 = x^2 + y^2,   radial = 1 + k1 r^2 + k2 r^4 + k3 r^6
    x_d = x radial + 2 p1 x y + p2 (r^2 + 2 x^2),   y_d = y radial + p1 (r^2 + 2 y^2) + 2 p2 x y
    u = fx x_d + cx,   v = fy y_d + cy

with ``dist = (k1, k2, p1, p2, k3)``. Recorded cameras may instead carry ROS's "rational_polynomial" model,
``dist = (k1, k2, p1, p2, k3, k4, k5, k6)``, whose radial factor is the ratio
``(1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6)`` (OpenCV's 8-coefficient model). Stage 01
renders through the true lens; the pipeline (stages 02 and 05) only knows the lens as a calibration estimated it (``camera.yaml``) and undistorts every keypoint and board corner with it
(:meth:`Camera.undistort`) before any geometry, so that everything after is a pinhole camera of the same K.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import yaml

from poseintegrity.errors import ArgumentError, PoseIntegrityError, check_array, check_intrinsics

DISTORTION_MODELS = {"plumb_bob": 5, "rational_polynomial": 8}  # ROS's names -> number of OpenCV coefficients
# cv2.undistortPoints stops when the re-distorted estimate is within eps px of the pixel: 1e-10 px, as 1e-14 lies
# below the float64 resolution of pixel coordinates (~1e-13 px at 1000 px) and kept it iterating to its 100 steps
# (0.76 s for the 968 x 608 sensor maps, 0.13 s now); round trips through cv2.projectPoints to < 1e-9 px
UNDISTORT_CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-10)
FOLD_SAMPLES = 4096  # radii sampled when checking that the lens' radial mapping keeps increasing
CANVAS_MARGIN_PX = 2  # beyond the outermost ray of the sensor: room for bilinear sampling


class LensError(PoseIntegrityError):
    """Distortion coefficients that cannot describe a lens over the image (it would fold)."""


class CameraFileError(PoseIntegrityError):
    """A camera.yaml that is unreadable or has a missing or invalid field (the message names file and field)."""


@dataclass(frozen=True)
class Camera:
    """A camera with a lens: K (3, 3) px, dist (5,) = (k1, k2, p1, p2, k3) (plumb_bob) or (8,) = (k1, k2, p1, p2,
    k3, k4, k5, k6) (rational_polynomial), image width and height (px).

    Checked once when made (:class:`~poseintegrity.errors.ArgumentError` naming the field): K a finite pinhole
    matrix [[fx, s, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0; dist 5 or 8 finite numbers; width and height positive
    integers. Every function taking a Camera (board pose, target model, undistortion) relies on it; a zero or NaN
    K would otherwise give NaN points or a pose hundreds of mm off reported as ok. Whether the lens folds the image
    is checked where a camera is read from a file (:func:`read_camera_yaml`, :func:`check_folding`).
    """

    K: np.ndarray
    dist: np.ndarray
    width: int
    height: int

    def __post_init__(self) -> None:
        check_intrinsics("Camera.K", self.K)
        dist = check_array("Camera.dist", self.dist, shape=(None,))
        if len(dist) not in DISTORTION_MODELS.values():
            raise ArgumentError(f"Camera.dist: expected 5 (plumb_bob) or 8 (rational_polynomial) coefficients, "
                                f"got {len(dist)}")
        for name, value in (("width", self.width), ("height", self.height)):
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ArgumentError(f"Camera.{name}: expected a positive integer (pixels), got {value!r}")

    def undistort(self, points_px: np.ndarray) -> np.ndarray:
        """(n, 2) sensor pixels -> (n, 2) pixels of the ideal pinhole camera with the same K (OpenCV's iterative
        inverse of the distortion, run to convergence)."""
        points = np.asarray(points_px, dtype=np.float64).reshape(-1, 1, 2)
        if len(points) == 0 or not np.any(self.dist):
            return points.reshape(-1, 2).copy()
        return cv2.undistortPoints(points, self.K, self.dist, None, self.K, criteria=UNDISTORT_CRITERIA).reshape(-1, 2)

    def distort(self, ideal_px: np.ndarray) -> np.ndarray:
        """(n, 2) ideal pinhole pixels (same K) -> (n, 2) sensor pixels: the forward model of the module docstring."""
        ideal = np.asarray(ideal_px, dtype=np.float64).reshape(-1, 2)
        x = (ideal[:, 0] - self.K[0, 2]) / self.K[0, 0]
        y = (ideal[:, 1] - self.K[1, 2]) / self.K[1, 1]
        x_d, y_d = distort_normalized(x, y, self.dist)
        return np.column_stack([self.K[0, 0] * x_d + self.K[0, 2], self.K[1, 1] * y_d + self.K[1, 2]])

    @cached_property
    def canvas(self) -> tuple[np.ndarray, int, int]:
        """(K_canvas, width, height): the ideal pinhole image (same focal lengths) that holds every ray the sensor
        sees, CANVAS_MARGIN_PX around them; the renderer draws it, :meth:`sensor_maps` distorts it onto the sensor."""
        border = np.concatenate([np.column_stack([np.arange(self.width), np.zeros(self.width)]),
                                 np.column_stack([np.arange(self.width), np.full(self.width, self.height - 1)]),
                                 np.column_stack([np.zeros(self.height), np.arange(self.height)]),
                                 np.column_stack([np.full(self.height, self.width - 1), np.arange(self.height)])])
        ideal = self.undistort(border)  # the image's outermost rays lie on its border (no fold: check_folding)
        low = np.floor(ideal.min(axis=0)) - CANVAS_MARGIN_PX
        high = np.ceil(ideal.max(axis=0)) + CANVAS_MARGIN_PX
        low, high = np.minimum(low, 0.0), np.maximum(high, [self.width - 1, self.height - 1])
        K_canvas = self.K.copy()
        K_canvas[:2, 2] -= low
        width, height = (high - low + 1).astype(int)
        return K_canvas, int(width), int(height)

    @cached_property
    def sensor_maps(self) -> tuple[np.ndarray, np.ndarray]:
        """(map_x, map_y), each (height, width) float32, for ``cv2.remap``: the canvas pixel each sensor pixel's ray
        lands on, so that ``cv2.remap(canvas_image, map_x, map_y, ...)`` is what the sensor records."""
        u, v = np.meshgrid(np.arange(self.width, dtype=np.float64), np.arange(self.height, dtype=np.float64))
        ideal = self.undistort(np.column_stack([u.ravel(), v.ravel()]))
        offset = self.canvas[0][:2, 2] - self.K[:2, 2]
        map_x = (ideal[:, 0] + offset[0]).reshape(self.height, self.width).astype(np.float32)
        map_y = (ideal[:, 1] + offset[1]).reshape(self.height, self.width).astype(np.float32)
        return map_x, map_y


def distort_normalized(x: np.ndarray, y: np.ndarray, dist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The Brown-Conrady model on normalized ideal coordinates (module docstring): (x_d, y_d), each like x."""
    p1, p2 = np.asarray(dist, dtype=float)[2:4]
    r2 = x * x + y * y
    radial = radial_factor(r2, dist)
    return (x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
            y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y)


def radial_factor(r2: np.ndarray, dist: np.ndarray) -> np.ndarray:
    """The radial factor of the lens at squared normalized radius ``r2`` (module docstring): the polynomial of
    plumb_bob, or the ratio of polynomials of rational_polynomial (8 coefficients)."""
    k1, k2, _, _, k3, *rational = np.asarray(dist, dtype=float)
    k4, k5, k6 = rational or (0.0, 0.0, 0.0)
    return (1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1.0 + r2 * (k4 + r2 * (k5 + r2 * k6)))


def check_folding(K: np.ndarray, dist: np.ndarray, width: int, height: int) -> None:
    """:class:`LensError` unless the lens maps rays one to one onto the whole image: the distorted radius
    r_d = r (1 + k1 r^2 + k2 r^4 + k3 r^6) must keep increasing until it reaches the farthest image corner (a lens
    whose r_d turns back folds the image's edge onto itself, and ``cv2.undistortPoints`` then returns nonsense
    without an error), and the Jacobian of the whole mapping, tangential terms included, must stay positive there."""
    K, dist = np.asarray(K, dtype=float), np.asarray(dist, dtype=float)
    corners = np.array([[0.0, 0.0], [width - 1.0, 0.0], [0.0, height - 1.0], [width - 1.0, height - 1.0]])
    r_corner = float(np.max(np.hypot((corners[:, 0] - K[0, 2]) / K[0, 0], (corners[:, 1] - K[1, 2]) / K[1, 1])))
    r = np.linspace(0.0, 4.0 * r_corner, FOLD_SAMPLES)
    r_d = r * radial_factor(r**2, dist)
    reached = np.flatnonzero(r_d >= r_corner)
    slope = np.diff(r_d)
    if not reached.size or np.any(slope[: reached[0]] <= 0):
        top = float(r_d[: (reached[0] if reached.size else len(r_d))].max())
        raise LensError(f"distortion {dist.tolist()} folds the image: the lens' radial mapping stops increasing at "
                        f"a distorted radius {top:.3f} before the image corner's {r_corner:.3f} (normalized)")
    # the Jacobian on a polar grid of ideal points out to the corner's ideal radius (tangential terms included)
    radius, angle = np.meshgrid(np.linspace(0.0, r[reached[0]], 64), np.linspace(0.0, 2 * np.pi, 64))
    x, y, h = radius * np.cos(angle), radius * np.sin(angle), 1e-6
    dx = [(a - b) / (2 * h) for a, b in zip(distort_normalized(x + h, y, dist), distort_normalized(x - h, y, dist))]
    dy = [(a - b) / (2 * h) for a, b in zip(distort_normalized(x, y + h, dist), distort_normalized(x, y - h, dist))]
    determinant = dx[0] * dy[1] - dx[1] * dy[0]
    if determinant.min() <= 0:
        raise LensError(f"distortion {dist.tolist()} folds the image: its Jacobian reaches {determinant.min():.3g} "
                        f"inside the image (tangential terms p1, p2 too large)")


def _matrix(info: dict, key: str, rows: int, cols: int, path: Path) -> np.ndarray:
    """``info[key]`` of a camera.yaml: {rows, cols, data} with that shape and finite numbers."""
    entry = info.get(key)
    if not isinstance(entry, dict) or not {"rows", "cols", "data"} <= set(entry):
        raise CameraFileError(f"{path}: field {key} must be a mapping with rows, cols and data")
    if (entry["rows"], entry["cols"]) != (rows, cols):
        raise CameraFileError(f"{path}: field {key} must be {rows} x {cols}, got {entry['rows']} x {entry['cols']}")
    try:
        data = np.asarray(entry["data"], dtype=np.float64)
    except (TypeError, ValueError):
        raise CameraFileError(f"{path}: field {key}.data must hold numbers, got {entry['data']!r:.80}") from None
    if data.shape != (rows * cols,) or not np.all(np.isfinite(data)):
        raise CameraFileError(f"{path}: field {key}.data must hold {rows * cols} finite numbers, got "
                              f"{entry['data']!r:.80}")
    return data.reshape(rows, cols)


def read_camera_yaml(path: str | Path) -> Camera:
    """A camera from ``camera.yaml`` (ROS camera_info / camera_calibration_parsers layout, docs/references.md
    "Camera calibration file"): image_width, image_height, camera_matrix, distortion_model plumb_bob with 5
    distortion_coefficients, or rational_polynomial with 8 (the projection and rectification matrices are not needed
    by a monocular pipeline and are not read). :class:`CameraFileError` naming the file and the field otherwise."""
    path = Path(path)
    try:
        info: Any = yaml.safe_load(path.read_text())
    except OSError as error:
        raise CameraFileError(f"cannot read {path}: {error.strerror}") from None
    except (yaml.YAMLError, UnicodeDecodeError) as error:
        raise CameraFileError(f"{path} is not valid YAML: {error}") from None
    if not isinstance(info, dict):
        raise CameraFileError(f"{path}: expected a mapping of camera_info fields, got {type(info).__name__}")
    size = []
    for key in ("image_width", "image_height"):
        value = info.get(key)
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise CameraFileError(f"{path}: field {key} must be a positive integer, got {value!r}")
        size.append(value)
    K = _matrix(info, "camera_matrix", 3, 3, path)
    if not (K[0, 0] > 0 and K[1, 1] > 0 and K[1, 0] == 0 and np.array_equal(K[2], [0.0, 0.0, 1.0])):
        raise CameraFileError(f"{path}: field camera_matrix must be [fx, s, cx, 0, fy, cy, 0, 0, 1] with fx, fy > 0, "
                              f"got {K.ravel().tolist()}")
    model = info.get("distortion_model")
    if not isinstance(model, str) or model not in DISTORTION_MODELS:
        raise CameraFileError(f"{path}: field distortion_model must be 'plumb_bob' (OpenCV's k1 k2 p1 p2 k3) or "
                              f"'rational_polynomial' (k1 k2 p1 p2 k3 k4 k5 k6), got {model!r}")
    dist = _matrix(info, "distortion_coefficients", 1, DISTORTION_MODELS[model], path).ravel()
    try:
        check_folding(K, dist, *size)
    except LensError as error:
        raise CameraFileError(f"{path}: field distortion_coefficients: {error}") from None
    return Camera(K, dist, *size)


def write_camera_yaml(path: str | Path, camera: Camera, name: str, projection: np.ndarray | None = None,
                      rectification: np.ndarray | None = None) -> None:
    """``camera.yaml`` of ``camera`` in the ROS camera_info layout. ``projection`` (3, 4) and ``rectification``
    (3, 3) are written as given (a ROS camera_info's P and R, e.g. of a stereo pair); by default those of a
    monocular camera, [K | 0] and the identity (the pipeline reads neither)."""
    K = np.asarray(camera.K, dtype=float)
    P = np.hstack([K, np.zeros((3, 1))]) if projection is None else np.asarray(projection, dtype=float).reshape(3, 4)
    R = np.eye(3) if rectification is None else np.asarray(rectification, dtype=float).reshape(3, 3)
    info = {
        "image_width": int(camera.width), "image_height": int(camera.height), "camera_name": name,
        "camera_matrix": {"rows": 3, "cols": 3, "data": K.ravel().tolist()},
        "distortion_model": next(name for name, n in DISTORTION_MODELS.items() if n == len(camera.dist)),
        "distortion_coefficients": {"rows": 1, "cols": len(camera.dist),
                                    "data": np.asarray(camera.dist, dtype=float).tolist()},
        "rectification_matrix": {"rows": 3, "cols": 3, "data": R.ravel().tolist()},
        "projection_matrix": {"rows": 3, "cols": 4, "data": P.ravel().tolist()},
    }
    Path(path).write_text(yaml.safe_dump(info, sort_keys=False))
