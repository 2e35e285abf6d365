"""The PnP results of one frame for every method, computed once and cached beside its evidence.

Stages 02 and 05 solve each frame's correspondences with their PnP methods (:mod:`pnp`). The results are kept in
one small ``.npz`` per frame (``<features_dir>/<dataset>/images/<image>.pnp.npz``), an entry per method, like the
SIFT features and the evidence, so that a re-run recomputes only what its changes reach (an edit of the package, of
``protocol`` or of ``parallel`` re-runs the stage, not its PnP). An entry's key hashes everything its result
depends on: the correspondences themselves (object and image points, which stand for the image, its features, M_t,
the ratio and the lens), M_t's digest, K, the method, the threshold, the confidence, the method's iteration cap,
the frame's seed, USAC's ``refine_lm`` (for USAC only), and what computes it: OpenCV's version and the CPU features
its kernels dispatch to, numpy's version (its Generator orders the matches). An entry is used only when recomputing
it would give the same result; the methods without one are computed (:func:`~poseintegrity.localization.pnp.solve_methods`,
the classic RANSAC shared) and the file is rewritten by write-then-rename with them added.
"""

from __future__ import annotations

import hashlib
import json
import zipfile
from collections.abc import Mapping, Sequence
from pathlib import Path

import cv2
import numpy as np

from poseintegrity.localization.features import write_npz
from poseintegrity.localization.params import ExtractParams
from poseintegrity.localization.pnp import PnPResult, solve_methods

PNP_CACHE_VERSION = 1  # bump when the cached content, its layout or what computes it changes
FIELDS = ("key", "T_cam_model", "inliers", "n_inliers_reported", "status", "reason")


def pnp_key(
    method: str, object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, digest: str,
    params: ExtractParams, max_iterations: int, seed: int,
) -> str:
    """Hash of everything the PnP result of ``method`` on these correspondences depends on (module docstring).

    object_points : (k, 3) float64 mm; image_points : (k, 2) float64 px; K : (3, 3) px; digest : M_t's
    """
    settings = [PNP_CACHE_VERSION, method, digest, np.asarray(K, np.float64).tolist(), len(object_points),
                params.reprojection_threshold_px, params.ransac_confidence, max_iterations, seed,
                params.usac_refine_lm if method == "usac_magsac" else None,
                cv2.__version__, cv2.getCPUFeaturesLine(), np.__version__]
    points = (np.ascontiguousarray(object_points, np.float64).tobytes()
              + np.ascontiguousarray(image_points, np.float64).tobytes())
    return hashlib.sha1(json.dumps(settings).encode() + points).hexdigest()


def _stored(path: Path) -> dict[str, np.ndarray]:
    """Every array of a cache file; {} when it is missing, truncated or not an .npz."""
    try:
        with np.load(path) as stored:
            return {name: stored[name] for name in stored.files}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return {}


def _entry(stored: Mapping[str, np.ndarray], method: str, key: str) -> PnPResult | None:
    """The result of ``method`` in a cache file when stored under ``key``, else None."""
    names = [f"{method}.{field}" for field in FIELDS]
    if not all(name in stored for name in names) or str(stored[names[0]]) != key:
        return None
    T_cam_model, inliers, n_reported, status, reason = (stored[name] for name in names[1:])
    if T_cam_model.shape != (4, 4) or inliers.ndim != 1:
        return None  # a foreign layout: recomputed
    return PnPResult(T_cam_model.astype(np.float64), inliers.astype(np.intp), int(n_reported), str(status), str(reason))


def frame_pnp(
    path: Path, object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, digest: str,
    methods: Sequence[str], max_iterations: Mapping[str, int], params: ExtractParams, seed: int,
) -> dict[str, PnPResult]:
    """The PnP result of every method of ``methods`` on one frame's correspondences: from the cache file ``path``
    for each method whose key matches, computed for the others (and added to the file).

    object_points : (k, 3) float64 mm, image_points : (k, 2) float64 px (undistorted), K : (3, 3) px, of checked
    evidence; digest : M_t's; max_iterations : each method's iteration cap; seed : the frame's RANSAC seed.
    """
    keys = {method: pnp_key(method, object_points, image_points, K, digest, params, max_iterations[method], seed)
            for method in methods}
    stored = _stored(path) if path.exists() else {}
    results = {method: _entry(stored, method, keys[method]) for method in methods}
    missing = [method for method, result in results.items() if result is None]
    if not missing:
        return results
    results |= solve_methods(object_points, image_points, K, missing, params.reprojection_threshold_px,
                             params.ransac_confidence, max_iterations, seed, params.usac_refine_lm)
    kept = {name: array for name, array in stored.items() if name.split(".")[0] not in missing}
    for method in missing:
        result = results[method]
        kept |= {f"{method}.key": np.str_(keys[method]), f"{method}.T_cam_model": result.T_cam_model,
                 f"{method}.inliers": result.inliers, f"{method}.n_inliers_reported": result.n_inliers_reported,
                 f"{method}.status": np.str_(result.status), f"{method}.reason": np.str_(result.reason)}
    write_npz(path, **kept)
    return results
