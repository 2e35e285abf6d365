"""Schema of the ``track`` section of params.yaml (stage 06, marker tracking).

Black and Salcudean, IEEE Transactions on Instrumentation and Measurement, 2024, DOI 10.1109/TIM.2024.3398108.
params.yaml is the only source of every value: no field has a default here (docs/references.md gives the source
of each published constant; everything else is our documented choice: the simulation, its noise levels,
P_p, P_o, the gyro rate split, the retuned filter sigmas).  Each field carries its bounds, and a rule between
keys raises :class:`~poseintegrity.schema.KeyRule` naming the key to change.
"""

from __future__ import annotations

import math
from itertools import combinations
from typing import Annotated, Literal

import numpy as np
from pydantic import AfterValidator, Field, model_validator

from poseintegrity.schema import FromList, KeyRule, Section, Seed, ordered_range


def _non_empty(values: list) -> list:
    if not values:
        raise ValueError("needs at least one value")
    return values


def tool_geometry_problem(tools: dict[str, np.ndarray], distinct_m: float) -> str:
    """Why these marker bodies cannot be told apart or posed, or "" if they can.

    tools : name -> (m, 3) marker centres, metres (the first tool is ``markers_body``, the
    geometry of docs/references.md).  Each tool needs at least 3 markers that do not lie on one line (a line
    of markers leaves the rotation about it open: Alg. 4 needs 3 non-collinear points), i.e. whose centred
    points spread more than distinct_m off their best line; and every inter-marker distance, within a tool
    and across tools, must differ from every other by more than distinct_m (m): Alg. 2 votes by distance, so
    a shared distance lets one pair vote for another's.
    """
    pairs = []
    for name, markers in tools.items():
        markers = np.asarray(markers, dtype=float).reshape(-1, 3)
        if len(markers) < 3:
            return f"tool {name!r} has {len(markers)} markers; at least 3 are needed for a pose"
        spread = np.linalg.svd(markers - markers.mean(axis=0), compute_uv=False)
        if spread[1] <= distinct_m:
            return f"the markers of tool {name!r} lie on one line (within {distinct_m * 1000:g} mm): the rotation about it is undetermined"
        D = np.linalg.norm(markers[:, None] - markers[None], axis=-1)
        pairs += [(D[i, j], f"{name} markers {i + 1}-{j + 1}") for i, j in combinations(range(len(markers)), 2)]
    pairs.sort()
    for (d1, a), (d2, b) in zip(pairs, pairs[1:]):
        if d2 - d1 <= distinct_m:
            return (f"inter-marker distances are not distinct: {a} = {d1 * 1000:.2f} mm and {b} = {d2 * 1000:.2f} mm "
                    f"differ by <= {distinct_m * 1000:g} mm (correspondence by distance voting cannot tell them apart)")
    return ""


# Bounds shared by several keys. Each refuses what no setting can mean (a typo such as 1e9), not what is unusual.
IR_MAX = 65535.0  # raw IR is a 16-bit reading (the AHAT's reaches ~1000; a marker saturates it)
DEPTH_MAX_MM = 65535.0  # depth images are uint16 mm
IMAGE_MAX_PX = 4096  # a side of the simulated frame: larger ones take GBs per recording
FOCAL_MAX_PX = 10_000.0  # beyond it a 512 px frame sees under 3 deg: no tracking camera
ANGULAR_MAX = 100.0  # rad/s (and its spreads): 16 turns a second is no hand
ACCEL_MAX = 1000.0  # m/s^2 (100 g): no hand, no tool
SECONDS_MAX = 3600.0  # an hour: longer than any simulated recording or time constant here
MAX_SIM_STEPS = 1e7  # motion.duration_s / motion.sim_dt: 10^7 steps of the simulated trajectory ~ 1 GB
FRAMES_MAX = 1_000_000  # frames or repeats of one run: ~13 h of 46 ms frames; minutes per 10^4 on 2 cores

Room = Annotated[float, Field(ge=-10, le=10)]  # m: a position in the camera's room
Point = Annotated[tuple[Room, Room, Room], FromList]  # metres
MarkerCoordinate = Annotated[float, Field(ge=-0.5, le=0.5)]  # m: a marker on a hand-held tool, from its centre
MarkerPoint = Annotated[tuple[MarkerCoordinate, MarkerCoordinate, MarkerCoordinate], FromList]
Seconds = ordered_range(gt=0, le=60)  # [low, high] s of a hand's turn or a finger's occlusion: under a minute
PositiveList = Annotated[list[Annotated[float, Field(gt=0, le=1000)]], AfterValidator(_non_empty)]  # non-empty


