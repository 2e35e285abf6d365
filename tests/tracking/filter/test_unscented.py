import numpy as np
import pytest

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.tracking.filter.srukf import SquareRootUKF
from poseintegrity.tracking.filter.ukf import UnscentedKalmanFilter
from poseintegrity.tracking.filter.unscented import unscented_weights

from tracking.track_section import GEOMETRY, TRACK

POINTS = GEOMETRY + [0.0, 0.0, 0.45]


def test_weights_and_unscented_transform_of_a_linear_map():
    Wm, Wc, gamma = unscented_weights(18, 1e-3, 2.0, 3 - 18)
    assert np.isclose(Wm.sum(), 1.0) and Wm[0] < -1e6  # the paper's alpha gives weights near -6e6
    rng = np.random.default_rng(0)
    x, A = rng.normal(size=18), rng.normal(size=(18, 18))
    S = np.linalg.cholesky(A @ A.T + np.eye(18))
    X = x[:, None] + gamma * np.hstack([np.zeros((18, 1)), S, -S])
    M = rng.normal(size=(5, 18))
    Y = M @ X
    y_mean = Y @ Wm
    np.testing.assert_allclose(y_mean, M @ x, atol=1e-6)
    dy = Y - y_mean[:, None]
    np.testing.assert_allclose((dy * Wc) @ dy.T, M @ S @ S.T @ M.T, rtol=1e-4)


@pytest.mark.parametrize("cls", [SquareRootUKF, UnscentedKalmanFilter])
def test_filter_steps_and_updates_are_checked_at_the_entry(cls):
    f = cls(GEOMETRY, TRACK.filter)
    f.initialize(POINTS)
    for dt in (-0.01, 0.0, float("nan"), "0.01"):
        with pytest.raises(PoseIntegrityError, match="dt: expected a finite time step > 0"):
            f.predict(dt)
    with pytest.raises(PoseIntegrityError, match="n_steps: expected a non-negative integer"):
        f.predict_steps(-1, 0.0025)
    assert f.predict_steps(0, 0.0)  # nothing to do
    with pytest.raises(PoseIntegrityError, match=r"z: expected shape \(12,\).*got \(5,\)"):
        f.update(np.zeros(5), np.ones(4, bool), gyro=False)
    with pytest.raises(PoseIntegrityError, match=r"observed: expected a boolean mask of shape \(4,\).*got shape \(3,\)"):
        f.update(POINTS[:3].ravel(), np.ones(3, bool), gyro=False)
    with pytest.raises(PoseIntegrityError, match=r"observed: .*got shape \(5,\)"):
        f.update(POINTS.ravel(), np.ones(5, bool), gyro=False)
    with pytest.raises(PoseIntegrityError, match="observed: .*dtype int64"):
        f.update(POINTS[:3].ravel(), np.array([0, 1, 2]), gyro=False)  # indices are not a mask
    with pytest.raises(PoseIntegrityError, match=r"markers: expected shape \(4, 3\)"):
        f.initialize(POINTS[:3])
    assert f.update(POINTS.ravel(), np.ones(4, bool), gyro=False) and f.initialized
