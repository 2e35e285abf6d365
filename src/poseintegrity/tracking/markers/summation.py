"""numpy's reductions compiled in numpy's order: the distances, sums and argmin of the compiled matchers (Alg. 2,
Alg. 3 and the gated assignment) round as the numpy code they replaced did, so that every assignment is the same to
the last bit.

- :func:`dot_norm`     |p - q| as np.linalg.norm of a vector (BLAS ddot);
- :func:`reduce_norm`  |p - q| as np.linalg.norm(..., axis=-1);
- :func:`einsum_norm`  |p - q| as :func:`~poseintegrity.tracking.markers.geometry.pairwise_distances` (einsum);
- :func:`numpy_sum`    sum(a) as np.add.reduce (pairwise summation);
- :func:`first_argmin` np.argmin, NaN first.
"""

from __future__ import annotations

import numba
import numpy as np

from poseintegrity.tracking.markers.kabsch import fused_multiply_add


@numba.njit(cache=True)
def dot_norm(p, q):  # pragma: no cover - compiled
    """|p - q| for (3,) points as np.linalg.norm of a vector rounds it (BLAS ddot: a fused multiply-add per term)."""
    d0, d1, d2 = p[0] - q[0], p[1] - q[1], p[2] - q[2]
    return np.sqrt(fused_multiply_add(d2, d2, fused_multiply_add(d1, d1, d0 * d0)))


@numba.njit(cache=True)
def reduce_norm(p, q):  # pragma: no cover - compiled
    """|p - q| for (3,) points as np.linalg.norm(..., axis=-1) rounds it (the squares summed in order)."""
    d0, d1, d2 = p[0] - q[0], p[1] - q[1], p[2] - q[2]
    return np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@numba.njit(cache=True)
def einsum_norm(p, q):  # pragma: no cover - compiled
    """|p - q| for (3,) points as geometry.pairwise_distances rounds it (einsum's two-lane sum: x^2 + z^2, then + y^2)."""
    d0, d1, d2 = p[0] - q[0], p[1] - q[1], p[2] - q[2]
    return np.sqrt((d0 * d0 + d2 * d2) + d1 * d1)


@numba.njit(cache=True)
def numpy_sum(a):  # pragma: no cover - compiled
    """sum(a) rounded as numpy's add.reduce (pairwise_sum): a block of at most 128 terms by _block_sum, a longer range
    as the sum of its halves (the first n // 2 rounded down to a multiple of 8), here without recursion (numba's
    cache cannot hold recursive functions): a stack of the ranges being split and their first halves' sums."""
    start, size = np.zeros(64, dtype=np.int64), np.zeros(64, dtype=np.int64)
    first, has_first = np.empty(64), np.zeros(64, dtype=np.bool_)  # the sum of a range's first half once known
    size[0] = a.size
    depth = 0
    while size[depth] > 128:  # split down to the first block
        half = size[depth] // 2 - size[depth] // 2 % 8
        start[depth + 1], size[depth + 1] = start[depth], half
        depth += 1
    while True:
        total = _block_sum(a, start[depth], size[depth])
        while depth > 0 and has_first[depth - 1]:  # the second half of its parent: the parent is done
            depth -= 1
            total = first[depth] + total
            has_first[depth] = False
        if depth == 0:
            return total
        first[depth - 1], has_first[depth - 1] = total, True  # a first half: go on with its sibling, split down to its first block
        parent = depth - 1
        half = size[parent] // 2 - size[parent] // 2 % 8
        start[depth], size[depth] = start[parent] + half, size[parent] - half
        while size[depth] > 128:
            half = size[depth] // 2 - size[depth] // 2 % 8
            start[depth + 1], size[depth + 1] = start[depth], half
            depth += 1


@numba.njit(cache=True)
def _block_sum(a, start, n):  # pragma: no cover - compiled
    """sum(a[start:start + n]), n <= 128, as numpy's pairwise_sum adds a block: in order below 8 terms, else 8
    running sums (term i into sum i % 8), combined pairwise, then the rest in order."""
    if n < 8:
        total = 0.0
        for i in range(n):
            total += a[start + i]
        return total
    r = a[start:start + 8].copy()
    i = 8
    while i < n - n % 8:
        for j in range(8):
            r[j] += a[start + i + j]
        i += 8
    total = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    for j in range(i, n):
        total += a[start + j]
    return total


@numba.njit(cache=True)
def first_argmin(values):  # pragma: no cover - compiled
    """np.argmin: the first minimum, or the first NaN if there is one."""
    best = 0
    for q in range(values.size):
        if np.isnan(values[q]):
            return q
        if values[q] < values[best]:
            best = q
    return best