class AhatCameraParams(Section):
    """AHAT-like pinhole camera (docs/references.md: 512 x 512); the world frame is the camera frame shifted by origin_m."""

    width: int = Field(ge=16, le=IMAGE_MAX_PX)
    height: int = Field(ge=16, le=IMAGE_MAX_PX)
    focal_px: float = Field(gt=0, le=FOCAL_MAX_PX)  # our choice: 11 mm spheres at 0.5 m give blobs of ~13-20 px (references: 10-20)
    origin_m: Point  # camera centre in the world frame (T_world_cam)


class FrameParams(Section):
    """IR reflectivity and depth synthesis (our choices; docs/references.md: IR raw 0-1000, depth in mm along the ray)."""

    ir_background: float = Field(ge=0, le=IR_MAX)
    ir_noise_std: float = Field(ge=0, le=IR_MAX)
    marker_ir: float = Field(gt=0, le=IR_MAX)  # retro-reflective spheres saturate (clipped at 1000 by the detector)
    marker_ir_std: float = Field(ge=0, le=IR_MAX)
    depth_noise_mm: float = Field(ge=0, le=1000)  # per pixel, ToF noise; a metre of it leaves no depth to read
    depth_bias_std_mm: float = Field(ge=0, le=1000)  # per marker and frame (multipath on the sphere); same bound
    frame_depth_bias_std_mm: float = Field(ge=0, le=1000)  # per frame, common to all pixels (ToF offset drift); same
    background_depth_mm: float = Field(ge=0, le=DEPTH_MAX_MM)  # beyond the detector's depth window; uint16 mm
    supersampling: int = Field(ge=1, le=8)
    phantom_radius_px: ordered_range(gt=0, le=IMAGE_MAX_PX / 2)  # no reflection larger than the frame
    phantom_depth_mm: ordered_range(gt=0, le=DEPTH_MAX_MM)
    phantom_elongation: ordered_range(ge=1, le=100)  # axis ratio (major / minor) of non-round reflections, >= 1


class DetectionParams(Section):
    """Detector of section II-B; constants of their public code (docs/references.md) and our two additions
    (shape_measure "pixel", split_touching; see :mod:`poseintegrity.tracking.markers.detection`)."""

    threshold: int = Field(ge=0, le=255)  # on the 8-bit image
    ir_clip: float = Field(gt=0, le=IR_MAX)  # raw IR clipped here, then scaled to 8 bit
    min_area: float = Field(ge=0, le=IMAGE_MAX_PX**2)  # px^2: at most the whole frame
    max_area: float = Field(gt=0, le=IMAGE_MAX_PX**2)
    min_circularity: float = Field(ge=0, le=1)
    min_convexity: float = Field(ge=0, le=1)
    depth_min_mm: float = Field(ge=0, le=DEPTH_MAX_MM)
    depth_max_mm: float = Field(gt=0, le=DEPTH_MAX_MM)  # published 900; AHAT reaches ~1 m and markers at 0.9 m read up to 0.9 m + noise
    depth_window: int = Field(ge=0, le=5)  # median over a (2w+1)^2 window at the centroid
    depth_offset_mm: float = Field(ge=0, le=100)  # sphere radius: the depth hits the surface, we want the centre; 100 mm is no marker
    shape_measure: Literal["contour", "pixel"]  # "contour": the published polygon form; "pixel": ours
    split_touching: bool  # split a blob made of two touching marker images
    split_max_residual_px: float = Field(gt=0, le=100)  # RMS boundary residual of each of the two circles; 100 px fits any blob
    depth_split_mm: float = Field(gt=0, le=1000)  # a depth jump inside a blob this large: two markers, one behind

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
    min_markers: int = Field(ge=3, le=100)  # the filter's state grows by 3 per marker: 100 is no hand-held tool
    distinct_m: float = Field(gt=0, le=0.1)  # inter-marker distances of all tools must differ by more than this


