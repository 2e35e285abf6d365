"""The tracking loop: marker frames and gyro samples in, filtered pose out (sections II-D, II-E).

Frames go through correspondence (gated by the filter's prediction once it runs) and a partial
measurement update with the markers that were matched; gyro samples (body frame) are rotated into the
world frame with the current estimate and update omega only.  Between measurements the filter predicts in
steps of at most ``dt`` (the paper's 400 Hz filter clock).

Bad arguments (checked once per call at :meth:`MarkerTracker.frame` / :meth:`MarkerTracker.gyro`, never inside the
filter) raise :class:`~poseintegrity.errors.ArgumentError` naming the argument: a timestamp that is not a finite
number of seconds within +-1e12 (None, text, NaN, 1e300), points that are not an (n, 3) array of numbers (NaN
rows are allowed and ignored), a gyro sample that is not 3 numbers.  Bad data returns a flag instead:

Failure handling (every step returns a flag):
- "no_points" / "no_markers": nothing detected / nothing matched; the filter keeps predicting;
- "gated" (ours): every matched marker lies outside the innovation gate, i.e. its squared Mahalanobis distance
  to the predicted marker, under the predicted covariance plus sigma_r^2 I, exceeds innovation_gate_chi2
  (3 dof); the measurement is not fused and the filter keeps predicting.  Markers outside the gate in a frame
  whose other markers pass are left out of the update ("ok" then; ``n_gated`` counts them).
- "restart": no marker for ``restart_after_s`` and (with use_gyro) no gyro fused either (their code restarts
  after 1 s; a time jump longer than that is one, so a clock glitch never runs the filter for hours): the
  filter waits for the next frame with >= min_markers matched markers; or (ours) ``restart_after_rejections``
  frames in a row were gated although they had >= min_markers rigidly matched markers: the object really
  moved (or the filter is lost), so the filter restarts from that measurement;
- "diverged": NaN or runaway covariance (see :class:`UnscentedMarkerFilter`); re-initialised from the next
  good frame;
- "stale": a measurement older than the filter's time (time went backwards); ignored; "bad_gyro": a non-finite gyro
  sample or one above MAX_RATE_RAD_S; ignored.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from poseintegrity.config import published
from poseintegrity.errors import check_array
from poseintegrity.params.track import FilterParams, MatchingParams
from poseintegrity.poses import NAN_POSE
from poseintegrity.tracking.filter.srukf import SquareRootUKF
from poseintegrity.tracking.filter.unscented import UnscentedMarkerFilter
from poseintegrity.tracking.io.timestamps import check_timestamp
from poseintegrity.tracking.markers.correspondence import match_markers_unchecked
from poseintegrity.tracking.markers.geometry import transform_points
from poseintegrity.tracking.markers.kabsch import pose_from_points_unchecked

MAX_RATE_RAD_S = 100.0  # beyond any MEMS gyro's range (2000 deg/s = 35 rad/s): a sample above it is bad_gyro


def check_points(points: object, name: str = "points") -> np.ndarray:
    """points as a float (n, 3) array (an empty sequence is (0, 3)); NaN / inf rows are kept (the matchers
    ignore them); :class:`~poseintegrity.errors.ArgumentError` if it is not an (n, 3) array of numbers."""
    if type(points) is np.ndarray and points.dtype == np.float64 and points.ndim == 2 and points.shape[1] == 3:
        return points
    if isinstance(points, (list, tuple, np.ndarray)) and np.size(points) == 0:
        return np.zeros((0, 3))
    return check_array(name, points, shape=(None, 3), finite=False)


def check_rates(omega: object, name: str = "omega_body") -> np.ndarray:
    """A gyro sample as a float (3,) array (non-finite entries are kept: the tracker flags them bad_gyro)."""
    if type(omega) is np.ndarray and omega.shape == (3,) and omega.dtype == np.float64:
        return omega
    return check_array(name, omega, shape=(3,), finite=False)


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
    filter_params, matching : ``track.filter`` / ``track.matching``; None takes the published defaults (params.yaml).
    """

    def __init__(
        self,
        markers_body: np.ndarray,
        filter_params: FilterParams | None = None,
        matching: MatchingParams | None = None,
        use_gyro: bool = True,
        filter_cls: type[UnscentedMarkerFilter] = SquareRootUKF,
    ):
        filter_params = published("track.filter") if filter_params is None else filter_params
        matching = published("track.matching") if matching is None else matching
        self.filter = filter_cls(markers_body, filter_params)  # refuses < 3, non-finite or collinear markers
        self.markers_body = self.filter.markers_body
        self.params = filter_params
        self.matching = matching
        self.use_gyro = use_gyro
        self.t = -np.inf  # time of the last event; any first timestamp is accepted
        self.last_marker_t = -np.inf
        self.last_fused_t = -np.inf  # last marker or gyro update
        self.n_restarts = 0
        self.n_rejected = 0  # consecutive gated frames
        self.n_gated = 0  # markers left out of an update by the innovation gate

    def pose(self) -> np.ndarray:
        """T_world_body (4, 4) of the filter, NaN while it is not running."""
        return self.filter.pose() if self.filter.initialized else NAN_POSE

    def advance(self, t: float) -> str:
        """Predict up to time t (s) in steps of at most dt.  Returns "" or the failure flag."""
        if not self.filter.initialized:
            self.t = t
            return ""
        if t - (self.last_fused_t if self.use_gyro else self.last_marker_t) > self.params.restart_after_s:
            self.filter.initialized = False
            self.n_restarts += 1
            self.t = t
            return "restart"
        n_steps = max(int(np.ceil((t - self.t) / self.params.dt - 1e-9)), 0)
        ok = self.filter.predict_steps(n_steps, (t - self.t) / n_steps if n_steps else 0.0)
        self.t = t
        return "" if ok else "diverged"

    def gyro(self, t: float, omega_body: np.ndarray) -> str:
        """A gyro sample at t: omega_body (3,) rad/s in the body frame.  Returns "ok" or a flag (module
        docstring); a bad timestamp or a sample that is not 3 numbers raises ArgumentError."""
        return self.gyro_unchecked(check_timestamp(t), check_rates(omega_body))

    def gyro_unchecked(self, t: float, omega_body: np.ndarray) -> str:
        """:meth:`gyro` on checked arguments (t as :func:`check_timestamp` returns it, omega_body float (3,) rad/s):
        the per-sample path of callers whose samples are known to be good."""
        if t < self.t - 1e-9:
            return "stale"
        if not np.all(np.abs(omega_body) <= MAX_RATE_RAD_S):  # also False for NaN
            return "bad_gyro"
        flag = self.advance(t)
        if flag or not self.use_gyro or not self.filter.initialized:
            return flag or ("ok" if self.filter.initialized else "not_running")
        omega_world = self.filter.pose()[:3, :3] @ omega_body
        ok = self.filter._update(omega_world, np.zeros(self.filter.n, dtype=bool), gyro=True)
        if ok:
            self.last_fused_t = t
        return "ok" if ok else "diverged"

    def innovation_ok(self, points: np.ndarray, observed: np.ndarray) -> np.ndarray:
        """(n,) bool: observed markers whose point (n, 3 rows in geometry order) passes the innovation gate."""
        return innovation_gate(np.ascontiguousarray(self.filter.sqrt_covariance()), self.filter.x, np.ascontiguousarray(points, dtype=np.float64),
                               observed, float(self.params.sigma_r) ** 2, float(self.params.innovation_gate_chi2))

    def frame(self, t: float, points: np.ndarray) -> FrameResult:
        """A marker frame at t: measured points (n, 3), metres, world frame (may be empty, NaN rows ignored).
        Returns a :class:`FrameResult` whose flag says whether (and why not) the frame was used; a bad timestamp
        or points that are not an (n, 3) array raise ArgumentError."""
        return self.frame_unchecked(check_timestamp(t), check_points(points))

    def frame_unchecked(self, t: float, points: np.ndarray) -> FrameResult:
        """:meth:`frame` on checked arguments (t as :func:`check_timestamp` returns it, points float (n, 3) metres):
        the per-frame path of callers whose frames are known to be good."""
        if t < self.t - 1e-9:
            return FrameResult(np.full(self.filter.n, -1), NAN_POSE, self.pose(), "stale")
        flag = self.advance(t)
        predicted = self.filter.markers() if self.filter.initialized else None
        assignment = match_markers_unchecked(points, self.markers_body, predicted, self.matching)
        matched = assignment >= 0
        T_measured = pose_from_points_unchecked(points[assignment[matched]], self.markers_body[matched]) if matched.sum() >= 3 else NAN_POSE
        if not matched.any():
            return FrameResult(assignment, T_measured, self.pose(), flag or ("no_markers" if len(points) else "no_points"))
        if not self.filter.initialized:  # without a prediction a match has >= min_markers markers
            return self._restart(assignment, T_measured, t, flag or "initialized")
        measured = np.zeros((self.filter.n, 3))
        measured[matched] = points[assignment[matched]]
        accepted = matched & self.innovation_ok(measured, matched)
        self.n_gated += int(matched.sum() - accepted.sum())
        if not accepted.any():
            self.n_rejected += 1
            if self.n_rejected >= self.params.restart_after_rejections and matched.sum() >= self.matching.min_markers:
                self.n_restarts += 1
                return self._restart(assignment, T_measured, t, "restart")
            return FrameResult(assignment, T_measured, self.pose(), flag or "gated")
        self.n_rejected = 0
        ok = self.filter._update(measured[accepted].ravel(), accepted, gyro=False)
        self.last_marker_t = self.last_fused_t = t
        if not ok:
            return FrameResult(assignment, T_measured, NAN_POSE, "diverged")
        return FrameResult(assignment, T_measured, self.pose(), flag or "ok")

    def _restart(self, assignment: np.ndarray, T_measured: np.ndarray, t: float, flag: str) -> FrameResult:
        """Start the filter from a good measurement (>= min_markers matched, so T_measured is finite)."""
        self.filter.initialize(transform_points(T_measured, self.markers_body))
        self.last_marker_t = self.last_fused_t = t
        self.n_rejected = 0
        return FrameResult(assignment, T_measured, self.pose(), flag)


