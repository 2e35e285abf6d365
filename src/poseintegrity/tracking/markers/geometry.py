"""The rigid marker body and small frame helpers (section II-B of Black and Salcudean, IEEE TIM 2024).

Poses are 4x4 homogeneous matrices named ``T_a_b``: they map b coordinates into frame a.
"""

from __future__ import annotations

import numpy as np

MARKER_DIAMETER_M = 0.011  # docs/references.md: 11 mm spheres


def pairwise_distances(points: np.ndarray) -> np.ndarray:
    """Euclidean distances between all pairs.

    points : (n, 3) float, metres.  Returns (n, n) float, metres, zero diagonal.
    """
    diff = points[:, None, :] - points[None, :, :]
    return np.sqrt(np.einsum("ijk,ijk->ij", diff, diff))


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrix [v]x of the appendix, batched.

    v : (..., 3).  Returns (..., 3, 3) with skew(v) @ u == cross(v, u).
    """
    S = np.zeros(v.shape[:-1] + (3, 3))
    S[..., 0, 1], S[..., 0, 2] = -v[..., 2], v[..., 1]
    S[..., 1, 0], S[..., 1, 2] = v[..., 2], -v[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -v[..., 1], v[..., 0]
    return S


def transform_points(T_a_b: np.ndarray, points_b: np.ndarray) -> np.ndarray:
    """Map points from frame b into frame a.

    T_a_b : (..., 4, 4); points_b : (..., n, 3) metres.  Returns (..., n, 3) metres in frame a.
    """
    return points_b @ np.swapaxes(T_a_b[..., :3, :3], -1, -2) + T_a_b[..., None, :3, 3]