class FilterParams(Section):
    """SR-UKF constants.  Published (docs/references.md): alpha 1e-3, beta 2, kappa 3 - N, dt 0.0025 s, restart
    after 1 s, and the sigmas of :data:`PAPER_SIGMAS`; the sigmas used here are ours (params.yaml says why).
    The innovation gate and the restart after repeated rejections are ours too."""

    alpha: float = Field(gt=0, le=1)
    beta: float = Field(ge=0, le=100)  # 2 is optimal for Gaussian priors; 100 weights the centre point alone
    # None: 3 - N; N + kappa > 0 is checked against the marker count (TrackParams); beyond +-1000 one sigma point
    # holds nearly all the weight
    kappa: float | None = Field(ge=-1000, le=1000)
    sigma_r: float = Field(gt=0, le=1)  # m, eq. 16; a metre of measurement noise: a marker anywhere in the room
    sigma_omega: float = Field(gt=0, le=ANGULAR_MAX)  # rad/s, eq. 16
    sigma_c: float = Field(gt=0, le=ACCEL_MAX)  # m/s^2, eq. 8
    sigma_alpha: float = Field(gt=0, le=10 * ACCEL_MAX)  # rad/s^2, eq. 9; 10^4 rad/s^2 spins a hand up in 10 ms
    init_std_omega: float = Field(gt=0, le=ANGULAR_MAX)  # rad/s
    init_std_velocity: float = Field(gt=0, le=100)  # m/s: faster than any hand
    max_position_std: float = Field(gt=0, le=100)  # m: restart when the position spread exceeds it; beyond a room
    dt: float = Field(gt=0, le=0.1)  # filter clock: predictions in steps of at most dt
    restart_after_s: float = Field(gt=0, le=SECONDS_MAX)
    innovation_gate_chi2: float = Field(gt=0, le=1000)  # per marker, 3 dof: chi2.ppf(1 - 1e-4, 3); 1000 gates nothing
    restart_after_rejections: int = Field(ge=1, le=FRAMES_MAX)  # consecutive frames whose every marker failed the gate


# The sigmas Black and Salcudean published (docs/references.md): sigma_r^2 = 0.00025, sigma_omega^2 = 0.1,
# sigma_c = sigma_alpha = sqrt(0.5).
PAPER_SIGMAS = {"sigma_r": math.sqrt(0.00025), "sigma_omega": math.sqrt(0.1), "sigma_c": math.sqrt(0.5), "sigma_alpha": math.sqrt(0.5)}


class MotionParams(Section):
    """Simulation of section II-F (all our choices; the paper published none of them)."""

    duration_s: float = Field(gt=0, le=SECONDS_MAX)
    sim_dt: float = Field(gt=0, le=0.01)  # with duration_s at most MAX_SIM_STEPS steps (checked below)
    home_m: Point
    accel_std: float = Field(ge=0, le=ACCEL_MAX)  # m/s^2, random linear acceleration (OU)
    accel_tau_s: float = Field(gt=0, le=SECONDS_MAX)
    spring_hz: float = Field(ge=0, le=100)  # keeps the tool in front of the camera; 100 Hz is a vibration, not a hand
    damping: float = Field(ge=0, le=100)  # damping ratio of that spring: 1 is critical, 100 a tool stuck in honey
    omega_std: float = Field(ge=0, le=ANGULAR_MAX)  # rad/s, body angular velocity (OU) of the accuracy runs
    omega_tau_s: float = Field(gt=0, le=SECONDS_MAX)
    frame_interval_s: float = Field(gt=0, le=10)  # paper: 45.98 +- 7.67 ms; a frame every 10 s tracks nothing
    frame_jitter_s: float = Field(ge=0, le=10)
    p_gyro_2: float = Field(ge=0, le=1)  # P_2: two gyro samples per frame, else three (P_3 = 1 - P_2)
    gyro_noise_std: float = Field(ge=0, le=ANGULAR_MAX)  # rad/s
    p_occlusion: float = Field(ge=0, le=1)  # P_o per marker and frame
    p_phantom: float = Field(ge=0, le=1)  # P_p per phantom slot and frame
    max_phantoms: int = Field(ge=0, le=1000)  # phantom slots per frame: each a blob to render, detect and reject
    phantom_round_fraction: float = Field(ge=0, le=1)
    # (start_s, duration_s): all markers hidden; inside duration_s (checked below)
    occlusions: list[Annotated[tuple[Annotated[float, Field(ge=0, le=SECONDS_MAX)],
                                     Annotated[float, Field(gt=0, le=SECONDS_MAX)]], FromList]]

    @model_validator(mode="after")
    def _times(self):
        steps = self.duration_s / self.sim_dt
        if steps > MAX_SIM_STEPS:
            raise KeyRule("sim_dt", f"duration_s / sim_dt = {steps:.3g} simulation steps, more than {MAX_SIM_STEPS:g} "
                                    f"(GBs of trajectory): raise sim_dt or shorten duration_s, got {self.sim_dt:g}")
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

    turn_s: Seconds  # duration of one full turn, s (uniform)
    pause_s: ordered_range(ge=0, le=60)  # between turns, s (uniform); under a minute
    wobble_std: float = Field(ge=0, le=ANGULAR_MAX)  # rad/s, OU angular velocity added throughout (hand tremor, re-grip)
    accel_std: float = Field(ge=0, le=ACCEL_MAX)  # m/s^2, the OU linear acceleration of the large motions
    occlusion_rate_hz: float = Field(ge=0, le=1000)  # per marker; more than one occlusion a millisecond is no finger
    occlusion_s: Seconds  # duration of a brief occlusion, s (uniform)