@numba.njit(cache=True)
def innovation_gate(S, x, points, observed, sigma_r2, chi2):  # pragma: no cover - compiled
    """(n,) bool: the observed markers whose measured point passes the chi-square gate nu^T C^-1 nu <= chi2.

    S (N, N): the filter's covariance factor (P = S S^T); x (N,): its state, markers first (eq. 3); points (n, 3) m
    in geometry order; observed (n,) bool.  Marker i's innovation nu = point - x[3i:3i+3] has the covariance
    C = S_i S_i^T + sigma_r2 I of its predicted position and the measurement noise (eq. 16), S_i the marker's
    three rows of S; the quadratic form runs through C's Cholesky factor.  A C that is not positive definite, or
    any NaN, fails the gate."""
    n, N = observed.shape[0], S.shape[1]
    ok = np.zeros(n, dtype=np.bool_)
    C, L, y = np.empty((3, 3)), np.zeros((3, 3)), np.empty(3)
    for i in range(n):
        if not observed[i]:
            continue
        for a in range(3):
            for b in range(3):
                total = 0.0
                for j in range(N):
                    total += S[3 * i + a, j] * S[3 * i + b, j]
                C[a, b] = total + (sigma_r2 if a == b else 0.0)
        positive = True
        for a in range(3):  # C = L L^T
            for b in range(a + 1):
                total = C[a, b]
                for k in range(b):
                    total -= L[a, k] * L[b, k]
                if a == b:
                    positive = positive and total > 0.0
                    L[a, a] = np.sqrt(total) if total > 0.0 else 1.0
                else:
                    L[a, b] = total / L[b, b]
        for a in range(3):  # y = L^-1 nu: nu^T C^-1 nu = y . y
            total = points[i, a] - x[3 * i + a]
            for k in range(a):
                total -= L[a, k] * y[k]
            y[a] = total / L[a, a]
        ok[i] = positive and y[0] * y[0] + y[1] * y[1] + y[2] * y[2] <= chi2
    return ok
