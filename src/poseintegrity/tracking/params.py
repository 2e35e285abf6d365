"""Schema of the ``track`` section of params.yaml (stage 06, marker tracking).

Black and Salcudean, IEEE Transactions on Instrumentation and Measurement, 2024, DOI 10.1109/TIM.2024.3398108.
params.yaml is the source of every value; the defaults here equal it (docs/references.md gives the source
of each published constant; everything else is our documented choice: the simulation, its noise levels,
P_p, P_o, the gyro rate split, the retuned filter sigmas).
"""

from __future__ import annotations

import math
from typing import Literal

from pydantic import Field, model_validator

from poseintegrity.schema import Section
from poseintegrity.tracking.geometry import MARKERS_BODY


class CameraParams(Section):
    """AHAT-like pinhole camera (docs/references.md: 512 x 512); the world frame is the camera frame shifted by origin_m."""

    width: int = Field(512, ge=16)
    height: int = Field(512, ge=16)
    focal_px: float = Field(240.0, gt=0)  # our choice: 11 mm spheres at 0.5 m give blobs of ~13-20 px (references: 10-20)
    origin_m: tuple[float, float, float] = (0.0, 0.0, 0.0)  # camera centre in the world frame (T_world_cam)


class FrameParams(Section):
    """IR reflectivity and depth synthesis (our choices; docs/references.md: IR raw 0-1000, depth in mm along the ray)."""

    ir_background: float = Field(80.0, ge=0)
    ir_noise_std: float = Field(25.0, ge=0)
    marker_ir: float = Field(2000.0, gt=0)  # retro-reflective spheres saturate (clipped at 1000 by the detector)
    marker_ir_std: float = Field(100.0, ge=0)
    depth_noise_mm: float = Field(2.0, ge=0)  # per pixel, ToF noise
    depth_bias_std_mm: float = Field(0.8, ge=0)  # per marker and frame (multipath on the sphere)
    frame_depth_bias_std_mm: float = Field(3.0, ge=0)  # per frame, common to all pixels (ToF offset drift)
    background_depth_mm: float = Field(1200.0, ge=0)  # beyond the detector's depth window
    supersampling: int = Field(3, ge=1, le=8)
    phantom_radius_px: tuple[float, float] = (1.5, 4.0)
    phantom_depth_mm: tuple[float, float] = (150.0, 850.0)
    phantom_elongation: tuple[float, float] = (3.0, 8.0)  # axis ratio of non-round reflections


class DetectionParams(Section):
    """Detector of section II-B; constants of their public code (docs/references.md) and our two additions
    (shape_measure "pixel", split_touching; see :mod:`poseintegrity.tracking.detection`)."""

    threshold: int = Field(222, ge=0, le=255)  # on the 8-bit image
    ir_clip: float = Field(1000.0, gt=0)  # raw IR clipped here, then scaled to 8 bit
    min_area: float = Field(2.0, ge=0)
    max_area: float = Field(1000.0, gt=0)
    min_circularity: float = Field(0.6, ge=0, le=1)
    min_convexity: float = Field(0.75, ge=0, le=1)
    depth_min_mm: float = Field(100.0, ge=0)
    depth_max_mm: float = Field(1000.0, gt=0)  # published 900; AHAT reaches ~1 m and markers at 0.9 m read up to 0.9 m + noise
    depth_window: int = Field(1, ge=0, le=5)  # median over a (2w+1)^2 window at the centroid
    depth_offset_mm: float = Field(5.5, ge=0)  # sphere radius: the depth hits the surface, we want the centre
    shape_measure: Literal["pixel", "contour"] = "pixel"  # "contour": the published polygon form
    split_touching: bool = True  # split a blob made of two touching marker images
    split_max_residual_px: float = Field(0.6, gt=0)  # RMS boundary residual of each of the two circles
    depth_split_mm: float = Field(12.0, gt=0)  # a depth jump inside a blob this large: two markers, one behind

    @model_validator(mode="after")
    def _ranges(self):
        if self.min_area >= self.max_area:
            raise ValueError("min_area must be below max_area")
        if self.depth_min_mm >= self.depth_max_mm:
            raise ValueError("depth_min_mm must be below depth_max_mm")
        return self


