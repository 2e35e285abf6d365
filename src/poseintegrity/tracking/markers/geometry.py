"""The rigid marker body and small frame helpers (section II-B of Black and Salcudean, IEEE TIM 2024).

Poses are 4x4 homogeneous matrices named ``T_a_b``: they map b coordinates into frame a.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

MARKER_DIAMETER_M = 0.011  # docs/references.md: 11 mm spheres


def pairwise_distances(points: np.ndarray) -> np.ndarray:
    """Euclidean distances between all pairs.

    points : (n, 3) float, metres.  Returns (n, n) float, metres, zero diagonal.
    """
    diff = points[:, None, :] - points[None, :, :]
    return np.sqrt(np.einsum("ijk,ijk->ij", diff, diff))


def tool_geometry_problem(tools: dict[str, np.ndarray], distinct_m: float) -> str:
    """Why these marker bodies cannot be told apart or posed, or "" if they can.

    tools : name -> (m, 3) marker centres, metres (the first tool is params.yaml's ``markers_body``, the
    geometry of docs/references.md).  Each tool needs at least 3 markers that do not lie on one line (a line
    of markers leaves the rotation about it open: Alg. 4 needs 3 non-collinear points), i.e. whose centred
    points spread more than distinct_m off their best line; and every inter-marker distance, within a tool
    and across tools, must differ from every other by more than distinct_m (m): Alg. 2 votes by distance, so
    a shared distance lets one pair vote for another's.
    """
    pairs = []
    for name, markers in tools.items():
        markers = np.asarray(markers, dtype=float).reshape(-1, 3)
        if len(markers) < 3:
            return f"tool {name!r} has {len(markers)} markers; at least 3 are needed for a pose"
        spread = np.linalg.svd(markers - markers.mean(axis=0), compute_uv=False)
        if spread[1] <= distinct_m:
            return f"the markers of tool {name!r} lie on one line (within {distinct_m * 1000:g} mm): the rotation about it is undetermined"
        D = pairwise_distances(markers)
        pairs += [(D[i, j], f"{name} markers {i + 1}-{j + 1}") for i, j in combinations(range(len(markers)), 2)]
    pairs.sort()
    for (d1, a), (d2, b) in zip(pairs, pairs[1:]):
        if d2 - d1 <= distinct_m:
            return (f"inter-marker distances are not distinct: {a} = {d1 * 1000:.2f} mm and {b} = {d2 * 1000:.2f} mm "
                    f"differ by <= {distinct_m * 1000:g} mm (correspondence by distance voting cannot tell them apart)")
    return ""


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
