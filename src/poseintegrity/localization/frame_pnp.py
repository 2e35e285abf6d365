"""The PnP results of one frame for every method, computed once and cached beside its evidence.

Stages 02 and 05 solve each frame's correspondences with their PnP methods (:mod:`pnp`). The results are kept in
one small ``.npz`` per frame (``<features_dir>/<dataset>/images/<image>.pnp.npz``), a row per method, like the
SIFT features and the evidence, so that a re-run recomputes only what its changes reach (an edit of the package, of
``protocol`` or of ``parallel`` re-runs the stage, not its PnP). An entry's key hashes everything its result
depends on: the correspondences themselves (object and image points, which stand for the image, its features, M_t,
the ratio and the lens), M_t's digest, K, the method, the threshold, the confidence, the method's iteration cap,
the frame's seed and USAC's ``refine_lm`` (for USAC only); what computes it (OpenCV's and numpy's versions, the
kernels' dispatch level) is the file's own key (:mod:`poseintegrity.cache_entry`). An entry is used only when the
file is whole and recomputing the entry would give the same result; the methods without one are computed
(:func:`~poseintegrity.localization.pnp.solve_methods`, the classic RANSAC shared) and the file is rewritten by
write-then-rename with them added.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from poseintegrity.cache_entry import Miss, count, read_entry, write_entry
from poseintegrity.localization.pnp import PnPResult, solve_methods
from poseintegrity.params.extract import ExtractParams

PNP_CACHE_VERSION = 2  # bump when the cached content or its layout changes (2: OpenCV and numpy in the file's key)
FILE_KEY = f"pnp results, layout {PNP_CACHE_VERSION}"  # each method's entry carries its own key (pnp_key)
# one array per field, a row per method (the inliers of all methods concatenated): an .npz array costs ~30 us to read
FIELDS = ("methods", "keys", "T_cam_model", "n_inliers_reported", "status", "reason", "inlier_counts", "inliers")


def pnp_key(
    method: str, object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, digest: str,
    params: ExtractParams, max_iterations: int, seed: int,
) -> str:
    """Hash of everything the PnP result of ``method`` on these correspondences depends on (module docstring).

    object_points : (m, 3) float64 mm; image_points : (m, 2) float64 px; K : (3, 3) px; digest : M_t's
    """
    settings = [PNP_CACHE_VERSION, method, digest, np.asarray(K, np.float64).tolist(), len(object_points),
                params.reprojection_threshold_px, params.ransac_confidence, max_iterations, seed,
                params.usac_refine_lm if method == "usac_magsac" else None]
    points = (np.ascontiguousarray(object_points, np.float64).tobytes()
              + np.ascontiguousarray(image_points, np.float64).tobytes())
    return hashlib.sha1(json.dumps(settings).encode() + points).hexdigest()


def _stored(path: Path) -> dict[str, tuple[str, PnPResult]]:
    """The entries of a cache file: method -> (its key, its result); {} when the file is missing, not whole or of
    another layout."""
    stored = read_entry(path, FILE_KEY)
    if isinstance(stored, Miss) or any(field not in stored for field in FIELDS):
        return {}
    methods, keys, T, n_reported, status, reason, counts, inliers = (stored[field] for field in FIELDS)
    m = len(methods)
    if (methods.ndim != 1 or T.shape != (m, 4, 4) or inliers.ndim != 1 or counts.sum() != len(inliers)
            or any(len(a) != m for a in (keys, n_reported, status, reason, counts))):
        return {}  # a foreign layout: recomputed
    bounds = np.cumsum(counts)
    return {method: (str(keys[i]), PnPResult(T[i].astype(np.float64),
                                             inliers[bounds[i] - counts[i]:bounds[i]].astype(np.intp),
                                             int(n_reported[i]), str(status[i]), str(reason[i])))
            for i, method in enumerate(methods.tolist())}


def _write(path: Path, entries: Mapping[str, tuple[str, PnPResult]]) -> None:
    """Store the entries (:func:`_stored`'s layout) by write-then-rename."""
    results = [result for _, result in entries.values()]
    write_entry(path, FILE_KEY, dict(
        methods=np.array(list(entries), dtype=str), keys=np.array([key for key, _ in entries.values()], dtype=str),
        T_cam_model=np.array([r.T_cam_model for r in results], dtype=np.float64).reshape(-1, 4, 4),
        n_inliers_reported=np.array([r.n_inliers_reported for r in results], dtype=np.int64),
        status=np.array([r.status for r in results], dtype=str), reason=np.array([r.reason for r in results], dtype=str),
        inlier_counts=np.array([r.n_inliers for r in results], dtype=np.int64),
        inliers=np.concatenate([np.empty(0, np.intp)] + [r.inliers for r in results]).astype(np.int64)))


def stale_entries(stored: Mapping[str, tuple], missing: Sequence[str]) -> None:
    """Count a file whose entries of ``missing`` are recomputed (:func:`~poseintegrity.cache_entry.count`): stale
    when one of them was there under another key; a file read whole with only new methods to add is not counted."""
    if any(method in stored for method in missing):
        count("stale")


def frame_pnp(
    path: Path, object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, digest: str,
    methods: Sequence[str], max_iterations: Mapping[str, int], params: ExtractParams, seed: int,
) -> dict[str, PnPResult]:
    """The PnP result of every method of ``methods`` on one frame's correspondences: from the cache file ``path``
    for each method whose key matches, computed for the others (and added to the file).

    object_points : (m, 3) float64 mm, image_points : (m, 2) float64 px (undistorted), K : (3, 3) px, of checked
    evidence; digest : M_t's; max_iterations : each method's iteration cap; seed : the frame's RANSAC seed.
    """
    keys = {method: pnp_key(method, object_points, image_points, K, digest, params, max_iterations[method], seed)
            for method in methods}
    stored = _stored(path)
    missing = [method for method in methods if stored.get(method, ("",))[0] != keys[method]]
    if missing:
        stale_entries(stored, missing)
        computed = solve_methods(object_points, image_points, K, missing, params.reprojection_threshold_px,
                                 params.ransac_confidence, max_iterations, seed, params.usac_refine_lm)
        stored |= {method: (keys[method], result) for method, result in computed.items()}  # the others stay
        _write(path, stored)
    return {method: stored[method][1] for method in methods}
