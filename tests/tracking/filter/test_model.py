import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.tracking.filter.model import centred, process_model, process_model_reference, process_noise_sqrt
from poseintegrity.tracking.markers.geometry import pairwise_distances, skew

from tracking.track_section import GEOMETRY


def _state(rng, R, omega, v):
    markers = GEOMETRY @ R.T + [0.0, 0.1, 0.5]
    return np.concatenate([markers.ravel(), omega, v])


def test_compiled_process_model_equals_the_plain_one_per_sigma_point():
    rng = np.random.default_rng(3)
    X = np.stack([_state(rng, Rotation.random(random_state=k).as_matrix(), rng.normal(size=3), rng.normal(size=3)) + rng.normal(0, 1e-3, 18) for k in range(37)], axis=1)
    expected = np.stack([process_model_reference(X[:, k], 0.01, GEOMETRY) for k in range(37)], axis=1)
    np.testing.assert_allclose(process_model(X, 0.01, centred(GEOMETRY)), expected, atol=1e-14)


def test_process_model_moves_a_rigid_body_like_a_rotation():
    R0 = Rotation.from_rotvec([0.2, 0.4, -0.1])
    omega, dt = np.array([0.5, -1.0, 2.0]), 1e-3
    x = _state(None, R0.as_matrix(), omega, np.zeros(3))
    x_next = process_model(x[:, None], dt, centred(GEOMETRY))[:, 0]
    markers = x_next[:12].reshape(4, 3)
    exact = (centred(GEOMETRY) @ (Rotation.from_rotvec(omega * dt) * R0).as_matrix().T) + x[:12].reshape(4, 3).mean(0)
    np.testing.assert_allclose(markers, exact, atol=1e-6)  # first order in dt
    np.testing.assert_allclose(pairwise_distances(markers), pairwise_distances(GEOMETRY), atol=1e-6)


def test_process_noise_square_root_gives_the_rederived_eq_30():
    rng = np.random.default_rng(4)
    R = Rotation.random(random_state=4).as_matrix()
    omega, dt, sc, sa = rng.normal(size=3), 0.0025, 0.7, 0.9
    x = _state(rng, R, omega, rng.normal(size=3))
    B = process_noise_sqrt(x, dt, centred(GEOMETRY), sc, sa)
    Q = B @ B.T
    a = centred(GEOMETRY) @ R.T
    W2 = skew(omega) @ skew(omega)
    for i in range(4):
        for j in range(4):
            E_rr = 0.25 * dt**4 * (sc**2 * np.eye(3) + sa**2 * (a[i] @ a[j] * np.eye(3) - np.outer(a[j], a[i])) + np.outer(W2 @ a[i], W2 @ a[j]))
            np.testing.assert_allclose(Q[3 * i : 3 * i + 3, 3 * j : 3 * j + 3], E_rr, atol=1e-18)
        np.testing.assert_allclose(Q[3 * i : 3 * i + 3, 12:15], -0.5 * dt**3 * sa**2 * skew(a[i]), atol=1e-16)
        np.testing.assert_allclose(Q[3 * i : 3 * i + 3, 15:18], 0.5 * dt**3 * sc**2 * np.eye(3), atol=1e-16)
    np.testing.assert_allclose(Q[12:15, 12:15], dt**2 * sa**2 * np.eye(3), atol=1e-16)
    np.testing.assert_allclose(Q[15:18, 15:18], dt**2 * sc**2 * np.eye(3), atol=1e-16)
    np.testing.assert_allclose(Q[12:15, 15:18], 0.0, atol=1e-18)  # E_c_alpha = 0 (eq. 25)


def test_process_noise_matches_monte_carlo_of_the_noise_vector():
    rng = np.random.default_rng(5)
    R = Rotation.random(random_state=5).as_matrix()
    x = _state(rng, R, np.zeros(3), np.zeros(3))  # omega = 0: no deterministic term
    dt, sc, sa = 0.01, 1.0, 2.0
    Q = process_noise_sqrt(x, dt, centred(GEOMETRY), sc, sa) @ process_noise_sqrt(x, dt, centred(GEOMETRY), sc, sa).T
    c_dd, alpha = rng.normal(0, sc, (200_000, 3)), rng.normal(0, sa, (200_000, 3))
    a = centred(GEOMETRY) @ R.T
    v = np.concatenate([(0.5 * dt**2 * (c_dd[:, None, :] + np.cross(alpha[:, None, :], a[None]))).reshape(-1, 12), dt * alpha, dt * c_dd], axis=1)  # eq. 11
    np.testing.assert_allclose(np.cov(v.T), Q, atol=0.02 * np.abs(Q).max())
