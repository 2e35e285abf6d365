"""Descriptor matching with Lowe's ratio test (used for the target model, III-B, and every frame).

Exact L2 nearest neighbours by one matrix product, ||q - t||^2 = ||q||^2 + ||t||^2 - 2 q.t: the same matches
as ``cv2.BFMatcher(cv2.NORM_L2).knnMatch(k=2)`` (tested) at about half its time.
"""

from __future__ import annotations

import numpy as np

from poseintegrity.config import published
from poseintegrity.errors import ArgumentError, check_scalar

MAX_DESCRIPTOR = 1e6  # SIFT components are at most 512 (OpenCV scales the unit vector by 512 and clips at 0.2 of it)


def _descriptors(name: str, values: object) -> np.ndarray:
    """float32 (n, d) descriptors; checked without a float64 copy (a frame has thousands)."""
    try:
        array = np.asarray(values) if isinstance(values, (np.ndarray, list, tuple)) else None
    except ValueError:  # a ragged list
        array = None
    if array is None or array.dtype.kind not in "iuf" or array.ndim != 2:
        found = f"shape {array.shape} and dtype {array.dtype}" if array is not None else type(values).__name__
        raise ArgumentError(f"{name}: expected (n, d) descriptors of real numbers, got {found}")
    array = array.astype(np.float32, copy=False)
    if array.size and not np.abs(array).max() <= MAX_DESCRIPTOR:  # False for NaN
        raise ArgumentError(f"{name}: descriptors must be finite and at most {MAX_DESCRIPTOR:g}")
    return array


def match_ratio_test(query: np.ndarray, train: np.ndarray, ratio: float | None = None) -> np.ndarray:
    """Nearest-neighbour matches that pass the ratio test.

    query : (n, 128) float32 descriptors (the frame), train : (m, 128) float32 descriptors (the model).
    A query descriptor is kept when its nearest train descriptor is closer than ``ratio`` times the second
    nearest (Lowe 2004, section 7.1), L2 distance; ratio None takes ``extract.ratio_test`` of the published
    defaults (params.yaml).
    Returns (p, 2) int: rows of (query index, train index); (0, 2) when the query is empty or the train
    set has fewer than the 2 descriptors a ratio test needs.
    Refused (:class:`~poseintegrity.errors.ArgumentError` naming the argument): descriptors that are not a 2-D array
    of finite real numbers, query and train of different descriptor lengths, a ratio outside (0, 1].
    """
    query, train = _descriptors("query", query), _descriptors("train", train)
    if query.shape[1] != train.shape[1]:
        raise ArgumentError(f"query, train: descriptors of {query.shape[1]} and {train.shape[1]} values cannot be compared")
    ratio = published("extract.ratio_test") if ratio is None else ratio
    check_scalar("ratio", ratio, low=0.0, high=1.0, low_open=True)
    if len(query) == 0 or len(train) < 2:
        return np.empty((0, 2), dtype=np.intp)
    d2 = query @ train.T  # (n, m): squared distances up to the per-row constant ||q||^2
    d2 *= -2.0
    d2 += np.einsum("ij,ij->i", train, train)[None, :]
    rows = np.arange(len(query))
    nearest = d2.argmin(axis=1)
    d2_first = d2[rows, nearest]
    d2[rows, nearest] = np.inf
    d2_second = d2.min(axis=1)
    q2 = np.einsum("ij,ij->i", query, query)
    first = np.sqrt(np.maximum(d2_first + q2, 0.0))
    second = np.sqrt(np.maximum(d2_second + q2, 0.0))
    keep = first < ratio * second
    return np.column_stack([rows[keep], nearest[keep]]).astype(np.intp)