class MatchingParams(Section):
    """Correspondence (Alg. 1-3 and the gated assignment).  docs/references.md: matching threshold 8 mm."""

    tolerance_m: float = Field(0.008, gt=0)
    gate_m: float = Field(0.03, gt=0)  # around the filter's predicted marker positions
    min_markers: int = Field(3, ge=3)
    distinct_m: float = Field(0.001, gt=0)  # inter-marker distances of all tools must differ by more than this


class FilterParams(Section):
    """SR-UKF constants.  Published (docs/references.md): alpha 1e-3, beta 2, kappa 3 - N, dt 0.0025 s, restart
    after 1 s, and the sigmas of :data:`PAPER_SIGMAS`; the sigmas used here are ours (params.yaml says why).
    The innovation gate and the restart after repeated rejections are ours too."""

    alpha: float = Field(1e-3, gt=0, le=1)
    beta: float = 2.0
    kappa: float | None = None  # None: 3 - N
    sigma_r: float = Field(0.003, gt=0)  # m, eq. 16
    sigma_omega: float = Field(math.sqrt(0.1), gt=0)  # rad/s, eq. 16
    sigma_c: float = Field(3.0, gt=0)  # m/s^2, eq. 8
    sigma_alpha: float = Field(30.0, gt=0)  # rad/s^2, eq. 9
    init_std_omega: float = Field(1.0, gt=0)
    init_std_velocity: float = Field(0.5, gt=0)
    max_position_std: float = Field(1.0, gt=0)
    dt: float = Field(0.0025, gt=0)  # filter clock: predictions in steps of at most dt
    restart_after_s: float = Field(1.0, gt=0)
    innovation_gate_chi2: float = Field(21.1, gt=0)  # per marker, 3 dof: chi2.ppf(1 - 1e-4, 3)
    restart_after_rejections: int = Field(5, ge=1)  # consecutive frames whose every marker failed the gate


# The sigmas Black and Salcudean published (docs/references.md): sigma_r^2 = 0.00025, sigma_omega^2 = 0.1,
# sigma_c = sigma_alpha = sqrt(0.5).
PAPER_SIGMAS = {"sigma_r": math.sqrt(0.00025), "sigma_omega": math.sqrt(0.1), "sigma_c": math.sqrt(0.5), "sigma_alpha": math.sqrt(0.5)}


class MotionParams(Section):
    """Simulation of section II-F (all our choices; the paper published none of them)."""

    duration_s: float = Field(60.0, gt=0)
    sim_dt: float = Field(0.001, gt=0)
    home_m: tuple[float, float, float] = (0.0, 0.0, 0.45)
    accel_std: float = Field(0.5, ge=0)  # m/s^2, random linear acceleration (OU)
    accel_tau_s: float = Field(0.3, gt=0)
    spring_hz: float = Field(0.8, ge=0)  # keeps the tool in front of the camera
    damping: float = Field(0.7, ge=0)
    omega_std: float = Field(0.5, ge=0)  # rad/s, body angular velocity (OU) of the accuracy runs
    omega_tau_s: float = Field(0.6, gt=0)
    frame_interval_s: float = Field(0.046, gt=0)  # paper: 45.98 +- 7.67 ms
    frame_jitter_s: float = Field(0.0077, ge=0)
    p_gyro_2: float = Field(0.5, ge=0, le=1)  # P_2: two gyro samples per frame, else three (P_3 = 1 - P_2)
    gyro_noise_std: float = Field(0.02, ge=0)  # rad/s
    p_occlusion: float = Field(0.03, ge=0, le=1)  # P_o per marker and frame
    p_phantom: float = Field(0.3, ge=0, le=1)  # P_p per phantom slot and frame
    max_phantoms: int = Field(2, ge=0)
    phantom_round_fraction: float = Field(0.5, ge=0, le=1)
    occlusions: list[tuple[float, float]] = [(20.0, 2.0)]  # (start_s, duration_s): all markers hidden


