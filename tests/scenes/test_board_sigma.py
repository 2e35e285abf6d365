"""The predicted uncertainty of a board's pose (scenes/board_sigma.py, issue 39): it is OpenCV's, and the plan's margin
on it is how far stage 02's own estimate scatters."""

import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity.poses import pose_matrix
from poseintegrity.scenes import board_sigma


def _rvec_tvec(T: np.ndarray):
    return cv2.Rodrigues(T[:3, :3])[0], T[:3, 3]


def test_the_predicted_uncertainty_is_opencvs_at_any_point_of_the_board():
    """sigma_t of the plan (left-perturbed rotation, the translation of the point) against OpenCV's
    projectPoints Jacobian (rvec, tvec), at the board origin and at a point 80 mm off it."""
    K = np.array([[1024.0, 0.0, 484.0], [0.0, 1024.0, 304.0], [0.0, 0.0, 1.0]])
    T = pose_matrix(Rotation.from_euler("xyz", [20.0, -30.0, 5.0], degrees=True).as_matrix(), [-40.0, 10.0, 350.0])
    corners = np.array([[15.0 * (i + 1), 15.0 * (j + 1), 0.0] for j in range(4) for i in range(6)])
    for point in (np.zeros(3), np.array([80.0, -20.0, 0.0])):
        shifted = corners - point  # the same board with its origin at the point
        _, jacobian = cv2.projectPoints(shifted, *_rvec_tvec(T @ pose_matrix(np.eye(3), point)), K, None)
        expected = np.sqrt(np.trace(np.linalg.inv(jacobian[:, :6].T @ jacobian[:, :6])[3:, 3:]))
        world = corners @ T[:3, :3].T + T[:3, 3]
        got = board_sigma.unit_sigma_t(world[None], (T[:3, :3] @ point + T[:3, 3])[None], np.eye(4), K)[0]
        assert got == pytest.approx(expected, rel=1e-9)


def test_the_plans_margin_on_sigma_t_is_how_far_stage_02s_estimate_scatters():
    """Stage 02 trusts a pose by its own sigma_t, s (J^T J)^-1 with s^2 = SSR / (2n - 6): over 4000 draws of Gaussian
    noise on the 24 corners of a 7 x 5 board at 350 mm, fitted by OpenCV (IPPE, then LM as stage 02 does), the 95th
    percentile of s / sigma is the plan's margin (the chi-square quantile) to within the draws' scatter."""
    K = np.array([[1024.0, 0.0, 484.0], [0.0, 1024.0, 304.0], [0.0, 0.0, 1.0]])
    T = pose_matrix(Rotation.from_euler("xyz", [25.0, -20.0, 5.0], degrees=True).as_matrix(), [-40.0, 10.0, 350.0])
    corners = np.array([[15.0 * (i + 1), 15.0 * (j + 1), 0.0] for j in range(4) for i in range(6)])
    exact, _ = cv2.projectPoints(corners, *_rvec_tvec(T), K, None)
    rng, sigma_px, ratios = np.random.default_rng(39), 0.1, []
    for _ in range(4000):
        seen = exact.reshape(-1, 2) + sigma_px * rng.standard_normal((len(corners), 2))
        _, rvec, tvec = cv2.solvePnP(corners, seen, K, None, flags=cv2.SOLVEPNP_IPPE)
        rvec, tvec = cv2.solvePnPRefineLM(corners, seen, K, None, rvec, tvec)
        residual = cv2.projectPoints(corners, rvec, tvec, K, None)[0].reshape(-1, 2) - seen
        ratios.append(np.sqrt(np.sum(residual**2) / (2 * len(corners) - 6)) / sigma_px)
    assert np.quantile(ratios, 0.95) == pytest.approx(board_sigma.estimate_spread(len(corners)), abs=0.015)
    assert board_sigma.estimate_spread(len(corners)) == pytest.approx(1.176, abs=0.001)
