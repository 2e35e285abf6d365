"""Schema of the camera side of the ``generate`` section (stage 01): the camera and its lens, the sensor, how a
stop's images are captured, the calibration session and its ChArUco card (scenes/camera.py, scenes/optics.py,
scenes/calibration_views.py, :mod:`poseintegrity.lens`); the scenes' boards are in :mod:`.boards`. Every number
bounded, its key named when refused."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field, field_validator, model_validator

from poseintegrity.boards import dictionary_size
from poseintegrity.lens import LensError, check_folding
from poseintegrity.params.boards import Dictionary
from poseintegrity.schema import FromList, KeyRule, Section, ordered_range

MIN_IMAGE_PX = 64  # the rendered image's shorter side: below it no target keeps enough pixels to be localized
# Zhang's method takes the focal length from how the board's plane turns between views (views of parallel planes add
# no constraint, Zhang 2000, section 3.3): with views tilted by at most max_tilt_deg the calibration of params.yaml's
# session still converges with an RMS of 0.07-0.09 px at any tilt, but its focal length is off by up to 3590 % at
# 0 deg, 39 % at 2, 10 % at 5, 3.9 % at 10, 2.4 % at 15, 1.6 % at 20 and 1.1 % at params.yaml's 40 deg (worst of 3
# sessions, benchmarks/bench_calibration_tilt.py): below 20 deg the error grows as the tilt shrinks, past 1.5 times
# what more tilt reaches
MIN_CALIBRATION_TILT_DEG = 20.0
MAX_SENSOR_PX = 4096  # a side of the sensor: larger frames take GBs of z-buffer per worker


Radial = Annotated[float, Field(ge=-2, le=2)]  # k_i beyond +-2 describe a fisheye, which plumb_bob does not model
Tangential = Annotated[float, Field(ge=-0.05, le=0.05)]  # a lens decentred enough for p_i = 0.05 is broken


class CameraParams(Section):
    """IDS U3-3060CP-M (Sony IMX174, mono) with a fixed-focal lens (docs/references.md, "Camera of the Windsor et al. experiments")."""

    sensor_width_px: int = Field(gt=0, le=MAX_SENSOR_PX)
    sensor_height_px: int = Field(gt=0, le=MAX_SENSOR_PX)
    pixel_um: float = Field(gt=0, le=50)
    lens_mm: float = Field(gt=0, le=75, description="focal length of the (unpublished) lens; ours. Below every "
                                                    "camera distance (>= 100 mm): the lens must focus")
    downscale: int = Field(ge=1, le=MAX_SENSOR_PX // MIN_IMAGE_PX,
                           description="images are rendered at sensor size / downscale (the shorter side >= "
                                       "MIN_IMAGE_PX, checked below)")
    f_number: float = Field(ge=0.5, le=64, description="aperture; sets the depth of field (focus at the model view; "
                                                       "the lines' session: lines.focus)")
    principal_point_offset_px: Annotated[tuple[Annotated[float, Field(ge=-100, le=100)],
                                               Annotated[float, Field(ge=-100, le=100)]], FromList] = (
        Field(description="where the optical axis meets the sensor, from its centre, full-resolution px (a lens is "
                          "mounted a few px off; 100 px would be a visibly decentred lens)"))
    distortion: Annotated[tuple[Radial, Radial, Tangential, Tangential, Radial], FromList] = Field(
        description="k1, k2, p1, p2, k3 of the lens (Brown-Conrady as OpenCV models it, poseintegrity.lens)")

    @model_validator(mode="after")
    def _image_size(self) -> "CameraParams":
        shorter = min(self.sensor_width_px, self.sensor_height_px) // self.downscale
        if shorter < MIN_IMAGE_PX:
            raise KeyRule("downscale", f"the image's shorter side would be {shorter} px "
                                       f"({self.sensor_width_px} x {self.sensor_height_px} / {self.downscale}); "
                                       f"at most {min(self.sensor_width_px, self.sensor_height_px) // MIN_IMAGE_PX} "
                                       f"keeps it >= {MIN_IMAGE_PX} px")
        return self

    @model_validator(mode="after")
    def _lens_does_not_fold(self) -> "CameraParams":
        K, width, height = self.intrinsics()
        try:
            check_folding(K, np.array(self.distortion), width, height)
        except LensError as error:
            raise KeyRule("distortion", str(error)) from None
        return self

    def intrinsics(self) -> tuple[np.ndarray, int, int]:
        """(K (3, 3) px, width, height) of the rendered images: f_px = f_mm / pixel pitch (docs/references.md,
        "Camera of the Windsor et al. experiments"), the principal point ``principal_point_offset_px`` from the
        sensor's centre, downscaled. Pixel centres at integer coordinates: the sensor's centre is at (w - 1) / 2."""
        scale = 1.0 / self.downscale
        f_px = self.lens_mm / (self.pixel_um * 1e-3) * scale
        width, height = self.sensor_width_px // self.downscale, self.sensor_height_px // self.downscale
        cx = (width - 1) / 2 + self.principal_point_offset_px[0] * scale
        cy = (height - 1) / 2 + self.principal_point_offset_px[1] * scale
        return np.array([[f_px, 0.0, cx], [0.0, f_px, cy], [0.0, 0.0, 1.0]]), width, height


class SensorParams(Section):
    """Image formation after the optics: exposure, noise, blur, flicker (8-bit output)."""

    exposure: float = Field(gt=0, le=1000, description="DN for a white Lambertian surface facing the ring light "
                                                       "(255 saturates; 1000 is white everywhere)")
    read_noise_dn: float = Field(ge=0, le=50)
    shot_noise_dn_per_dn: float = Field(ge=0, le=10, description="variance of shot noise per DN of signal")
    blur_sigma_px: float = Field(ge=0, le=20, description="optical blur, Gaussian sigma in pixels")
    flicker: float = Field(ge=0, le=0.1, description="std of the per-image illumination gain (above 0.1 a gain "
                                                     "1 + flicker x N(0, 1) would sometimes be <= 0: a black image)")


class CharucoParams(Section):
    """The calibration board: a ChArUco board (cv2.aruco.CharucoBoard) printed on paper."""

    squares_x: int = Field(ge=3, le=40)
    squares_y: int = Field(ge=3, le=40)
    square_mm: float = Field(gt=0, le=200)
    marker_mm: float = Field(gt=0, le=200, description="the ArUco marker inside each white square")
    dictionary: Dictionary = Field(description="an OpenCV ArUco dictionary, e.g. DICT_5X5_100")

    @model_validator(mode="after")
    def _marker_inside(self) -> "CharucoParams":
        if self.marker_mm >= self.square_mm:
            raise KeyRule("marker_mm", f"a marker lies inside its square: must be < square_mm ({self.square_mm:g}), "
                                       f"got {self.marker_mm:g}")
        n_markers, size = self.squares_x * self.squares_y // 2, dictionary_size(self.dictionary)
        if n_markers > size:
            raise KeyRule("dictionary", f"{self.squares_x} x {self.squares_y} squares hold {n_markers} markers, "
                                        f"{self.dictionary} has {size}")
        return self


class CalibrationParams(Section):
    """The camera's calibration session before any data (scenes/calibration_views.py): the board shown in ``n_views``
    poses; the estimate is what the pipeline uses as the camera."""

    board: CharucoParams
    n_views: int = Field(ge=5, le=200, description="views rendered (5: the fewest a calibration can use)")
    distance_mm: ordered_range(ge=100, le=2000) = Field(
        description="camera to board centre, drawn per view: within [100, 2000] mm, where the lens focuses and the "
                    "board covers more than a few pixels")
    max_tilt_deg: float = Field(ge=0, le=70, description="board tilt from facing the camera, drawn per view (at "
                                                         "least MIN_CALIBRATION_TILT_DEG, checked below)")
    max_rms_px: float = Field(gt=0, le=5, description="a calibration whose reprojection RMS exceeds this stops "
                                                      "stage 01: its camera would not be worth using")

    @field_validator("max_tilt_deg")
    @classmethod
    def _tilted_enough(cls, tilt: float) -> float:
        if tilt < MIN_CALIBRATION_TILT_DEG:
            raise ValueError(f"views tilted by at most {tilt:g} deg are nearly parallel to the image, and Zhang's "
                             f"calibration cannot tell the focal length from the distance (off by 10 % at 5 deg, 3.9 % "
                             f"at 10 deg): must be >= {MIN_CALIBRATION_TILT_DEG:g}")
        return tilt


class CaptureParams(Section):
    """How the images of a stop are taken once the robot reports it has stopped (IV-D: "stopping every 2.25 deg to
    capture 10 images"): a burst of exposures while the arm rings down (scenes/ringdown.py). Ours: the paper gives no
    timing."""

    delay_ms: float = Field(ge=0, le=5000, description="from the reported stop to the first exposure's start")
    interval_ms: float = Field(gt=0, le=5000, description="between exposure starts (the frame period of the burst)")
    exposure_ms: float = Field(gt=0, le=200, description="shutter time; with the ring light a few ms suffice")
    blur_step_px: float = Field(gt=0, le=5, description="motion blur: sub-exposures no further apart in the image than "
                                                        "this (1 sub-exposure when the image moves less)")
    model_settle_ms: float = Field(ge=0, le=60000, description="the model pair is exposed this long after the robot "
                                   "reports each model pose, once the arm has rung down (III-B: 'two images of a "
                                   "static scene'); the stops' bursts keep their ring-down")

    @model_validator(mode="after")
    def _one_at_a_time(self) -> "CaptureParams":
        if self.exposure_ms > self.interval_ms:
            raise KeyRule("exposure_ms", f"a camera exposes one frame at a time: must be <= interval_ms "
                                         f"({self.interval_ms:g}), got {self.exposure_ms:g}")
        return self
