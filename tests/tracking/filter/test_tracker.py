import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity.errors import PoseIntegrityError

from poseintegrity.params.track import PAPER_SIGMAS
from poseintegrity.tracking.filter.multi_tool import MultiToolTracker
from poseintegrity.tracking.filter.tracker import MarkerTracker, innovation_gate
from poseintegrity.tracking.markers.geometry import transform_points
from poseintegrity.tracking.markers.kabsch import pose_from_points

from tracking.track_section import GEOMETRY, TRACK

FILTER = TRACK.filter.model_copy(update=dict(sigma_r=0.002, sigma_c=3.0, sigma_alpha=30.0))
MATCHING = TRACK.matching
POINTS = GEOMETRY + [0.0, 0.0, 0.45]


def _pose(t):
    return pose_from_points(GEOMETRY @ Rotation.from_rotvec([0.3 * t, -0.2 * t, 0.5 * t]).as_matrix().T + [0.01 * t, 0.0, 0.45], GEOMETRY)


def test_bad_frames_are_flagged_and_the_filter_keeps_predicting():
    rng = np.random.default_rng(0)
    tracker = MarkerTracker(GEOMETRY, FILTER, MATCHING)
    assert tracker.frame(0.0, np.zeros((0, 3))).flag == "no_points"
    assert tracker.frame(0.05, transform_points(_pose(0.05), GEOMETRY)[:2]).flag == "no_markers"
    for k in range(2, 30):
        t = 0.05 * k
        points = transform_points(_pose(t), GEOMETRY) + rng.normal(0, 0.0005, (4, 3))
        result = tracker.frame(t, points[rng.permutation(4)])
        assert result.flag in ("initialized", "ok")
        tracker.gyro(t + 0.02, np.array([0.3, -0.2, 0.5]) @ np.eye(3))
    t_before = tracker.t
    bad_inputs = [np.zeros((0, 3)), np.full((4, 3), np.nan), np.vstack([points, points]), rng.uniform(-1, 1, (3, 3))]
    for k, points in enumerate(bad_inputs):
        result = tracker.frame(t_before + 0.05 * (k + 1), points)
        assert tracker.filter.initialized and np.isfinite(result.T_filtered).all()
    assert tracker.t > t_before


def test_restart_after_a_second_without_markers_and_reinitialisation():
    tracker = MarkerTracker(GEOMETRY, FILTER, MATCHING, use_gyro=False)
    tracker.frame(0.0, transform_points(_pose(0.0), GEOMETRY))
    assert tracker.filter.initialized
    assert tracker.frame(1.5, np.zeros((0, 3))).flag == "restart" and not tracker.filter.initialized
    result = tracker.frame(1.6, transform_points(_pose(1.6), GEOMETRY))
    assert result.flag == "initialized"
    np.testing.assert_allclose(result.T_filtered, _pose(1.6), atol=1e-9)


def test_divergence_is_recovered_from_the_next_good_frame():
    tracker = MarkerTracker(GEOMETRY, FILTER, MATCHING)
    tracker.frame(0.0, transform_points(_pose(0.0), GEOMETRY))
    tracker.filter.x[:] = np.nan  # e.g. a NaN from a bad update
    result = tracker.frame(0.05, transform_points(_pose(0.05), GEOMETRY))
    assert result.flag == "diverged" and tracker.filter.initialized  # restarted from this good frame
    np.testing.assert_allclose(result.T_filtered, _pose(0.05), atol=1e-9)
    assert tracker.frame(0.10, transform_points(_pose(0.10), GEOMETRY)).flag == "ok"
    assert tracker.filter.n_divergences == 1


def test_a_persistent_ten_metre_jump_is_gated_then_restarted_never_ok_while_off():
    rng = np.random.default_rng(1)
    tracker = MarkerTracker(GEOMETRY, FILTER, MATCHING, use_gyro=False)
    flags = []
    for k in range(60):
        t = 0.046 * k
        shift = [10.0, 0.0, 0.0] if k >= 20 else [0.0, 0.0, 0.0]
        result = tracker.frame(t, transform_points(_pose(t), GEOMETRY) + rng.normal(0, 0.001, (4, 3)) + shift)
        off = np.linalg.norm(result.T_filtered[:3, 3] - _pose(t)[:3, 3] - shift)
        if result.flag == "ok":
            assert off < 0.01  # "ok" only when the estimate is where the measurements are
        flags.append(result.flag)
    after = flags[20:]
    restart = FILTER.restart_after_rejections - 1
    assert after[:restart] == ["gated"] * restart and after[restart] == "restart"
    assert set(after[restart + 1 :]) == {"ok"}


def test_non_finite_timestamps_are_rejected_with_a_clear_error():
    tracker = MarkerTracker(GEOMETRY, FILTER, MATCHING)
    tracker.frame(0.0, transform_points(_pose(0.0), GEOMETRY))
    with pytest.raises(PoseIntegrityError, match=r"t: expected a finite number in \[-1e\+12, 1e\+12\], got nan"):
        tracker.frame(float("nan"), transform_points(_pose(0.0), GEOMETRY))
    with pytest.raises(PoseIntegrityError, match="t: expected a finite number.*got inf"):
        tracker.gyro(float("inf"), np.zeros(3))
    assert tracker.gyro(0.01, np.array([np.nan, 0.0, 0.0])) == "bad_gyro"
    assert tracker.frame(-1.0, transform_points(_pose(0.0), GEOMETRY)).flag == "stale"


