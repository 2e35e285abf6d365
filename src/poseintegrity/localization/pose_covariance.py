"""The error a PnP pose is expected to have, propagated to first order from its sources (ours, beyond the paper).

Windsor et al. predict failure from the inlier count n_i alone, and name "thresholds based on task specific
localization accuracy requirements" as their first item of future work (VI). The PnP solution itself says how far it
can be trusted: its pose is the least-squares fit of the inliers' reprojections, so its covariance follows from the
Jacobian of those reprojections and the uncertainty of what went in (Hartley & Zisserman, Multiple View Geometry,
2nd ed., ch. 5: forward propagation of covariance through a least-squares estimate, Sigma = A Sigma_u A^T with
A = (J^T J)^-1 J^T; docs/references.md, "Predicted localization error"):

(a) the image points: the residual at the inliers gives the pixel noise, s^2 = RSS / (2 n - 6) (ch. 5: the expected
    residual of a least-squares fit of d parameters to N measurements is sigma^2 (N - d) / N per measurement);
(b) the model points: every point of M_t was triangulated from the 20 mm model pair, so it carries a covariance
    (ch. 12, structure computation: Sigma_X = sigma^2 (J_X^T J_X)^-1 for the two projections' Jacobian J_X, the depth
    sigma ~ z^2 / (f b) sqrt(2) sigma along the model view's ray). It lies along the model view's rays, so it is invisible at
    theta = 0 and enters the image as the view turns (~ sin theta).

The pose is perturbed on the left, T = (exp([psi]x) R, t): t is the board origin in the camera (where E_t is
measured, IV-C) and |psi| is E_r's angle to first order, so the covariance of (psi, t) is that of the errors
Windsor et al. score. Per inlier j with x_j = R X_j + t in the camera and D_j = d(pixel)/d(x_j) (2, 3) of the ideal
pinhole (image points are undistorted), the rows of the pose Jacobian are [D_j (-[R X_j]x), D_j] and the model point
enters through D_j R:

    Sigma_pose = s^2 N^-1 + N^-1 (sum_j J_j^T D_j R Sigma_Xj R^T D_j^T J_j) N^-1,   N = sum_j J_j^T J_j

(the second term is the model points' covariance carried into the image and through the same least-squares map).
Predicted errors are RMS values: sigma_t = sqrt(trace Sigma_t) (mm), sigma_r = sqrt(trace Sigma_psi) (deg).

The inliers are chosen (c). RANSAC keeps a point only when its residual at the fitted pose is within the threshold
tau, so an inlier's model error is not a draw from its whole triangulation covariance: as the view turns, the
points whose depth error would throw them off by more than tau are outliers, and the pose rests on the others
(this selection is why n_i falls from the model view on). Its residual is (1 - h_j) of its error to first order,
h_j its leverage (the mean of the diagonal of J_j N^-1 J_j^T: how much the pose follows that point), so the
inlier's error e_j = n_j + m_j (image noise s^2 I plus model term C_j = D_j R Sigma_Xj R^T D_j^T) is conditioned
on |e_j| <= tau_j = tau / (1 - h_j), along each eigen-direction of C_j (variance v, total w = v + s^2): the
Gaussian truncated to [-tau_j, tau_j] has variance w_c = w (1 - 2 a phi(a) / (2 Phi(a) - 1)), a = tau_j / sqrt(w),
and the model part of it is v_c = (v / w)^2 w_c + v s^2 / w (the regression of m on e). Without (c) the first-order
covariance over-predicts the error measured on our worlds by 2-3 x where few inliers remain; with it, within
~1.1-1.5 x (docs/references.md, "Predicted localization error"). Both are computed: ``model`` is conditioned when
a threshold is given, ``unconditioned`` is not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr

from poseintegrity.errors import (ArgumentError, check_array, check_intrinsics, check_pose, check_same_length,
                                  check_scalar)

MIN_POINTS = 4  # a pose (6 parameters) needs more measurements (2 n) than parameters, and a residual
MAX_CONDITION = 1e12  # of N = J^T J: beyond it the inliers do not fix the pose (collinear, coincident)
MAX_LEVERAGE = 0.95  # (c): 1 - h_j is kept above 0.05 (a point the pose follows entirely would pass any threshold)


def skew(v: np.ndarray) -> np.ndarray:
    """[v]x (..., 3, 3) of vectors v (..., 3): [v]x w = v x w."""
    v = np.asarray(v, dtype=np.float64)
    zero = np.zeros(v.shape[:-1])
    return np.stack([np.stack([zero, -v[..., 2], v[..., 1]], -1),
                     np.stack([v[..., 2], zero, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], zero], -1)], -2)


def pinhole_jacobian(points_cam: np.ndarray, K: np.ndarray) -> np.ndarray:
    """D (n, 2, 3) = d(u, v)/d(x, y, z) of the ideal pinhole K at camera points (n, 3) (in front of the camera)."""
    x, y, z = points_cam[:, 0], points_cam[:, 1], points_cam[:, 2]
    fx, fy, s = K[0, 0], K[1, 1], K[0, 1]
    zero = np.zeros_like(z)
    du = np.stack([fx / z, s / z, -(fx * x + s * y) / z**2], -1)
    dv = np.stack([zero, fy / z, -fy * y / z**2], -1)
    return np.stack([du, dv], -2)


def pose_jacobians(points_model: np.ndarray, T_cam_model: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(J_pose (n, 2, 6), J_point (n, 2, 3)): the derivatives of each model point's pixel by the pose's left
    perturbation (psi (rad), t (mm)) and by the model point itself (mm), at the pose T_cam_model (4, 4).

    points_model : (n, 3) float, model (board) frame, mm; K : (3, 3) pinhole px.
    """
    R, t = T_cam_model[:3, :3], T_cam_model[:3, 3]
    rotated = points_model @ R.T
    D = pinhole_jacobian(rotated + t, K)
    J_pose = np.concatenate([D @ -skew(rotated), D], axis=-1)  # d x_cam / d psi = -[R X]x, d x_cam / d t = I
    return J_pose, D @ R


