"""Depth readings of marker pixels (section II-B: each marker's depth is read from the AHAT depth image along its
pixels' rays; millimetres, valid within [depth_min_mm, depth_max_mm]): the median as ``np.median`` computes it, and
the compiled readers detection and the touching-blob split share.
"""

from __future__ import annotations

import numba
import numpy as np


def small_median(values: np.ndarray) -> float:
    """``np.median`` of a 1-D float array (NaN if empty) without its overhead: the middle of the sorted values,
    or the mean of the two middle ones, (a + b) / 2, as np.median computes it (same bits)."""
    ordered = np.sort(values)
    k = len(ordered) // 2
    if len(ordered) == 0:
        return float("nan")
    return float(ordered[k]) if len(ordered) % 2 else float((ordered[k - 1] + ordered[k]) / 2)


@numba.njit(cache=True, nogil=True, inline="always")
def is_valid_depth(d, depth_min_mm, depth_max_mm):  # pragma: no cover - compiled
    """A depth reading (float) that is finite and within [depth_min_mm, depth_max_mm]."""
    return np.isfinite(d) and d >= depth_min_mm and d <= depth_max_mm


@numba.njit(cache=True, nogil=True)
def largest_depth_gap(depth_mm, pixels, depth_min_mm, depth_max_mm):  # pragma: no cover - compiled
    """Largest gap (mm) between consecutive sorted valid depths of a blob's pixels (k, 2) (u, v); -inf with
    fewer than two valid readings.  What :func:`split_by_depth` cuts at (the same subtractions, so the same bits)."""
    values = np.empty(len(pixels))
    n = 0
    for i in range(len(pixels)):
        d = float(depth_mm[pixels[i, 1], pixels[i, 0]])
        if is_valid_depth(d, depth_min_mm, depth_max_mm):
            values[n] = d
            n += 1
    ordered = np.sort(values[:n])
    gap = -np.inf
    for i in range(n - 1):
        gap = max(gap, ordered[i + 1] - ordered[i])
    return gap


@numba.njit(cache=True, nogil=True)
def valid_depth_range(depth_mm, x0, y0, w, h, depth_min_mm, depth_max_mm):  # pragma: no cover - compiled
    """max - min (mm) of the valid depth readings in the rectangle [x0, x0 + w) x [y0, y0 + h); -inf with fewer than
    two.  A blob inside the rectangle has no larger gap between its sorted readings (:func:`largest_depth_gap`):
    its readings are a subset and rounded subtraction is monotone, so below depth_split_mm it cannot be split."""
    low, high, n = np.inf, -np.inf, 0
    for v in range(y0, y0 + h):
        for u in range(x0, x0 + w):
            d = float(depth_mm[v, u])
            if is_valid_depth(d, depth_min_mm, depth_max_mm):
                low, high, n = min(low, d), max(high, d), n + 1
    return high - low if n >= 2 else -np.inf


@numba.njit(cache=True, nogil=True)
def window_medians(depth_mm, uv_int, w, depth_min_mm, depth_max_mm):  # pragma: no cover - compiled
    """:func:`lookup_depth` on rounded centres uv_int (k, 2) int: per centre the median of the valid readings
    in its (2w+1)^2 window, as :func:`small_median` computes it (the middle one or (a + b) / 2), NaN if none."""
    H, W = depth_mm.shape
    out = np.full(len(uv_int), np.nan)
    values = np.empty((2 * w + 1) * (2 * w + 1))
    for k in range(len(uv_int)):
        u, v = uv_int[k, 0], uv_int[k, 1]
        if not (0 <= u < W and 0 <= v < H):
            continue
        n = 0
        for r in range(max(v - w, 0), min(v + w + 1, H)):
            for c in range(max(u - w, 0), min(u + w + 1, W)):
                d = float(depth_mm[r, c])
                if is_valid_depth(d, depth_min_mm, depth_max_mm):
                    values[n] = d
                    n += 1
        ordered = np.sort(values[:n])
        if n:
            out[k] = ordered[n // 2] if n % 2 else (ordered[n // 2 - 1] + ordered[n // 2]) / 2
    return out


COMPILED_DEPTH_TYPES = frozenset(np.dtype(t) for t in (np.uint8, np.uint16, np.uint32, np.int16, np.int32, np.int64, np.float32, np.float64))


def compiled_depth(depth_mm: np.ndarray) -> np.ndarray:
    """depth_mm as the compiled readers take it: unchanged if its dtype is one of COMPILED_DEPTH_TYPES (native byte
    order), else as float64 (what the readers convert every reading to anyway)."""
    return depth_mm if depth_mm.dtype in COMPILED_DEPTH_TYPES and depth_mm.dtype.isnative else depth_mm.astype(np.float64)