def test_published_sigmas_track_a_constant_rate_turn():
    # no defect in the filter with the published sigmas: a body turning at a constant 0.62 rad/s is tracked to
    # about a millimetre and a degree; their trouble on hand motion is the stiff process model (params.yaml)
    rng = np.random.default_rng(2)
    tracker = MarkerTracker(GEOMETRY, TRACK.filter.model_copy(update=PAPER_SIGMAS), MATCHING, use_gyro=False)
    errors = []
    for k in range(300):
        t = 0.046 * k
        result = tracker.frame(t, transform_points(_pose(t), GEOMETRY) + rng.normal(0, 0.001, (4, 3)))
        R_err = result.T_filtered[:3, :3] @ _pose(t)[:3, :3].T
        errors.append((np.linalg.norm(result.T_filtered[:3, 3] - _pose(t)[:3, 3]), np.degrees(np.arccos(np.clip((np.trace(R_err) - 1) / 2, -1, 1)))))
    late = np.array(errors[100:])
    assert np.sqrt((late[:, 0] ** 2).mean()) < 0.0015 and np.sqrt((late[:, 1] ** 2).mean()) < 1.5
    np.testing.assert_allclose(tracker.filter.x[12:15], [0.3, -0.2, 0.5], atol=0.05)


def test_the_compiled_innovation_gate_decides_as_numpys_solve():
    """innovation_gate against the quadratic form written with numpy (stacked products and np.linalg.solve), on
    random factors and innovations around the threshold; cases within 1e-9 of it are left out (rounding)."""
    rng = np.random.default_rng(8)
    n, N, chi2, decided = 4, 18, 21.1, 0
    for _ in range(400):
        S = np.tril(rng.normal(0.0, 0.002, (N, N)))
        x = rng.normal(0.0, 0.3, N)
        observed = rng.random(n) < 0.8
        points = x[: 3 * n].reshape(n, 3) + rng.normal(0.0, rng.choice([0.001, 0.005, 0.02]), (n, 3))
        rows = S[: 3 * n].reshape(n, 3, N)
        cov = rows @ np.swapaxes(rows, 1, 2) + 0.003**2 * np.eye(3)
        nu = points - x[: 3 * n].reshape(n, 3)
        d = np.einsum("ki,ki->k", nu, np.linalg.solve(cov, nu[:, :, None])[:, :, 0])
        clear = np.abs(d - chi2) > 1e-9 * chi2
        ok = innovation_gate(S, x, points, observed, 0.003**2, chi2)
        np.testing.assert_array_equal(ok[clear], (observed & (d <= chi2))[clear])
        decided += int((observed & clear).sum())
    assert decided > 1000
    S[0, 0] = np.nan
    assert not innovation_gate(S, x, points, np.ones(n, dtype=bool), 0.003**2, chi2)[0]  # NaN fails the gate
    assert not innovation_gate(np.zeros((N, N)), x, points, np.ones(n, dtype=bool), 0.0, chi2).any()  # C = 0: not positive definite


def _tracker():
    tracker = MarkerTracker(GEOMETRY, TRACK.filter, TRACK.matching)
    assert tracker.frame(0.0, POINTS).flag == "initialized"
    return tracker


@pytest.mark.parametrize("t, found", [(None, "NoneType"), ("0.1", "str"), (1e300, "1e\\+300"), (float("nan"), "nan"), (True, "bool")])
def test_bad_timestamps_are_refused_naming_t(t, found):
    tracker = _tracker()
    with pytest.raises(PoseIntegrityError, match=f"^t: expected .*{found}"):
        tracker.frame(t, POINTS)
    with pytest.raises(PoseIntegrityError, match=f"^t: expected .*{found}"):
        tracker.gyro(t, np.zeros(3))
    with pytest.raises(PoseIntegrityError, match="^t: "):
        MultiToolTracker({"probe": GEOMETRY}, TRACK.filter, TRACK.matching).frame(t, POINTS)


def test_time_going_backwards_is_flagged_stale_and_a_long_jump_restarts():
    tracker = _tracker()
    x = tracker.filter.x.copy()
    assert tracker.frame(-0.5, POINTS).flag == "stale" and tracker.gyro(-0.5, np.zeros(3)) == "stale"
    np.testing.assert_array_equal(tracker.filter.x, x)  # a stale sample changes nothing
    gyro_tracker = MarkerTracker(GEOMETRY, TRACK.filter, TRACK.matching, use_gyro=True)
    gyro_tracker.frame(0.0, POINTS)
    assert gyro_tracker.gyro(1e9, np.zeros(3)) == "restart"  # no 4e11 filter steps for a clock glitch
    first = MarkerTracker(GEOMETRY, TRACK.filter, TRACK.matching)
    assert first.frame(-3.0, POINTS).flag == "initialized"  # negative clocks are clocks


def test_points_and_gyro_of_the_wrong_shape_are_refused():
    tracker = _tracker()
    with pytest.raises(PoseIntegrityError, match=r"points: expected shape \(n, 3\), got \(4, 2\)"):
        tracker.frame(0.05, POINTS[:, :2])
    with pytest.raises(PoseIntegrityError, match=r"points: expected shape \(n, 3\), got \(6, 2\)"):
        tracker.frame(0.05, np.zeros((6, 2)))  # 12 numbers: reshape(-1, 3) used to make 4 points of them
    with pytest.raises(PoseIntegrityError, match="points: expected an array, got str"):
        tracker.frame(0.05, "points")
    for omega in (np.zeros(2), np.zeros(4), np.zeros((1, 3))):
        with pytest.raises(PoseIntegrityError, match=r"omega_body: expected shape \(3\)"):
            tracker.gyro(0.05, omega)
    assert tracker.gyro(0.05, np.array([np.nan, 0.0, 0.0])) == "bad_gyro"  # bad data: a flag
    assert tracker.frame(0.1, []).flag == "no_points"
