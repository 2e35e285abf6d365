"""Point correspondence between measured marker points and the known geometry (section II-D): the pipeline of the
matchers, one module each.

Every matcher returns ``assignment`` : (m,) int, for each geometry marker the index of its measured point,
or -1 if it was not found.  Measured points are (n, 3) metres; rows with NaN are never matched.

- :func:`~.frobenius.match_frobenius`     Alg. 1 and appendix B: closest previous points by the Frobenius norm,
  including a missing marker (a column of Y removed) and, beyond the paper, extra points.
- :func:`~.voting.match_voting`           Alg. 2: Euclidean-distance voting with outlier rejection; only confident
  matches.
- :func:`~.brute_force.match_brute_force` Alg. 3: permutations with Kabsch, generalised to phantoms and missing markers.
- :func:`~.gated.match_gated`             beyond the paper: optimal assignment (scipy linear_sum_assignment) of the
  points to the filter's predicted marker positions, with a distance gate.
- :func:`match_markers`                   the pipeline: gated assignment if a prediction is given, else / then voting,
  brute force for what voting leaves, brute force on everything as the last resort.
"""

from __future__ import annotations

import numba
import numpy as np

from poseintegrity.config import published
from poseintegrity.errors import ArgumentError, check_array
from poseintegrity.params.track import MatchingParams
from poseintegrity.tracking.markers.brute_force import brute_force_kernel
from poseintegrity.tracking.markers.consistency import finite_mask, is_consistent_kernel
from poseintegrity.tracking.markers.gated import match_gated_unchecked
from poseintegrity.tracking.markers.voting import voting_kernel

MAX_ABS_M = 1e6  # a measured or body point farther than 1000 km is not a marker


def match_markers(
    points: np.ndarray,
    geometry: np.ndarray,
    previous: np.ndarray | None = None,
    matching: MatchingParams | None = None,
) -> np.ndarray:
    """For each geometry marker (m, 3) the index of its measured point among points (n, 3), or -1.

    previous : (m, 3) predicted marker positions (metres, world) or None; matching : ``track.matching`` (None: the
    published defaults, params.yaml).  With a prediction the gated
    optimal assignment is tried first and kept if it rigidly matches at least min_markers markers and no
    other permutation of the same points fits the geometry better (Alg. 3 on those points).
    Otherwise voting (Alg. 2) fixes the confident matches and brute force (Alg. 3) fills the rest from the
    non-outliers; if that leaves markers unmatched although points remain, brute force also runs on all
    points and wins if it matches more.  If all of that finds nothing, a consistent
    gated match of one or two markers is returned (the filter can use a partial update); else all -1.
    Refused (:class:`~poseintegrity.errors.ArgumentError`): points not (n, 3) numbers (NaN rows are allowed:
    dropped detections), geometry not >= 3 finite (m, 3) markers, previous not (m, 3).
    """
    points = np.zeros((0, 3)) if np.size(points) == 0 and points is not None and not isinstance(points, str) else points
    points = check_array("points", points, shape=(None, 3), finite=False)  # NaN rows are dropped detections
    if not np.all(np.isnan(points) | (np.abs(points) <= MAX_ABS_M)):
        raise ArgumentError(f"points: entries must be NaN (no detection) or at most {MAX_ABS_M:g} m in magnitude")
    geometry = check_array("geometry", geometry, shape=(None, 3), min_rows=3, max_abs=MAX_ABS_M)
    if previous is not None:
        previous = check_array("previous", previous, shape=geometry.shape, finite=False)
    matching = published("track.matching") if matching is None else matching
    return match_markers_unchecked(points, geometry, previous, matching)


def match_markers_unchecked(points: np.ndarray, geometry: np.ndarray, previous: np.ndarray | None,
                            matching: MatchingParams) -> np.ndarray:
    """:func:`match_markers` on checked arguments (float (n, 3) points, (m, 3) geometry): the per-frame path."""
    geometry = np.ascontiguousarray(geometry, dtype=np.float64)
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    finite = finite_mask(points)
    if previous is None:
        gated = np.full(geometry.shape[0], -1, dtype=np.int64)
    else:
        gated = match_gated_unchecked(points, finite, np.ascontiguousarray(previous, dtype=np.float64), matching.gate_m)
    return _match(points, finite, geometry, gated, previous is not None, matching.tolerance_m, matching.min_markers)


@numba.njit(cache=True)
def _match(points, finite, geometry, gated, predicted, tolerance_m, min_markers):  # pragma: no cover - compiled
    """The pipeline of :func:`match_markers` after the gated assignment (of the prediction if predicted)."""
    m = geometry.shape[0]
    no_fixed = np.full(m, -1, dtype=np.int64)
    if predicted:
        if not is_consistent_kernel(points, geometry, gated, tolerance_m):
            gated[:] = -1
        used = np.zeros(points.shape[0], dtype=np.bool_)
        for i in range(m):
            if gated[i] >= 0:
                used[gated[i]] = True
        if used.sum() >= min_markers:
            # the marker body is nearly symmetric under some permutations (the published geometry: (4, 3, 2, 1) fits
            # within 3.7 mm), so keep the gated match only if it is also the best rigid fit of its points (Alg. 3)
            best = brute_force_kernel(points, geometry, no_fixed, np.flatnonzero(used & finite), tolerance_m, used.sum())
            if np.all(best == gated):
                return gated
    voted, outlier = voting_kernel(points, finite, geometry, tolerance_m)  # Alg. 2
    if (voted >= 0).sum() >= 2 and not is_consistent_kernel(points, geometry, voted, tolerance_m):
        voted[:] = -1
    if np.all(voted >= 0):
        return voted
    usable = finite & ~outlier  # Alg. 3 for the markers voting left open
    for i in range(m):
        if voted[i] >= 0:
            usable[voted[i]] = False
    found = brute_force_kernel(points, geometry, voted, np.flatnonzero(usable), tolerance_m, min_markers)
    if (found >= 0).sum() < min(m, finite.sum()):  # voting may have misled it: Alg. 3 on every point
        unguided = brute_force_kernel(points, geometry, no_fixed, np.flatnonzero(finite), tolerance_m, min_markers)
        if (unguided >= 0).sum() > (found >= 0).sum():
            found = unguided
    return found if np.any(found >= 0) else gated
