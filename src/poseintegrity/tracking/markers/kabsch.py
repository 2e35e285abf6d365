"""Kabsch-Umeyama pose from corresponding points (Algorithm 4 of Black and Salcudean, IEEE TIM 2024).

The paper returns the translation as ``r_bar - y_bar``; the least-squares translation is ``r_bar - R y_bar``
(the two agree only when the body points are centred), so we return the latter.
"""

from __future__ import annotations

import numba
import numpy as np
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic

from poseintegrity.errors import ArgumentError, check_array
from poseintegrity.poses import pose_matrix


def kabsch(points_world: np.ndarray, points_body: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation and translation that best map body points onto measured points (Alg. 4), batched.

    points_world : (..., n, 3) float, metres, measured points r^i.
    points_body : (..., n, 3) or (n, 3) float, metres, known points y^i in the same order.
    Returns R : (..., 3, 3) proper rotation and t : (..., 3) metres with ``R @ y + t ~= r``.
    R is the proper rotation maximising tr(R P^T Q) (Alg. 4's R = V diag(1, 1, d) U^T of the SVD of
    H = P^T Q), found as the top eigenvector of Horn's 4x4 quaternion matrix (Horn 1987) by compiled Jacobi
    sweeps: one call costs microseconds instead of a LAPACK SVD and numpy's per-call overhead.

    The arguments are checked once (:func:`check_kabsch_arguments`): fewer than 3 points, non-finite
    coordinates, shapes that do not correspond, or body points on one line (the rotation about the line is
    then undetermined) raise :class:`~poseintegrity.errors.ArgumentError` naming the argument.  The library's
    own per-frame callers, whose points are already checked, use :func:`kabsch_unchecked`.
    """
    return kabsch_unchecked(*check_kabsch_arguments(points_world, points_body))


def check_kabsch_arguments(points_world: object, points_body: object) -> tuple[np.ndarray, np.ndarray]:
    """(points_world, points_body) as float arrays, or :class:`ArgumentError` saying what is wrong with them:
    world (..., n, 3) and body (n, 3) or the same shape as world, n >= 3, finite, body points not collinear
    (their centred spread off the best line at most 1e-9 of the spread along it, or all coincident)."""
    world = check_array("points_world", points_world, shape=None)
    body = check_array("points_body", points_body, shape=None)
    for name, array in (("points_world", world), ("points_body", body)):
        if array.ndim < 2 or array.shape[-1] != 3:
            raise ArgumentError(f"{name}: expected shape (..., n, 3), got {array.shape}")
    if world.shape[-2] < 3:
        raise ArgumentError(f"points_world: Kabsch needs at least 3 corresponding points, got {world.shape[-2]}")
    if body.shape != world.shape and body.shape != world.shape[-2:]:
        raise ArgumentError(f"points_body: expected shape {world.shape[-2:]} or {world.shape} to match points_world, got {body.shape}")
    spread = np.linalg.svd(body - body.mean(axis=-2, keepdims=True), compute_uv=False)  # (..., 3)
    degenerate = spread[..., 1] <= 1e-9 * np.maximum(spread[..., 0], np.finfo(float).tiny)
    if np.any(degenerate):
        where = "" if body.ndim == 2 else f" (problem {tuple(int(i) for i in np.argwhere(degenerate)[0])})"
        raise ArgumentError(f"points_body: the points lie on one line or coincide{where}; the rotation about that line "
                            f"is undetermined (singular values of the centred points {np.ravel(spread[degenerate])[:3].tolist()})")
    return world, body


def kabsch_unchecked(points_world: np.ndarray, points_body: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`kabsch` without the argument checks, for callers whose points are known to be good (finite,
    (..., n, 3) with n >= 1); fewer than 3 non-collinear points give one of the equally good rotations."""
    points_world = np.asarray(points_world, dtype=np.float64)
    points_body = np.asarray(points_body, dtype=np.float64)
    batch, n = points_world.shape[:-2], points_world.shape[-2]
    if points_body.ndim > 2:  # one body per problem; else the same (n, 3) body for all
        points_body = np.broadcast_to(points_body, points_world.shape)
    R, t = _kabsch_kernel(np.ascontiguousarray(points_world.reshape(-1, n, 3)), np.ascontiguousarray(points_body.reshape(-1, n, 3)))
    return R.reshape(batch + (3, 3)), t.reshape(batch + (3,))


@numba.njit(cache=True)
def _kabsch_kernel(points_world, points_body):  # pragma: no cover - compiled
    """R (b, 3, 3) and t = r_bar - R y_bar (b, 3) of Alg. 4 for b problems of n points: points_world (b, n, 3),
    points_body (b, n, 3) or (1, n, 3) for one body shared by all."""
    b, n = points_world.shape[0], points_world.shape[1]
    R = np.empty((b, 3, 3))
    t = np.empty((b, 3))
    ell, y_bar, scratch = np.empty((n, 3)), np.empty(3), np.empty((4, 4, 4))
    for k in range(b):
        centre_into(points_body[k if points_body.shape[0] > 1 else 0], ell, y_bar)
        kabsch_into(points_world[k], ell, y_bar, scratch, R[k], t[k])
    return R, t


@numba.njit(cache=True)
def centre_into(body, ell, y_bar):  # pragma: no cover - compiled
    """y_bar (3,) = the mean of body (n, 3), summed row by row, and ell (n, 3) = body - y_bar: Alg. 4's centred body."""
    n = body.shape[0]
    y_bar[:] = 0.0
    for i in range(n):
        y_bar += body[i]
    y_bar /= n
    for i in range(n):
        for a in range(3):
            ell[i, a] = body[i, a] - y_bar[a]


@numba.njit(cache=True)
def kabsch_into(points_world, ell, y_bar, scratch, R, t):  # pragma: no cover - compiled
    """Alg. 4 for one problem without allocating: points_world (n, 3), the centred body ell (n, 3) and its mean y_bar
    (:func:`centre_into`); scratch (4, 4, 4) (H, V, N, M); R (3, 3) and t (3,) = r_bar - R y_bar receive the pose."""
    n = points_world.shape[0]
    r_bar = np.zeros(3)
    for i in range(n):
        r_bar += points_world[i]
    r_bar /= n
    H, V, N, M = scratch[0, :3, :3], scratch[1], scratch[2], scratch[3]
    centred_cross_covariance_into(points_world, ell, H)
    V[:] = 0.0
    for a in range(4):
        V[a, a] = 1.0
    horn_rotation_into(H, V, N, M, R)
    for a in range(3):
        t[a] = r_bar[a] - (R[a, 0] * y_bar[0] + R[a, 1] * y_bar[1] + R[a, 2] * y_bar[2])


def pose_from_points(points_world: np.ndarray, points_body: np.ndarray) -> np.ndarray:
    """``T_world_body`` (..., 4, 4) from corresponding points (see :func:`kabsch`; the same checks)."""
    return pose_matrix(*kabsch(points_world, points_body))


def pose_from_points_unchecked(points_world: np.ndarray, points_body: np.ndarray) -> np.ndarray:
    """:func:`pose_from_points` without the argument checks (see :func:`kabsch_unchecked`); one (n, 3) problem, the
    tracker's per-event pose, runs in one compiled call."""
    if np.ndim(points_world) == 2 and np.ndim(points_body) == 2:
        return _pose_kernel(np.ascontiguousarray(points_world, dtype=np.float64), np.ascontiguousarray(points_body, dtype=np.float64))
    return pose_matrix(*kabsch_unchecked(points_world, points_body))


@numba.njit(cache=True)
def _pose_kernel(points_world, points_body):  # pragma: no cover - compiled
    """T_world_body (4, 4) of Alg. 4 for one problem: points_world and points_body (n, 3)."""
    n = points_body.shape[0]
    ell, y_bar, scratch, T = np.empty((n, 3)), np.empty(3), np.empty((4, 4, 4)), np.zeros((4, 4))
    centre_into(points_body, ell, y_bar)
    kabsch_into(points_world, ell, y_bar, scratch, T[:3, :3], T[:3, 3])
    T[3, 3] = 1.0
    return T


def kabsch_residuals(points_world: np.ndarray, points_body: np.ndarray) -> np.ndarray:
    """Distances ``|R y^i + t - r^i|`` after the Kabsch fit, (..., n) metres (the error of Alg. 3); unchecked
    (correspondence calls it on its own candidate sets, see :func:`kabsch_unchecked`)."""
    points_world = np.asarray(points_world, dtype=np.float64)
    points_body = np.asarray(points_body, dtype=np.float64)
    batch, n = points_world.shape[:-2], points_world.shape[-2]
    if points_body.ndim > 2:  # one body per problem; else the same (n, 3) body for all
        points_body = np.broadcast_to(points_body, points_world.shape)
    res = _residuals_kernel(np.ascontiguousarray(points_world.reshape(-1, n, 3)), np.ascontiguousarray(points_body.reshape(-1, n, 3)))
    return res.reshape(batch + (n,))


@numba.njit(cache=True)
def _residuals_kernel(points_world, points_body):  # pragma: no cover - compiled
    """:func:`kabsch_residuals` of b problems: points_world (b, n, 3), points_body (b, n, 3) or (1, n, 3); (b, n)."""
    b, n = points_world.shape[0], points_world.shape[1]
    res = np.empty((b, n))
    ell, y_bar, scratch, R, t = np.empty((n, 3)), np.empty(3), np.empty((4, 4, 4)), np.empty((3, 3)), np.empty(3)
    for k in range(b):
        body = points_body[k if points_body.shape[0] > 1 else 0]
        centre_into(body, ell, y_bar)
        kabsch_into(points_world[k], ell, y_bar, scratch, R, t)
        residuals_into(points_world[k], body, R, t, res[k])
    return res


@numba.njit(cache=True)
def residuals_into(points_world, points_body, R, t, res):  # pragma: no cover - compiled
    """res (n,) = |R y^i + t - r^i| for the pose (R, t) of :func:`kabsch_into`, rounded as numpy rounds
    ``norm(points_body @ R.T + t - points_world, axis=-1)``: the product as OpenBLAS's dgemm forms it (a fused
    multiply-add per term, in order), then the squares summed in order."""
    for i in range(points_world.shape[0]):
        y = points_body[i]
        d0 = fused_multiply_add(y[2], R[0, 2], fused_multiply_add(y[1], R[0, 1], y[0] * R[0, 0])) + t[0] - points_world[i, 0]
        d1 = fused_multiply_add(y[2], R[1, 2], fused_multiply_add(y[1], R[1, 1], y[0] * R[1, 0])) + t[1] - points_world[i, 1]
        d2 = fused_multiply_add(y[2], R[2, 2], fused_multiply_add(y[1], R[2, 1], y[0] * R[2, 0])) + t[2] - points_world[i, 2]
        res[i] = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@intrinsic
def fused_multiply_add(typingctx, a, b, c):  # pragma: no cover - compiled
    """a * b + c rounded once (LLVM's llvm.fma.f64), in compiled code: the arithmetic of the BLAS kernels numpy calls."""
    def codegen(context, builder, signature, args):
        fma = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.DoubleType(), [ir.DoubleType()] * 3), "llvm.fma.f64")
        return builder.call(fma, args)

    return types.float64(types.float64, types.float64, types.float64), codegen