@dataclass(frozen=True)
class PoseCovariance:
    """The first-order covariance of a PnP pose, as its two sources add it (module docstring).

    residual : (6, 6) from the image points' noise (s^2 N^-1); model : (6, 6) from the model points' covariances,
    conditioned on the inlier test when a threshold was given ((c)); unconditioned : (6, 6) the same without (c);
    order (psi_x, psi_y, psi_z in rad, t_x, t_y, t_z in mm). sigma_px : s, the pixel noise the residual gave.
    ``status`` "ok", or why nothing could be propagated ("too_few_points", "degenerate_points": NaN matrices).
    """

    residual: np.ndarray
    model: np.ndarray
    unconditioned: np.ndarray
    sigma_px: float
    status: str = "ok"

    @property
    def total(self) -> np.ndarray:
        return self.residual + self.model

    @property
    def total_unconditioned(self) -> np.ndarray:
        return self.residual + self.unconditioned

    def sigma_t_mm(self, part: str = "total") -> float:
        """RMS of the board origin's position error, mm: sqrt(trace) of the translation block of ``part``
        ("total", "residual", "model", "unconditioned" (the model term without (c)) or "total_unconditioned")."""
        return float(np.sqrt(np.trace(getattr(self, part)[3:, 3:])))

    def sigma_r_deg(self, part: str = "total") -> float:
        """RMS of the rotation error angle, deg: sqrt(trace) of the rotation block of ``part``."""
        return float(np.degrees(np.sqrt(np.trace(getattr(self, part)[:3, :3]))))


def _nan_covariance(status: str, sigma_px: float = np.nan) -> PoseCovariance:
    nan = np.full((6, 6), np.nan)
    return PoseCovariance(nan, nan.copy(), nan.copy(), sigma_px, status)


