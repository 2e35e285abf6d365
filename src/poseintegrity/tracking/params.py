"""Schema of the ``track`` section of params.yaml (stage 06, marker tracking).

Black and Salcudean, IEEE Transactions on Instrumentation and Measurement, 2024, DOI 10.1109/TIM.2024.3398108.
params.yaml is the only source of every value: no field has a default here (docs/references.md gives the source
of each published constant; everything else is our documented choice: the simulation, its noise levels,
P_p, P_o, the gyro rate split, the retuned filter sigmas).  Each field carries its bounds, and a rule between
keys raises :class:`~poseintegrity.schema.KeyRule` naming the key to change.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import AfterValidator, Field, model_validator

from poseintegrity.schema import KeyRule, OrderedRange, Section, Seed
from poseintegrity.tracking.geometry import tool_geometry_problem


def _positive_low(bounds: tuple[float, float]) -> tuple[float, float]:
    if not bounds[0] > 0:
        raise ValueError(f"a range of positive values needs low > 0, got {list(bounds)}")
    return bounds


def _non_negative_low(bounds: tuple[float, float]) -> tuple[float, float]:
    if not bounds[0] >= 0:
        raise ValueError(f"a range of durations needs low >= 0, got {list(bounds)}")
    return bounds


def _non_empty(values: list) -> list:
    if not values:
        raise ValueError("needs at least one value")
    return values


PositiveRange = Annotated[OrderedRange, AfterValidator(_positive_low)]  # [low, high], 0 < low <= high
NonNegativeRange = Annotated[OrderedRange, AfterValidator(_non_negative_low)]  # [low, high], 0 <= low <= high
PositiveList = Annotated[list[Annotated[float, Field(gt=0)]], AfterValidator(_non_empty)]  # non-empty, every entry > 0
Point = tuple[float, float, float]  # metres


class CameraParams(Section):
    """AHAT-like pinhole camera (docs/references.md: 512 x 512); the world frame is the camera frame shifted by origin_m."""

    width: int = Field(ge=16)
    height: int = Field(ge=16)
    focal_px: float = Field(gt=0)  # our choice: 11 mm spheres at 0.5 m give blobs of ~13-20 px (references: 10-20)
    origin_m: Point  # camera centre in the world frame (T_world_cam)


class FrameParams(Section):
    """IR reflectivity and depth synthesis (our choices; docs/references.md: IR raw 0-1000, depth in mm along the ray)."""

    ir_background: float = Field(ge=0)
    ir_noise_std: float = Field(ge=0)
    marker_ir: float = Field(gt=0)  # retro-reflective spheres saturate (clipped at 1000 by the detector)
    marker_ir_std: float = Field(ge=0)
    depth_noise_mm: float = Field(ge=0)  # per pixel, ToF noise
    depth_bias_std_mm: float = Field(ge=0)  # per marker and frame (multipath on the sphere)
    frame_depth_bias_std_mm: float = Field(ge=0)  # per frame, common to all pixels (ToF offset drift)
    background_depth_mm: float = Field(ge=0, le=65535)  # beyond the detector's depth window; uint16 mm
    supersampling: int = Field(ge=1, le=8)
    phantom_radius_px: PositiveRange
    phantom_depth_mm: PositiveRange
    phantom_elongation: OrderedRange  # axis ratio (major / minor) of non-round reflections, >= 1

    @model_validator(mode="after")
    def _elongation(self):
        if self.phantom_elongation[0] < 1:
            raise KeyRule("phantom_elongation", f"an axis ratio (major / minor) is >= 1, got {list(self.phantom_elongation)}")
        return self


class DetectionParams(Section):
    """Detector of section II-B; constants of their public code (docs/references.md) and our two additions
    (shape_measure "pixel", split_touching; see :mod:`poseintegrity.tracking.detection`)."""

    threshold: int = Field(ge=0, le=255)  # on the 8-bit image
    ir_clip: float = Field(gt=0)  # raw IR clipped here, then scaled to 8 bit
    min_area: float = Field(ge=0)
    max_area: float = Field(gt=0)
    min_circularity: float = Field(ge=0, le=1)
    min_convexity: float = Field(ge=0, le=1)
    depth_min_mm: float = Field(ge=0)
    depth_max_mm: float = Field(gt=0)  # published 900; AHAT reaches ~1 m and markers at 0.9 m read up to 0.9 m + noise
    depth_window: int = Field(ge=0, le=5)  # median over a (2w+1)^2 window at the centroid
    depth_offset_mm: float = Field(ge=0)  # sphere radius: the depth hits the surface, we want the centre
    shape_measure: Literal["contour", "pixel"]  # "contour": the published polygon form; "pixel": ours
    split_touching: bool  # split a blob made of two touching marker images
    split_max_residual_px: float = Field(gt=0)  # RMS boundary residual of each of the two circles
    depth_split_mm: float = Field(gt=0)  # a depth jump inside a blob this large: two markers, one behind

    @model_validator(mode="after")
    def _ranges(self):
        if self.min_area >= self.max_area:
            raise KeyRule("max_area", f"must be above min_area ({self.min_area:g}), got {self.max_area:g}")
        if self.depth_min_mm >= self.depth_max_mm:
            raise KeyRule("depth_max_mm", f"must be above depth_min_mm ({self.depth_min_mm:g}), got {self.depth_max_mm:g}")
        return self


class MatchingParams(Section):
    """Correspondence (Alg. 1-3 and the gated assignment).  docs/references.md: matching threshold 8 mm."""

    tolerance_m: float = Field(gt=0, le=0.1)
    gate_m: float = Field(gt=0, le=1.0)  # around the filter's predicted marker positions
    min_markers: int = Field(ge=3)
    distinct_m: float = Field(gt=0, le=0.1)  # inter-marker distances of all tools must differ by more than this


class FilterParams(Section):
    """SR-UKF constants.  Published (docs/references.md): alpha 1e-3, beta 2, kappa 3 - N, dt 0.0025 s, restart
    after 1 s, and the sigmas of :data:`PAPER_SIGMAS`; the sigmas used here are ours (params.yaml says why).
    The innovation gate and the restart after repeated rejections are ours too."""

    alpha: float = Field(gt=0, le=1)
    beta: float = Field(ge=0)  # 2 is optimal for Gaussian priors
    kappa: float | None  # None: 3 - N; N + kappa > 0 is checked against the marker count (TrackParams)
    sigma_r: float = Field(gt=0)  # m, eq. 16
    sigma_omega: float = Field(gt=0)  # rad/s, eq. 16
    sigma_c: float = Field(gt=0)  # m/s^2, eq. 8
    sigma_alpha: float = Field(gt=0)  # rad/s^2, eq. 9
    init_std_omega: float = Field(gt=0)
    init_std_velocity: float = Field(gt=0)
    max_position_std: float = Field(gt=0)
    dt: float = Field(gt=0, le=0.1)  # filter clock: predictions in steps of at most dt
    restart_after_s: float = Field(gt=0)
    innovation_gate_chi2: float = Field(gt=0)  # per marker, 3 dof: chi2.ppf(1 - 1e-4, 3)
    restart_after_rejections: int = Field(ge=1)  # consecutive frames whose every marker failed the gate


# The sigmas Black and Salcudean published (docs/references.md): sigma_r^2 = 0.00025, sigma_omega^2 = 0.1,
# sigma_c = sigma_alpha = sqrt(0.5).
PAPER_SIGMAS = {"sigma_r": math.sqrt(0.00025), "sigma_omega": math.sqrt(0.1), "sigma_c": math.sqrt(0.5), "sigma_alpha": math.sqrt(0.5)}


class MotionParams(Section):
    """Simulation of section II-F (all our choices; the paper published none of them)."""

    duration_s: float = Field(gt=0)
    sim_dt: float = Field(gt=0, le=0.01)
    home_m: Point
    accel_std: float = Field(ge=0)  # m/s^2, random linear acceleration (OU)
    accel_tau_s: float = Field(gt=0)
    spring_hz: float = Field(ge=0)  # keeps the tool in front of the camera
    damping: float = Field(ge=0)
    omega_std: float = Field(ge=0)  # rad/s, body angular velocity (OU) of the accuracy runs
    omega_tau_s: float = Field(gt=0)
    frame_interval_s: float = Field(gt=0)  # paper: 45.98 +- 7.67 ms
    frame_jitter_s: float = Field(ge=0)
    p_gyro_2: float = Field(ge=0, le=1)  # P_2: two gyro samples per frame, else three (P_3 = 1 - P_2)
    gyro_noise_std: float = Field(ge=0)  # rad/s
    p_occlusion: float = Field(ge=0, le=1)  # P_o per marker and frame
    p_phantom: float = Field(ge=0, le=1)  # P_p per phantom slot and frame
    max_phantoms: int = Field(ge=0)
    phantom_round_fraction: float = Field(ge=0, le=1)
    occlusions: list[tuple[float, float]]  # (start_s, duration_s): all markers hidden

    @model_validator(mode="after")
    def _times(self):
        if self.frame_interval_s <= 4 * self.sim_dt:
            raise KeyRule("frame_interval_s", f"must exceed 4 sim_dt ({4 * self.sim_dt:g} s): frames are at least 4 grid steps apart, got {self.frame_interval_s:g}")
        for k, (start, duration) in enumerate(self.occlusions):
            if not (start >= 0 and duration > 0 and start + duration <= self.duration_s):
                raise KeyRule(f"occlusions.{k}", f"(start_s, duration_s) must lie inside [0, duration_s = {self.duration_s:g}] "
                                                 f"with a positive duration, got {[start, duration]}")
        return self


class HandMotionParams(Section):
    """Motion (a), paper-like (section III: "a series of large motions and many full 360 deg rotations in all
    axes ... with markers periodically occluded briefly"): full turns about the body x, y, z axes in turn, each
    with a smooth sin^2 speed profile lasting turn_s (peak speed 4 pi / turn_s), separated by pauses; the
    translation is the OU walk of ``motion`` with a larger acceleration; brief per-marker occlusions (a finger
    passing over a marker) instead of the i.i.d. P_o of ``motion``.  All our choices (see params.yaml)."""

    turn_s: PositiveRange  # duration of one full turn, s (uniform)
    pause_s: NonNegativeRange  # between turns, s (uniform)
    wobble_std: float = Field(ge=0)  # rad/s, OU angular velocity added throughout (hand tremor, re-grip)
    accel_std: float = Field(ge=0)  # m/s^2, the OU linear acceleration of the large motions
    occlusion_rate_hz: float = Field(ge=0)  # per marker
    occlusion_s: PositiveRange  # duration of a brief occlusion, s (uniform)


class EvaluationParams(Section):
    """Section III on our simulation."""

    success_frames: int = Field(ge=1)  # paper: 10 000 frames of large motion
    success_omega_std: float = Field(ge=0)  # rad/s, motion (b): the stress test, OU spin of this spread
    correct_tolerance_m: float = Field(gt=0, le=0.1)  # per matched point; a wrong match is off by >= 35 mm
    lag_max_ms: float = Field(gt=0)
    sigma_scales: PositiveList  # noise-vs-lag sweep of sigma_c and sigma_alpha
    timing_repeats: int = Field(ge=1)
    sweep_distances_m: PositiveList  # small-blob sweep; inside the detector's depth window (TrackParams)
    sweep_focal_px: float = Field(gt=0)
    sweep_poses: int = Field(ge=1)  # random tool orientations per distance
    sweep_phantoms: int = Field(ge=1)  # elongated phantoms rendered for the rejection rate
    replay_s: float = Field(gt=0)  # seconds of recording written as PNG frames and replayed from disk
    multi_tool_frames: int = Field(ge=1)  # frames of the two-tool and phantom-rich runs
    phantom_rich_max: int = Field(ge=0)  # phantoms per frame (binomial, p_phantom) in the phantom-rich scene
    second_tool: list[Point]  # m; checked against markers_body (TrackParams)


class TrackParams(Section):
    """The ``track`` section of params.yaml."""

    seed: Seed
    markers_body: list[Point]  # m, body frame (docs/references.md)
    drop_marker: int = Field(ge=0)  # the marker removed for the 3-marker variant (params.yaml says why)
    camera: CameraParams
    frames: FrameParams
    detection: DetectionParams
    matching: MatchingParams
    filter: FilterParams
    motion: MotionParams
    hand: HandMotionParams
    evaluation: EvaluationParams

    @model_validator(mode="after")
    def _geometry(self):
        n, distinct = len(self.markers_body), self.matching.distinct_m
        if n < self.matching.min_markers + 1:
            raise KeyRule("markers_body", f"needs at least matching.min_markers + 1 = {self.matching.min_markers + 1} markers "
                                          f"(the 3-marker variant removes one), got {n}")
        if self.drop_marker >= n:
            raise KeyRule("drop_marker", f"must index a marker of markers_body (0-{n - 1}), got {self.drop_marker}")
        for key, tools in (("markers_body", {"markers_body": self.markers_body}),
                           ("evaluation.second_tool", {"markers_body": self.markers_body, "second_tool": self.evaluation.second_tool})):
            problem = tool_geometry_problem({name: np.array(m) for name, m in tools.items()}, distinct)
            if problem:
                raise KeyRule(key, problem)
        if self.filter.kappa is not None and 3 * n + 6 + self.filter.kappa <= 0:
            raise KeyRule("filter.kappa", f"N + kappa must be positive (N = 3 markers + 6 = {3 * n + 6}), got {self.filter.kappa:g}")
        window = (self.detection.depth_min_mm, self.detection.depth_max_mm)
        outside = [d for d in self.evaluation.sweep_distances_m if not window[0] <= d * 1000 <= window[1]]
        if outside:
            raise KeyRule("evaluation.sweep_distances_m", f"must lie inside the detector's depth window {window[0]:g}-{window[1]:g} mm, got {outside} m")
        if self.motion.home_m[2] - self.camera.origin_m[2] <= 0:
            raise KeyRule("motion.home_m", f"must lie in front of the camera (z above camera.origin_m's {self.camera.origin_m[2]:g} m), got {list(self.motion.home_m)}")
        return self
