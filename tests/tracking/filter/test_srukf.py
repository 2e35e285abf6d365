import numpy as np
import pytest
from pykalman.sqrt.unscented import Moments, moments2points, unscented_filter_correct
from scipy.spatial.transform import Rotation

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.tracking.experiments.peers import additive_model, correlated_state, filterpy_filter, pykalman_time_update
from poseintegrity.tracking.filter.srukf import SquareRootUKF
from poseintegrity.tracking.filter.ukf import UnscentedKalmanFilter

from tracking.track_section import GEOMETRY, TRACK


def _measurements(n_steps, seed=0):
    """Rotating, translating body: (markers (4, 3) with noise, omega_world (3,)) per step."""
    rng = np.random.default_rng(seed)
    omega = np.array([0.8, -0.5, 1.2])
    out = []
    for k in range(n_steps):
        R = Rotation.from_rotvec(omega * 0.01 * k).as_matrix()
        markers = GEOMETRY @ R.T + [0.001 * k, 0.0, 0.45] + rng.normal(0, 0.001, (4, 3))
        out.append((markers, omega + rng.normal(0, 0.05, 3)))
    return out


def _run(cls, params, steps):
    f = cls(GEOMETRY, params)
    f.initialize(steps[0][0])
    states = []
    for k, (markers, omega) in enumerate(steps):
        f.predict(0.01)
        observed = np.array([k % 5 != 1, True, k % 7 != 3, True])  # partial updates
        f.update(markers[observed].ravel(), observed, gyro=False)
        if k % 2:
            f.update(omega, np.zeros(4, bool), gyro=True)  # gyro-only update
        states.append(f.x.copy())
    return np.array(states), f


@pytest.mark.parametrize("alpha, rtol", [(1.0, 1e-8), (1e-3, 1e-5)])
def test_square_root_ukf_equals_plain_ukf(alpha, rtol):
    params = TRACK.filter.model_copy(update=dict(alpha=alpha, sigma_r=0.002, sigma_c=3.0, sigma_alpha=10.0))
    steps = _measurements(60)
    x_sr, f_sr = _run(SquareRootUKF, params, steps)
    x_ukf, f_ukf = _run(UnscentedKalmanFilter, params, steps)
    assert np.max(np.abs(x_sr - x_ukf) / np.abs(x_ukf).max(axis=0)) < rtol
    np.testing.assert_allclose(f_sr.covariance(), f_ukf.covariance(), atol=rtol * np.abs(f_ukf.covariance()).max())


def test_square_root_ukf_equals_filterpy_on_full_measurements():
    params = TRACK.filter.model_copy(update=dict(alpha=1.0, sigma_r=0.002, sigma_c=3.0, sigma_alpha=10.0))
    steps = _measurements(30, seed=1)
    f = SquareRootUKF(GEOMETRY, params)
    f.initialize(steps[0][0])
    ref, step = filterpy_filter(GEOMETRY, params)
    ref.x, ref.P = f.x.copy(), f.covariance().copy()
    for markers, omega in steps:
        z = np.r_[markers.ravel(), omega]
        f.predict(0.01)
        f.update(z, np.ones(4, bool), gyro=True)
        step(z, 0.01)
    np.testing.assert_allclose(f.x, ref.x, rtol=0, atol=1e-8 * np.abs(ref.x).max())


def test_filter_tracks_without_failed_downdates():
    f = SquareRootUKF(GEOMETRY, TRACK.filter.model_copy(update=dict(sigma_r=0.002, sigma_c=3.0, sigma_alpha=10.0)))
    steps = _measurements(80, seed=2)
    f.initialize(steps[0][0])
    for markers, omega in steps:
        f.predict(0.01)
        assert f.update(np.r_[markers.ravel(), omega], np.ones(4, bool), gyro=True)
    assert np.linalg.norm(f.markers() - steps[-1][0], axis=1).max() < 0.005
    assert f.failed_downdates == 0


def test_a_failed_final_downdate_is_counted_and_keeps_the_prior_factor():
    # a nearly noise-free measurement (1 nm, 1 nrad/s) of every marker and omega: K S_y removes nearly all of S^-
    # in those rows, and rounding makes the downdate fail; section IV: the value from before the update is used
    f = SquareRootUKF(GEOMETRY, TRACK.filter.model_copy(update=dict(sigma_r=1e-9, sigma_omega=1e-9)))
    steps = _measurements(2, seed=2)
    f.initialize(steps[0][0])
    f.predict(0.01)
    S_prior, x_prior = f.S.copy(), f.x.copy()
    z = np.r_[steps[1][0].ravel(), steps[1][1]]
    assert f.update(z, np.ones(4, bool), gyro=True)
    assert f.failed_downdates == 1
    np.testing.assert_array_equal(f.S, S_prior)
    assert np.abs(f.x[:12] - z[:12]).max() < 0.5 * np.abs(x_prior[:12] - z[:12]).max()  # the state is still corrected


def test_divergence_is_detected_and_the_filter_stops():
    f = SquareRootUKF(GEOMETRY, TRACK.filter)
    f.initialize(GEOMETRY + [0, 0, 0.5])
    with pytest.raises(PoseIntegrityError, match="z: must be finite"):  # a NaN measurement is refused
        f.update(np.full(12, np.nan), np.ones(4, bool), gyro=False)
    f.x[0] = np.nan  # a NaN reached inside the filter is divergence
    assert not f.predict(0.0025)
    assert not f.initialized and f.n_divergences == 1 and f.last_reason == "non-finite state or covariance"
    f.initialize(GEOMETRY + [0, 0, 0.5])
    f.S = f.S * 1e4  # runaway covariance
    assert not f.predict(0.0025) and f.last_reason == "runaway covariance"


def test_time_update_agrees_with_pykalman_square_root_ukf():
    # pykalman's SR-UKF on the additive model, given the lower factor of Q: same mean and covariance; the
    # residual covariance difference is its |Wc[0]| centre term, 2 |Wc[0]| d d^T, and nothing else
    diff = pykalman_time_update(GEOMETRY, TRACK.filter, np.random.default_rng(3))
    assert diff["mean"] < 1e-8
    assert diff["covariance"] < 1e-8
    assert diff["covariance_after_centre_term"] < 1e-13


def test_our_update_is_the_kalman_update_and_pykalmans_is_not():
    # h is linear (rows of the state), so the exact update is x + K (z - x[rows]) with K = P H^T (H P H^T + R)^-1;
    # pykalman solves its gain with the transposed triangular factor (poseintegrity.tracking.experiments.peers), so it is not
    settings, _, R = additive_model(GEOMETRY, TRACK.filter, 1e-3)
    prior = correlated_state(GEOMETRY, settings, np.random.default_rng(4))
    x0, P = prior.x.copy(), prior.covariance()
    z = x0[:15] + 0.002
    expected = x0 + P[:, :15] @ np.linalg.solve(P[:15, :15] + R, z - x0[:15])
    with np.errstate(all="ignore"):
        theirs = unscented_filter_correct(lambda x: x[:15], Moments(x0, prior.S.T), moments2points(Moments(x0, prior.S.T)), z,
                                          sigma2_observation=np.sqrt(R))
    prior.update(z, np.ones(4, bool), gyro=True)
    np.testing.assert_allclose(prior.x, expected, rtol=0, atol=1e-10)
    assert np.abs(theirs.mean - expected).max() > 1e-4