class HandMotionParams(Section):
    """Motion (a), paper-like (section III: "a series of large motions and many full 360 deg rotations in all
    axes ... with markers periodically occluded briefly"): full turns about the body x, y, z axes in turn, each
    with a smooth sin^2 speed profile lasting turn_s (peak speed 4 pi / turn_s), separated by pauses; the
    translation is the OU walk of ``motion`` with a larger acceleration; brief per-marker occlusions (a finger
    passing over a marker) instead of the i.i.d. P_o of ``motion``.  All our choices (see params.yaml)."""

    turn_s: tuple[float, float] = (2.0, 4.0)  # duration of one full turn, s (uniform)
    pause_s: tuple[float, float] = (0.3, 1.5)  # between turns, s (uniform)
    wobble_std: float = Field(0.3, ge=0)  # rad/s, OU angular velocity added throughout (hand tremor, re-grip)
    accel_std: float = Field(1.5, ge=0)  # m/s^2, the OU linear acceleration of the large motions
    occlusion_rate_hz: float = Field(0.045, ge=0)  # per marker
    occlusion_s: tuple[float, float] = (0.1, 0.3)  # duration of a brief occlusion, s (uniform)


class EvaluationParams(Section):
    """Section III on our simulation."""

    success_frames: int = Field(10_000, ge=1)  # paper: 10 000 frames of large motion
    success_omega_std: float = Field(2.0, ge=0)  # rad/s, motion (b): the stress test, OU spin of this spread
    correct_tolerance_m: float = Field(0.015, gt=0)  # per matched point; a wrong match is off by >= 35 mm
    lag_max_ms: float = Field(600.0, gt=0)
    sigma_scales: list[float] = [0.1, 0.3, 1.0, 3.0, 10.0]  # noise-vs-lag sweep of sigma_c and sigma_alpha
    timing_repeats: int = Field(200, ge=1)
    sweep_distances_m: list[float] = [0.4, 0.5, 0.6, 0.7, 0.8, 0.9]  # small-blob sweep
    sweep_focal_px: float = Field(250.0, gt=0)
    sweep_poses: int = Field(50, ge=1)  # random tool orientations per distance
    sweep_phantoms: int = Field(400, ge=1)  # elongated phantoms rendered for the rejection rate
    replay_s: float = Field(5.0, gt=0)  # seconds of recording written as PNG frames and replayed from disk
    multi_tool_frames: int = Field(500, ge=1)  # frames of the two-tool and phantom-rich runs
    phantom_rich_max: int = Field(6, ge=0)  # phantoms per frame (binomial, p_phantom) in the phantom-rich scene
    second_tool: list[tuple[float, float, float]] = [
        (-0.055, 0.043, -0.021), (0.045, -0.047, 0.035), (-0.034, -0.049, 0.018), (0.056, 0.034, -0.007)
    ]  # m; distances 81-146 mm, 10 mm apart and away from the first tool's 36-70 mm


class TrackParams(Section):
    """The ``track`` section of params.yaml."""

    seed: int = 6
    markers_body: list[tuple[float, float, float]] = [tuple(m) for m in MARKERS_BODY.tolist()]
    drop_marker: int = Field(1, ge=0)  # the marker removed for the 3-marker variant (params.yaml says why)
    camera: CameraParams = CameraParams()
    frames: FrameParams = FrameParams()
    detection: DetectionParams = DetectionParams()
    matching: MatchingParams = MatchingParams()
    filter: FilterParams = FilterParams()
    motion: MotionParams = MotionParams()
    hand: HandMotionParams = HandMotionParams()
    evaluation: EvaluationParams = EvaluationParams()

    @model_validator(mode="after")
    def _geometry(self):
        if len(self.markers_body) < 3:
            raise ValueError("markers_body needs at least 3 markers")
        if self.drop_marker >= len(self.markers_body):
            raise ValueError("drop_marker must index a marker of markers_body")
        return self
