"""The tracking loop: marker frames and gyro samples in, filtered pose out (sections II-D, II-E).

Frames go through correspondence (gated by the filter's prediction once it runs) and a partial
measurement update with the markers that were matched; gyro samples (body frame) are rotated into the
world frame with the current estimate and update omega only.  Between measurements the filter predicts in
steps of at most ``dt`` (the paper's 400 Hz filter clock).

Failure handling (every step returns a flag, nothing raises):
- "no_points" / "no_markers": nothing detected / nothing matched; the filter keeps predicting;
- "restart": no marker for ``restart_after_s`` and no gyro fused (their code restarts after 1 s): the
  filter waits for the next frame with >= min_markers matched markers;
- "diverged": NaN or runaway covariance (see :class:`UnscentedMarkerFilter`); re-initialised from the next
  good frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from poseintegrity.tracking.correspondence import match_markers
from poseintegrity.tracking.geometry import transform_points
from poseintegrity.tracking.kabsch import pose_from_points
from poseintegrity.tracking.params import FilterParams, MatchingParams
from poseintegrity.tracking.srukf import SquareRootUKF
from poseintegrity.tracking.unscented import UnscentedMarkerFilter

NAN_POSE = np.full((4, 4), np.nan)


@dataclass(frozen=True)
class FrameResult:
    """Outcome of one marker frame.

    assignment : (m,) int, index of each geometry marker's point or -1; T_measured : (4, 4) Kabsch pose
    of the matched points (NaN if < 3); T_filtered : (4, 4) filter pose after the update (NaN if the filter
    is not running); flag : "ok" or the reason the frame was not (fully) used.
    """

    assignment: np.ndarray
    T_measured: np.ndarray
    T_filtered: np.ndarray
    flag: str


class MarkerTracker:
    """SR-UKF (or another :class:`UnscentedMarkerFilter`) fed by matched marker frames and a gyro.

    markers_body : (m, 3) geometry, metres.  use_gyro : fuse gyro samples (else they only advance time).
    """

    def __init__(
        self,
        markers_body: np.ndarray,
        filter_params: FilterParams = FilterParams(),
        matching: MatchingParams = MatchingParams(),
        use_gyro: bool = True,
        filter_cls: type[UnscentedMarkerFilter] = SquareRootUKF,
    ):
        self.markers_body = np.asarray(markers_body, dtype=float)
        self.filter = filter_cls(self.markers_body, filter_params)
        self.params = filter_params
        self.matching = matching
        self.use_gyro = use_gyro
        self.t = 0.0
        self.last_marker_t = -np.inf
        self.n_restarts = 0

    def pose(self) -> np.ndarray:
        """T_world_body (4, 4) of the filter, NaN while it is not running."""
        return self.filter.pose() if self.filter.initialized else NAN_POSE

    def advance(self, t: float) -> str:
        """Predict up to time t (s) in steps of at most dt.  Returns "" or the failure flag."""
        if not self.filter.initialized:
            self.t = t
            return ""
        if not self.use_gyro and t - self.last_marker_t > self.params.restart_after_s:
            self.filter.initialized = False
            self.n_restarts += 1
            self.t = t
            return "restart"
        n_steps = int(np.ceil((t - self.t) / self.params.dt - 1e-9))
        for _ in range(max(n_steps, 0)):
            if not self.filter.predict((t - self.t) / n_steps if n_steps else 0.0):
                self.t = t
                return "diverged"
        self.t = t
        return ""

    def gyro(self, t: float, omega_body: np.ndarray) -> str:
        """A gyro sample at t: omega_body (3,) rad/s in the body frame.  Returns "ok" or a flag."""
        flag = self.advance(t)
        if flag or not self.use_gyro or not self.filter.initialized:
            return flag or ("ok" if self.filter.initialized else "not_running")
        omega_world = self.filter.pose()[:3, :3] @ np.asarray(omega_body, dtype=float)
        ok = self.filter.update(omega_world, np.zeros(self.filter.n, dtype=bool), gyro=True)
        return "ok" if ok else "diverged"

    def frame(self, t: float, points: np.ndarray) -> FrameResult:
        """A marker frame at t: measured points (n, 3), metres, world frame (may be empty, NaN rows ignored)."""
        flag = self.advance(t)
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        predicted = self.filter.markers() if self.filter.initialized else None
        assignment = match_markers(
            points, self.markers_body, predicted, tolerance_m=self.matching.tolerance_m,
            gate_m=self.matching.gate_m, min_markers=self.matching.min_markers,
        )
        matched = assignment >= 0
        T_measured = pose_from_points(points[assignment[matched]], self.markers_body[matched]) if matched.sum() >= 3 else NAN_POSE
        if not matched.any():
            return FrameResult(assignment, T_measured, self.pose(), flag or ("no_markers" if len(points) else "no_points"))
        if not self.filter.initialized:  # without a prediction a match has >= min_markers markers
            self.filter.initialize(transform_points(T_measured, self.markers_body))  # start from a good measurement
            self.last_marker_t = t
            return FrameResult(assignment, T_measured, self.pose(), flag or "initialized")
        ok = self.filter.update(points[assignment[matched]].ravel(), matched, gyro=False)
        self.last_marker_t = t
        if not ok:
            return FrameResult(assignment, T_measured, NAN_POSE, "diverged")
        return FrameResult(assignment, T_measured, self.pose(), flag or "ok")
