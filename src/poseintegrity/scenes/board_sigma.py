"""How well a board's pose is predicted from its corners: criterion 4 of the board plan (:mod:`.board_plan`, placement planned).

The covariance s^2 (J^T J)^-1 of the board pose from the inner corners found (the same prediction as stage 02's
trust rule, :mod:`poseintegrity.localization.ground_truth`), J the Jacobian of the corners' projections at the
commanded pose, s the corner noise CORNER_NOISE_PX grown by the blur (:func:`corner_noise_px`); sigma_t is its RMS at
the board origin, where E_t is measured (IV-C; :func:`unit_sigma_t` at unit noise). Stage 02 trusts a pose by its own
estimate of that sigma_t, from the residual scale s^2 = SSR / (2n - 6) of the n corners it fits; with Gaussian corner
noise (2n - 6) s^2 / sigma^2 is chi-square with 2n - 6 degrees of freedom (docs/references.md), so the estimate
exceeds the prediction by sqrt(chi2_q(2n - 6) / (2n - 6)) in a share 1 - q of frames (:func:`estimate_spread`: 1.18
for 24 corners at q = TRUSTED_SHARE). A stop is served where even that estimate stays within ``plan_sigma_t_mm``
(without this margin, the frames of stops predicted within 0.128-0.15 mm were trusted in 90 % of both worlds' frames
at one image per stop, those below in 92-96 %; stage 02's estimate over the plan's: median 0.76-0.81, 95th
percentile 1.15-1.21, as sqrt(chi2_0.95(42) / 42) = 1.18). A frame judged by another board (a handover) is predicted
at the own board's origin from the other's corners (:func:`handover_sigma_t`).

J^T J is compiled (numba) and rounds as numpy and OpenBLAS did (:func:`~.image_polygons.to_camera`).
"""

from __future__ import annotations

import numba
import numpy as np
from scipy.stats import chi2

from poseintegrity.scenes.image_polygons import NEAR_MM, fma, to_camera

# Measured on the renders of studies/board_options.py (ChArUco boards, 960 frames of the facing_camera placement's and this plan's
# boards): the corner noise the trust rule sees, s = sqrt(SSR / (2n - 6)), is 0.055-0.065 px (median) on sharp boards
# and grows with the blur to 0.10-0.13 px at a blur sigma of 2-2.7 px, as hypot(a, b x blur sigma). With
# (0.068, 0.038) px the predicted sigma_t is at least the measured one in 95 % of the 506 frames whose board was
# wholly in view, in focus and found with 20 or more corners (the measured one is 0.51-1.21 x, median 0.76 x, the
# predicted one).
CORNER_NOISE_PX = (0.068, 0.038)
TRUSTED_SHARE = 0.95  # of a served stop's frames stage 02 should trust (the plan's target share of trusted frames)
SINGULAR_COND = 1e12  # an information matrix this ill-conditioned predicts nothing: sigma_t inf


def corner_noise_px(blur_px: np.ndarray) -> np.ndarray:
    """The corner noise (px, the shape of ``blur_px``) at a blur sigma of ``blur_px``: hypot(a, b x blur sigma) of
    CORNER_NOISE_PX (a, b)."""
    return np.hypot(CORNER_NOISE_PX[0], CORNER_NOISE_PX[1] * blur_px)


def handover_sigma_t(corners: np.ndarray, origin: np.ndarray, views: np.ndarray, K: np.ndarray, served: np.ndarray,
                     noise: np.ndarray, visible: np.ndarray, spread: np.ndarray) -> np.ndarray:
    """(p,) the sigma_t (mm) at a board's ``origin`` (3,, world mm) of a frame judged by another board, whose inner
    corners are ``corners`` (m, 3, world mm) (a handover: stage 02 carries the camera's motion since model image 0,
    read from the other board, to the origin, :func:`~poseintegrity.localization.ground_truth.handed_over`): hypot of
    what the other's corners found, at their corner noise, predict for the origin at the pose (``views`` (p, 4, 4):
    T_cam_world) and at model image 0 (pose 0), times ``spread`` (by the corners found, :func:`estimate_spread`).
    Per pose the other board's corner noise ``noise`` (p,, px) and its corners found ``visible`` (p, m); inf where
    ``served`` (p,) is False (where the other board does not serve the pose, or the own board needs no handover)."""
    out = np.full(len(views), np.inf)
    at = np.flatnonzero(served)
    if len(at):
        poses = np.concatenate([[0], at])
        unit = unit_sigma_t(np.repeat(corners[None], len(poses), axis=0), np.repeat(origin[None], len(poses), axis=0),
                            views[poses], K, visible[poses])
        sigma = noise[poses] * unit
        out[at] = np.hypot(sigma[1:], sigma[0]) * spread[visible[at].sum(axis=1)]
    return out