def residual_sigma(points_model: np.ndarray, image_points: np.ndarray, T_cam_model: np.ndarray, K: np.ndarray) -> float:
    """s, the pixel noise of n image points (n, 2) about the projections of their model points (n, 3) at the pose:
    sqrt(RSS / (2 n - 6)), the unbiased estimate for a 6-parameter least-squares fit (module docstring). NaN for
    n < MIN_POINTS."""
    n = len(points_model)
    if n < MIN_POINTS:
        return float("nan")
    cam = points_model @ T_cam_model[:3, :3].T + T_cam_model[:3, 3]
    projected = cam @ K.T
    residual = image_points - projected[:, :2] / projected[:, 2:3]
    return float(np.sqrt(np.sum(residual**2) / (2 * n - 6)))


def pose_covariance(
    points_model: np.ndarray, image_points: np.ndarray, T_cam_model: np.ndarray, K: np.ndarray,
    point_covariances: np.ndarray | None = None, sigma_px: float | None = None,
    inlier_threshold_px: float | None = None,
) -> PoseCovariance:
    """The first-order covariance of the pose fitted to the inliers (module docstring).

    points_model : (n, 3) float, the inliers' model points, model (board) frame, mm
    image_points : (n, 2) float, their undistorted pixels (ideal pinhole of K)
    T_cam_model : (4, 4) the pose fitted to them (model -> camera, mm); K : (3, 3) px
    point_covariances : (n, 3, 3) mm^2, each model point's covariance in the model frame (None: exact points)
    sigma_px : the image points' noise (px); None estimates it from the residual (:func:`residual_sigma`)
    inlier_threshold_px : RANSAC's threshold tau: the model term is conditioned on the inlier test ((c)); None: not
    Fewer than MIN_POINTS inliers, or inliers that leave the pose undetermined (N's condition number beyond
    MAX_CONDITION), give NaN matrices and a status saying so: a flagged value, not an error. Arguments of the wrong
    shape or values are refused (:class:`~poseintegrity.errors.ArgumentError` naming them).
    """
    points_model = check_array("points_model", points_model, shape=(None, 3))
    image_points = check_array("image_points", image_points, shape=(None, 2))
    T_cam_model, K = check_pose("T_cam_model", T_cam_model), check_intrinsics("K", K)
    if point_covariances is not None:
        point_covariances = check_array("point_covariances", point_covariances, shape=(None, 3, 3))
        check_same_length(points_model=points_model, point_covariances=point_covariances)
    check_same_length(points_model=points_model, image_points=image_points)
    if sigma_px is not None:
        check_scalar("sigma_px", sigma_px, low=0.0)
    if inlier_threshold_px is not None:
        check_scalar("inlier_threshold_px", inlier_threshold_px, low=0.0, low_open=True)
    if np.any(points_model @ T_cam_model[2, :3] + T_cam_model[2, 3] <= 0):
        raise ArgumentError("points_model: every inlier must lie in front of the camera at T_cam_model")
    return propagated_covariance(points_model, image_points, T_cam_model, K, point_covariances, sigma_px,
                                 inlier_threshold_px)


def propagated_covariance(
    points_model: np.ndarray, image_points: np.ndarray, T_cam_model: np.ndarray, K: np.ndarray,
    point_covariances: np.ndarray | None, sigma_px: float | None, inlier_threshold_px: float | None = None,
) -> PoseCovariance:
    """:func:`pose_covariance` on arguments already checked (the per-frame path of stage 02: inliers of a PnP
    pose, in front of its camera)."""
    n = len(points_model)
    if sigma_px is None:
        sigma_px = residual_sigma(points_model, image_points, T_cam_model, K)
    if n < MIN_POINTS:
        return _nan_covariance("too_few_points", sigma_px)
    J_pose, J_point = pose_jacobians(points_model, T_cam_model, K)
    N = np.einsum("nki,nkj->ij", J_pose, J_pose)
    if not np.isfinite(N).all() or np.linalg.cond(N) > MAX_CONDITION:
        return _nan_covariance("degenerate_points", sigma_px)
    N_inv = np.linalg.inv(N)
    residual = sigma_px**2 * N_inv
    if point_covariances is None:
        return PoseCovariance(residual, np.zeros((6, 6)), np.zeros((6, 6)), sigma_px)
    C = J_point @ point_covariances @ np.swapaxes(J_point, -1, -2)  # (n, 2, 2): each model point's pixel covariance

    def carried(C: np.ndarray) -> np.ndarray:  # N^-1 (sum_j J_j^T C_j J_j) N^-1, symmetrised
        model = N_inv @ np.einsum("nki,nkl,nlj->ij", J_pose, C, J_pose) @ N_inv
        return 0.5 * (model + model.T)

    unconditioned = carried(C)
    if inlier_threshold_px is None:
        return PoseCovariance(residual, unconditioned, unconditioned, sigma_px)
    leverage = np.einsum("nki,ij,nkj->n", J_pose, N_inv, J_pose) / 2.0
    tau = inlier_threshold_px / (1.0 - np.minimum(leverage, MAX_LEVERAGE))
    return PoseCovariance(residual, carried(inlier_conditioned(C, sigma_px**2, tau)), unconditioned, sigma_px)


