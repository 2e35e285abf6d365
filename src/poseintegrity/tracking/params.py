"""Schema of the ``track`` section of params.yaml (stage 06, marker tracking).

Defaults are the constants of Black and Salcudean (2023) where they published one (FACTS.md) and our own
documented choices where they did not (the simulation, its noise levels, P_p, P_o, the gyro rate split).
"""

from __future__ import annotations

import math

from pydantic import BaseModel, ConfigDict, Field, model_validator

from poseintegrity.tracking.geometry import MARKERS_BODY


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class CameraParams(_Section):
    """AHAT-like pinhole camera (FACTS.md: 512 x 512); the world frame is the camera frame shifted by origin_m."""

    width: int = Field(512, ge=16)
    height: int = Field(512, ge=16)
    focal_px: float = Field(240.0, gt=0)  # our choice: 11 mm spheres at 0.5 m give blobs of ~13-20 px (FACTS.md: 10-20)
    origin_m: tuple[float, float, float] = (0.0, 0.0, 0.0)  # camera centre in the world frame (T_world_cam)


class FrameParams(_Section):
    """IR reflectivity and depth synthesis (our choices; FACTS.md: IR raw 0-1000, depth in mm along the ray)."""

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


class DetectionParams(_Section):
    """Detector of section II-B; constants of their public code (FACTS.md)."""

    threshold: int = Field(222, ge=0, le=255)  # on the 8-bit image
    ir_clip: float = Field(1000.0, gt=0)  # raw IR clipped here, then scaled to 8 bit
    min_area: float = Field(2.0, ge=0)
    max_area: float = Field(1000.0, gt=0)
    min_circularity: float = Field(0.6, ge=0, le=1)
    min_convexity: float = Field(0.75, ge=0, le=1)
    depth_min_mm: float = Field(100.0, ge=0)
    depth_max_mm: float = Field(900.0, gt=0)
    depth_window: int = Field(1, ge=0, le=5)  # median over a (2w+1)^2 window at the centroid
    depth_offset_mm: float = Field(5.5, ge=0)  # sphere radius: the depth hits the surface, we want the centre

    @model_validator(mode="after")
    def _ranges(self):
        if self.min_area >= self.max_area:
            raise ValueError("min_area must be below max_area")
        if self.depth_min_mm >= self.depth_max_mm:
            raise ValueError("depth_min_mm must be below depth_max_mm")
        return self


class MatchingParams(_Section):
    """Correspondence (Alg. 1-3 and the gated assignment).  FACTS.md: matching threshold 8 mm."""

    tolerance_m: float = Field(0.008, gt=0)
    gate_m: float = Field(0.03, gt=0)  # around the filter's predicted marker positions
    min_markers: int = Field(3, ge=3)


class FilterParams(_Section):
    """SR-UKF constants (FACTS.md: alpha 1e-3, beta 2, kappa 3 - N, the sigmas, dt 0.0025 s, restart 1 s)."""

    alpha: float = Field(1e-3, gt=0, le=1)
    beta: float = 2.0
    kappa: float | None = None  # None: 3 - N
    sigma_r: float = Field(math.sqrt(0.00025), gt=0)  # m
    sigma_omega: float = Field(math.sqrt(0.1), gt=0)  # rad/s
    sigma_c: float = Field(math.sqrt(0.5), gt=0)  # m/s^2
    sigma_alpha: float = Field(math.sqrt(0.5), gt=0)  # rad/s^2
    init_std_omega: float = Field(1.0, gt=0)
    init_std_velocity: float = Field(0.5, gt=0)
    max_position_std: float = Field(1.0, gt=0)
    dt: float = Field(0.0025, gt=0)  # filter clock: predictions in steps of at most dt
    restart_after_s: float = Field(1.0, gt=0)


class MotionParams(_Section):
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


class EvaluationParams(_Section):
    """Section III on our simulation."""

    success_frames: int = Field(10_000, ge=1)  # paper: 10 000 frames of large motion
    success_omega_std: float = Field(2.0, ge=0)  # rad/s in the large-motion runs: full turns about every axis
    correct_tolerance_m: float = Field(0.015, gt=0)  # per matched point; a wrong match is off by >= 35 mm
    lag_max_ms: float = Field(600.0, gt=0)
    sigma_scales: list[float] = [0.1, 0.3, 1.0, 3.0, 10.0]  # noise-vs-lag sweep of sigma_c and sigma_alpha
    timing_repeats: int = Field(200, ge=1)


class TrackParams(_Section):
    """The ``track`` section of params.yaml."""

    seed: int = 6
    markers_body: list[tuple[float, float, float]] = [tuple(m) for m in MARKERS_BODY.tolist()]
    drop_marker: int = Field(3, ge=0)  # the marker removed for the 3-marker variant
    camera: CameraParams = CameraParams()
    frames: FrameParams = FrameParams()
    detection: DetectionParams = DetectionParams()
    matching: MatchingParams = MatchingParams()
    filter: FilterParams = FilterParams()
    motion: MotionParams = MotionParams()
    evaluation: EvaluationParams = EvaluationParams()

    @model_validator(mode="after")
    def _geometry(self):
        if len(self.markers_body) < 3:
            raise ValueError("markers_body needs at least 3 markers")
        if self.drop_marker >= len(self.markers_body):
            raise ValueError("drop_marker must index a marker of markers_body")
        return self
