import numpy as np
import pytest

from poseintegrity.tracking.filter.cholesky import cholupdate, lower_factor


def _spd(rng, n):
    A = rng.normal(size=(n, n))
    return A @ A.T + n * np.eye(n)


@pytest.mark.parametrize("gamma", [1.0, 0.3, -0.2])
def test_rank1_update_and_downdate_match_numpy_cholesky(gamma):
    rng = np.random.default_rng(1)
    P = _spd(rng, 7)
    X = rng.normal(size=(7, 2))
    S, ok = cholupdate(np.linalg.cholesky(P), X, gamma)
    assert ok
    np.testing.assert_allclose(S, np.linalg.cholesky(P + gamma * X @ X.T), atol=1e-10)


def test_failed_downdate_is_reported_and_leaves_factor_unchanged():
    L = np.linalg.cholesky(np.eye(3))
    S, ok = cholupdate(L, np.array([2.0, 0.0, 0.0]), -1.0)  # I - 4 e1 e1^T is indefinite
    assert not ok
    np.testing.assert_array_equal(S, L)


def test_lower_factor_gives_a_factor_of_a_rectangular_square_root():
    rng = np.random.default_rng(2)
    A = rng.normal(size=(5, 12))
    S = lower_factor(A)
    np.testing.assert_allclose(S @ S.T, A @ A.T, atol=1e-12)
    assert np.allclose(S, np.tril(S)) and np.all(np.diag(S) >= 0)