class PaceParams(Section):
    """Motion (c), the paper's pace: the accuracy recording's motion (``motion``) slowed to the pace the paper's
    own numbers allow (params.yaml derives it from the published lag and errors):
    :func:`~poseintegrity.tracking.simulation.pace.paced_motion` sets the OU angular velocity and linear acceleration
    spreads so that the truth's per-axis RMS rates, averaged over the three axes, are these."""

    euler_rate_rms: float = Field(gt=0, le=ANGULAR_MAX)  # rad/s, RMS rate of each Unity Euler angle (mean over the three)
    velocity_rms: float = Field(gt=0, le=100)  # m/s, RMS velocity along each position axis (mean over x, y, z); 100 m/s is no hand


class EvaluationParams(Section):
    """Section III on our simulation."""

    success_frames: int = Field(ge=1, le=FRAMES_MAX)  # paper: 10 000 frames of large motion
    success_omega_std: float = Field(ge=0, le=ANGULAR_MAX)  # rad/s, motion (b): the stress test, OU spin of this spread
    correct_tolerance_m: float = Field(gt=0, le=0.1)  # per matched point; a wrong match is off by >= 35 mm
    lag_max_ms: float = Field(gt=0, le=60_000)  # lags searched up to this; a minute is no lag
    sigma_scales: PositiveList  # noise-vs-lag sweep of sigma_c and sigma_alpha (each scale at most 1000)
    timing_repeats: int = Field(ge=1, le=FRAMES_MAX)
    # small-blob sweep; inside the detector's depth window (TrackParams)
    sweep_distances_m: Annotated[list[Annotated[float, Field(gt=0, le=DEPTH_MAX_MM / 1000)]], AfterValidator(_non_empty)]
    sweep_focal_px: float = Field(gt=0, le=FOCAL_MAX_PX)
    sweep_poses: int = Field(ge=1, le=10_000)  # random tool orientations per distance; each renders a frame
    sweep_phantoms: int = Field(ge=1, le=100_000)  # elongated phantoms rendered for the rejection rate
    replay_s: float = Field(gt=0, le=600)  # s of recording written as PNG frames and replayed: 10 min ~ GBs of PNGs
    multi_tool_frames: int = Field(ge=1, le=FRAMES_MAX)  # frames of the two-tool and phantom-rich runs
    phantom_rich_max: int = Field(ge=0, le=1000)  # phantoms per frame (binomial, p_phantom) in the phantom-rich scene
    second_tool: list[MarkerPoint]  # m; checked against markers_body (TrackParams)
    # ours (issue 49): intervals of the headline rates and errors, blocks of the recording resampled with replacement
    interval_draws: int = Field(ge=100, le=100_000)
    interval_level: float = Field(gt=0, lt=1)  # two-sided, e.g. 0.9: the 5-95 % of the draws
    interval_block_s: float = Field(gt=0, le=600)  # s: frames this close share a motion, an occlusion, a phantom


class TrackParams(Section):
    """The ``track`` section of params.yaml."""

    seed: Seed
    markers_body: list[MarkerPoint]  # m, body frame (docs/references.md)
    drop_marker: int = Field(ge=0, le=100)  # the marker removed for the 3-marker variant (params.yaml says why); an index of markers_body
    camera: AhatCameraParams
    frames: FrameParams
    detection: DetectionParams
    matching: MatchingParams
    filter: FilterParams
    motion: MotionParams
    hand: HandMotionParams
    pace: PaceParams
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