@numba.njit(cache=True)
def horn_rotation(H):  # pragma: no cover - compiled
    """Proper rotation maximising tr(R H) for a 3x3 cross-covariance H = P^T Q (Alg. 4), by Horn's method."""
    return horn_rotation_from(H, np.eye(4))[0]


@numba.njit(cache=True)
def horn_rotation_from(H, V0):  # pragma: no cover - compiled
    """:func:`horn_rotation` with the Jacobi sweeps started from the eigenvectors V0 (4, 4, orthogonal) of a
    nearby H (the sigma points of the filter are micrometres apart: one or two sweeps instead of five).
    Returns (R (3, 3), V (4, 4) the eigenvectors of this H's quaternion matrix)."""
    R, V = np.empty((3, 3)), V0.copy()
    horn_rotation_into(H, V, np.empty((4, 4)), np.empty((4, 4)), R)
    return R, V


@numba.njit(cache=True)
def horn_rotation_into(H, V, N, M, R):  # pragma: no cover - compiled
    """:func:`horn_rotation_from` in place, for the filter's 25 rotations a step (no array allocated): V (4, 4)
    holds the starting eigenvectors and receives this H's; N and M (4, 4) are scratch; R (3, 3) receives R."""
    N[0, 0] = H[0, 0] + H[1, 1] + H[2, 2]
    N[1, 1] = H[0, 0] - H[1, 1] - H[2, 2]
    N[2, 2] = -H[0, 0] + H[1, 1] - H[2, 2]
    N[3, 3] = -H[0, 0] - H[1, 1] + H[2, 2]
    N[0, 1] = N[1, 0] = H[1, 2] - H[2, 1]
    N[0, 2] = N[2, 0] = H[2, 0] - H[0, 2]
    N[0, 3] = N[3, 0] = H[0, 1] - H[1, 0]
    N[1, 2] = N[2, 1] = H[0, 1] + H[1, 0]
    N[1, 3] = N[3, 1] = H[2, 0] + H[0, 2]
    N[2, 3] = N[3, 2] = H[1, 2] + H[2, 1]
    scale = 1e-30 * (1.0 + N[0, 0] ** 2 + N[1, 1] ** 2 + N[2, 2] ** 2 + N[3, 3] ** 2)
    M[:] = 0.0  # Horn's matrix in the starting basis, V^T N V (exactly N for V = I)
    for a in range(4):
        for b in range(4):
            for i in range(4):
                for j in range(4):
                    M[a, b] += V[i, a] * N[i, j] * V[j, b]
    for _sweep in range(30):  # cyclic Jacobi eigen-decomposition of the symmetric 4x4 M
        off = 0.0
        for p in range(3):
            for q in range(p + 1, 4):
                off += M[p, q] * M[p, q]
        if off < scale:
            break
        for p in range(3):
            for q in range(p + 1, 4):
                if M[p, q] == 0.0:
                    continue
                theta = (M[q, q] - M[p, p]) / (2.0 * M[p, q])
                t = 1.0 if theta == 0.0 else np.sign(theta) / (abs(theta) + np.sqrt(theta * theta + 1.0))
                c = 1.0 / np.sqrt(t * t + 1.0)
                s = t * c
                for j in range(4):  # M <- J^T M J, V <- V J
                    mpj, mqj = M[p, j], M[q, j]
                    M[p, j], M[q, j] = c * mpj - s * mqj, s * mpj + c * mqj
                for j in range(4):
                    mjp, mjq = M[j, p], M[j, q]
                    M[j, p], M[j, q] = c * mjp - s * mjq, s * mjp + c * mjq
                    vjp, vjq = V[j, p], V[j, q]
                    V[j, p], V[j, q] = c * vjp - s * vjq, s * vjp + c * vjq
    best = 0
    for j in range(1, 4):
        if M[j, j] > M[best, best]:
            best = j
    w, x, y, z = V[0, best], V[1, best], V[2, best], V[3, best]  # unit quaternion of R
    R[0, 0] = w * w + x * x - y * y - z * z
    R[0, 1] = 2.0 * (x * y - w * z)
    R[0, 2] = 2.0 * (x * z + w * y)
    R[1, 0] = 2.0 * (x * y + w * z)
    R[1, 1] = w * w - x * x + y * y - z * z
    R[1, 2] = 2.0 * (y * z - w * x)
    R[2, 0] = 2.0 * (x * z - w * y)
    R[2, 1] = 2.0 * (y * z + w * x)
    R[2, 2] = w * w - x * x - y * y + z * z


@numba.njit(cache=True)
def centred_cross_covariance(points_world, ell):  # pragma: no cover - compiled
    """H = P^T Q of Alg. 4 for centred body points ell (n, 3) and measured points (n, 3)."""
    H = np.empty((3, 3))
    centred_cross_covariance_into(points_world, ell, H)
    return H


@numba.njit(cache=True)
def centred_cross_covariance_into(points_world, ell, H):  # pragma: no cover - compiled
    """:func:`centred_cross_covariance` written into H (3, 3)."""
    n = ell.shape[0]
    r0 = r1 = r2 = 0.0  # r_bar, summed row by row as r_bar += points_world[i] does
    for i in range(n):
        r0 += points_world[i, 0]
        r1 += points_world[i, 1]
        r2 += points_world[i, 2]
    r_bar = (r0 / n, r1 / n, r2 / n)
    H[:] = 0.0
    for i in range(n):
        for a in range(3):
            for c in range(3):
                H[a, c] += ell[i, a] * (points_world[i, c] - r_bar[c])