def unit_sigma_t(corners: np.ndarray, origin: np.ndarray, view: np.ndarray, K: np.ndarray,
                  seen: np.ndarray | None = None) -> np.ndarray:
    """(k,) RMS error (mm) of the board origin predicted from the corners (k, m, 3, world) at unit pixel noise:
    sqrt(trace of the translation block of (J^T J)^-1), J (2m, 6) the Jacobian of the corners' pixels with respect to
    a small rotation about the camera origin and the translation of the board (the translation block does not
    depend on how the rotation is parametrized: OpenCV's rvec gives the same). ``view``: T_cam_world (4, 4), or one
    per board (k, 4, 4); ``seen`` (k, m): the corners found (default: all). J^T J compiled (:func:`_information`),
    inverted by numpy's LAPACK."""
    if len(corners) == 0:
        return np.empty(0)
    views = np.ascontiguousarray(np.broadcast_to(view, (len(corners), 4, 4)))
    seen = np.ones(corners.shape[:2], bool) if seen is None else seen
    information = np.zeros((len(corners), 6, 6))
    _information(corners, origin, views, K[0, 0], K[1, 1], seen, information)
    covariance = np.empty_like(information)
    try:
        covariance[...] = np.linalg.inv(information)
        # cond = |A|_2 |A^-1|_2 <= |A|_F |A^-1|_F: the SVD (np.linalg.cond) only where this bound does not rule it out
        with np.errstate(over="ignore"):
            doubt = ~(np.linalg.norm(information, axis=(1, 2)) * np.linalg.norm(covariance, axis=(1, 2))
                      <= SINGULAR_COND / 10)
    except np.linalg.LinAlgError:  # one is singular to the bit
        doubt = np.ones(len(corners), bool)
    singular = np.zeros(len(corners), bool)
    if doubt.any():
        singular[doubt] = np.linalg.cond(information[doubt]) > SINGULAR_COND
        information[singular] = np.eye(6)
        covariance[doubt] = np.linalg.inv(information[doubt])
    return np.where(singular, np.inf, np.sqrt(np.clip(np.trace(covariance[:, 3:, 3:], axis1=1, axis2=2), 0.0, None)))


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA unasked
def _information(corners, origin, views, fx, fy, seen, out):
    """out (k, 6, 6, zeros) += J^T J of :func:`unit_sigma_t` for corners (k, m, 3), origins (k, 3), views
    (k, 4, 4), focal lengths fx, fy px and the corners found (k, m), to the bit as numpy computed them with matrix
    products (the camera frame, :func:`~.image_polygons.to_camera`; d(pixel)/d(point) times -[r]_x: OpenBLAS's fused
    multiply-adds from zero, term by term) and an einsum over the corners (the products summed in order from zero). A
    corner not found (its rows of J times 0) adds only zeros to a sum that is never -0: skipped."""
    J = np.empty((2, 6))
    for n in range(corners.shape[0]):
        t0, t1, t2 = to_camera(origin[n, 0], origin[n, 1], origin[n, 2], views[n])
        for i in range(corners.shape[1]):
            if not seen[n, i]:
                continue
            X, Y, Z = to_camera(corners[n, i, 0], corners[n, i, 1], corners[n, i, 2], views[n])
            r0, r1, r2 = X - t0, Y - t1, Z - t2  # before Z is clipped
            Z = max(Z, NEAR_MM)
            # d(pixel)/d(point) (2, 3): [[fx / Z, 0, -fx X / Z^2], [0, fy / Z, -fy Y / Z^2]]; times -[r]_x, whose
            # diagonal is -0.0 (the negated zeros of [r]_x)
            for row in range(2):
                if row == 0:
                    d0, d1, d2 = fx / Z, 0.0, -fx * X / (Z * Z)
                else:
                    d0, d1, d2 = 0.0, fy / Z, -fy * Y / (Z * Z)
                J[row, 0] = fma(d2, r1, fma(d1, -r2, fma(d0, -0.0, 0.0)))
                J[row, 1] = fma(d2, -r0, fma(d1, -0.0, fma(d0, r2, 0.0)))
                J[row, 2] = fma(d2, -0.0, fma(d1, r0, fma(d0, -r1, 0.0)))
                J[row, 3], J[row, 4], J[row, 5] = d0, d1, d2
            for row in range(2):
                for a in range(6):
                    for b in range(a, 6):
                        out[n, a, b] = out[n, a, b] + J[row, a] * J[row, b]
        for a in range(6):
            for b in range(a):
                out[n, a, b] = out[n, b, a]


def estimate_spread(n_corners: int, share: float = TRUSTED_SHARE) -> float:
    """How far stage 02's estimate of a pose's sigma_t exceeds the true one in a share 1 - ``share`` of frames: the
    quantile sqrt(chi2_share(2n - 6) / (2n - 6)) of s / sigma, s^2 = SSR / (2n - 6) the residual variance of a pose
    fitted to ``n_corners`` points with Gaussian noise (6 parameters; module docstring)."""
    dof = 2 * n_corners - 6
    return float(np.sqrt(chi2.ppf(share, dof) / dof))