def inlier_conditioned(C: np.ndarray, noise: float, tau: np.ndarray) -> np.ndarray:
    """(n, 2, 2): the model terms C (n, 2, 2) px^2 of points whose whole error (model term plus image noise of
    variance ``noise`` px^2) passed the test |e| <= tau (n,) px, along each eigen-direction of C (module docstring,
    (c): the truncated Gaussian's variance, and the model part of it by regression)."""
    v, vectors = np.linalg.eigh(C)
    v = np.maximum(v, 0.0)
    w = v + noise
    with np.errstate(divide="ignore", invalid="ignore"):
        a = tau[:, None] / np.sqrt(w)
        kept = 2.0 * ndtr(a) - 1.0
        truncated = w * (1.0 - 2.0 * a * np.exp(-0.5 * a**2) / np.sqrt(2.0 * np.pi) / kept)
        v_c = np.where(w > 0, (v / w) ** 2 * truncated + v * noise / w, 0.0)
    return vectors @ (v_c[..., None] * np.swapaxes(vectors, -1, -2))


def triangulation_covariances(
    points_cam0: np.ndarray, T_cam1_cam0: np.ndarray, K: np.ndarray, sigma_px: float
) -> np.ndarray:
    """(n, 3, 3) mm^2: the first-order covariance of points triangulated from two views with pixel noise ``sigma_px``
    in both, Sigma_X = sigma^2 (J^T J)^-1, J (4, 3) the Jacobian of the point's pixels in camera 0 (K [I | 0]) and
    camera 1 (K [R | t] of T_cam1_cam0) (module docstring, (b)). points_cam0 : (n, 3) mm in camera 0, in front of
    both cameras. Along the rays the sigma is ~ z^2 / (f b) sqrt(2) sigma_px (the disparity's noise), across them ~ z / f
    sigma_px.
    """
    points_cam0 = check_array("points_cam0", points_cam0, shape=(None, 3))
    T_cam1_cam0, K = check_pose("T_cam1_cam0", T_cam1_cam0), check_intrinsics("K", K)
    check_scalar("sigma_px", sigma_px, low=0.0)
    R, t = T_cam1_cam0[:3, :3], T_cam1_cam0[:3, 3]
    J = np.concatenate([pinhole_jacobian(points_cam0, K), pinhole_jacobian(points_cam0 @ R.T + t, K) @ R], axis=1)
    return sigma_px**2 * np.linalg.inv(np.swapaxes(J, -1, -2) @ J)


def triangulation_sigma(residuals0: np.ndarray, residuals1: np.ndarray) -> float:
    """The pixel noise of a two-view triangulation, measured from its residuals (n, 2) in each view: a point fitted
    to its 4 pixel coordinates has 3 parameters, so E[RSS_j] = sigma^2 (4 - 3) and sigma^2 = mean_j RSS_j
    (module docstring, (a)). NaN without points. The residual sees only the noise across the epipolar lines; the
    noise along them becomes depth and is taken to be as large (isotropic keypoint noise)."""
    residuals0 = check_array("residuals0", residuals0, shape=(None, 2))
    residuals1 = check_array("residuals1", residuals1, shape=(len(residuals0), 2))
    if len(residuals0) == 0:
        return float("nan")
    return float(np.sqrt(np.mean(np.sum(residuals0**2, axis=1) + np.sum(residuals1**2, axis=1))))
