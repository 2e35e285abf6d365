"""Evidence about a frame's pose that needs no ground truth (issue 50): how firmly its own data hold it there.

E_t and E_r need a trusted board pose; a robot in the field has none. What a frame's correspondences say about
their pose can be read from them alone, and from the stop's other images:

- ``consensus_t_mm``, ``consensus_r_deg``: the estimator's spread given the inlier set. ``n_bootstrap`` resamples of
  the frame's n_i inliers are drawn with replacement, each refined from the RANSAC pose T by ``cv2.solvePnP``
  (SOLVEPNP_ITERATIVE, Levenberg-Marquardt, extrinsic guess T) to T_b; the columns are
  sqrt(mean_b E_t(T_b, T)^2) and sqrt(mean_b E_r(T_b, T)^2), E_t / E_r of :func:`~poseintegrity.poses.pose_errors`
  (the bootstrap estimate of the RMS error of a least-squares pose, Efron & Tibshirani 1993). A resample that
  solvePnP cannot solve (fewer than 4 distinct points, no or a non-finite pose) is skipped; with fewer than
  :data:`MIN_RESAMPLES` solved ones the columns are NaN.
- ``consensus_elsewhere``: the share of ``n_reruns`` RANSAC re-runs of the same method, with seeds drawn from the
  frame's (:func:`rerun_seeds`), whose pose lands elsewhere: beyond ``elsewhere_mm`` or ``elsewhere_deg`` of T,
  or no pose at all. A share above 0 says another hypothesis has a support like the chosen one's (a second
  surface, a repeated texture): the pose is a draw, not a consensus. ``consensus_rerun_t_mm``: the largest E_t
  among the re-runs with a pose (NaN when none has one).
- ``stop_spread_t_mm``, ``stop_spread_r_deg`` (:func:`stop_spread`): the robot is still at a stop, its images
  differ by sensor noise only, so the spread of their poses is the estimator's variance for free: the RMS over the
  stop's posed images of E_t / E_r against their mean pose (translations averaged, rotations by the chordal L2
  mean of ``scipy.spatial.transform.Rotation.mean``); NaN with fewer than 2 posed images.

All of them are NaN where the frame has no pose. Stage 02 computes them for the method it runs,
``protocol.pnp_method`` (per frame of ~100 matches, ~60 inliers: ~2 ms for 16 resamples, ~15 ms for 3 USAC
re-runs); stage 05 leaves them NaN (:func:`~poseintegrity.localization.extract.extract_datasets`, ``consensus``).
The per-frame columns are cached beside the frame's PnP results (``<image>.consensus.npz``, the layout of
:mod:`frame_pnp`), under a key hashing the PnP result's own key (the correspondences, K, M_t, the method and its
settings, the frame's seed), the pose, its inliers, the re-run seeds and the ``extract.consensus`` settings, in a file
keyed by what computes them (:mod:`poseintegrity.cache_entry`): a re-run of the stage after an unrelated change
reads them.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from poseintegrity.cache_entry import Miss, read_entry, write_entry
from poseintegrity.localization.frame_pnp import pnp_key, stale_entries
from poseintegrity.localization.pnp import PnPResult, solve_methods
from poseintegrity.params.extract import ConsensusParams, ExtractParams
from poseintegrity.pose_correspondences import MIN_CORRESPONDENCES
from poseintegrity.poses import pose_errors, pose_from_rvec_tvec
from poseintegrity.seeding import keyed_rng
from poseintegrity.table_checks import CONSENSUS_COLUMNS, STOP_SPREAD_COLUMNS

STOP_KEYS = ["dataset", "method", "stop"]
MIN_RESAMPLES = 4  # an RMS of fewer solved resamples says little
CONSENSUS_CACHE_VERSION = 2  # bump when the cached content or its layout changes (2: OpenCV and numpy in the file key)
FILE_KEY = f"consensus columns, layout {CONSENSUS_CACHE_VERSION}"  # each method's entry carries its own key
FIELDS = ("methods", "keys", "values")  # values: (m, 4) float64, CONSENSUS_COLUMNS per method


def bootstrap_dispersion(
    object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, T_cam_model: np.ndarray,
    inliers: np.ndarray, n_bootstrap: int, rng: np.random.Generator,
) -> tuple[float, float]:
    """(consensus_t_mm, consensus_r_deg): RMS E_t (mm) and E_r (deg) of poses re-solved on ``n_bootstrap``
    resamples of the inliers against ``T_cam_model`` (module docstring).

    object_points : (n, 3) mm; image_points : (n, 2) px (undistorted); K : (3, 3) px; T_cam_model : (4, 4) mm, the
    pose the inliers were found with; inliers : (m,) int indices into the points. NaN with fewer than
    :data:`MIN_RESAMPLES` solved resamples (n_bootstrap 0 among them).
    """
    rvec0, _ = cv2.Rodrigues(T_cam_model[:3, :3])
    tvec0 = T_cam_model[:3, 3].reshape(3, 1)
    poses = []
    for _ in range(n_bootstrap):
        sample = inliers[rng.integers(0, len(inliers), len(inliers))]
        if len(np.unique(sample)) < MIN_CORRESPONDENCES:
            continue
        try:
            found, rvec, tvec = cv2.solvePnP(object_points[sample], image_points[sample], K, None, rvec0.copy(),
                                             tvec0.copy(), useExtrinsicGuess=True, flags=cv2.SOLVEPNP_ITERATIVE)
        except cv2.error:
            continue
        if found and np.isfinite(rvec).all() and np.isfinite(tvec).all():
            poses.append(pose_from_rvec_tvec(rvec, tvec))
    if len(poses) < MIN_RESAMPLES:
        return np.nan, np.nan
    E_t, E_r = pose_errors(np.stack(poses), T_cam_model)
    return float(np.sqrt(np.mean(E_t**2))), float(np.sqrt(np.mean(E_r**2)))


def rerun_seeds(seed: int, n_reruns: int) -> list[int]:
    """The seeds of a frame's RANSAC re-runs, drawn from a Generator keyed by its seed (the first r the same for
    every n_reruns >= r)."""
    return keyed_rng(seed, "consensus", "reruns").integers(0, 2**31 - 1, n_reruns).tolist()


def elsewhere(T_reruns: np.ndarray, T_cam_model: np.ndarray, elsewhere_mm: float,
              elsewhere_deg: float) -> tuple[float, float]:
    """(consensus_elsewhere, consensus_rerun_t_mm) of re-run poses T_reruns (r, 4, 4) mm (NaN: no pose) against
    the frame's pose T_cam_model (4, 4): the share of re-runs beyond elsewhere_mm or elsewhere_deg of it or without
    a pose, and the largest E_t (mm) of those with one (NaN if none has one, and both NaN for r = 0)."""
    if len(T_reruns) == 0:
        return np.nan, np.nan
    E_t, E_r = pose_errors(T_reruns, T_cam_model)
    away = ~((E_t <= elsewhere_mm) & (E_r <= elsewhere_deg))  # NaN (no pose) compares False: elsewhere
    posed = np.isfinite(E_t)
    return float(away.mean()), float(E_t[posed].max()) if posed.any() else np.nan


def frame_consensus(
    path: Path, object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, digest: str,
    results: Mapping[str, PnPResult], max_iterations: Mapping[str, int], params: ExtractParams, seed: int,
) -> dict[str, dict[str, float]]:
    """The :data:`CONSENSUS_COLUMNS` of every method of ``results`` (the frame's PnP results, :mod:`frame_pnp`):
    from the cache file ``path`` for each method whose key matches, computed for the others (and added to it).

    object_points : (n, 3) float64 mm, image_points : (n, 2) float64 px, K : (3, 3) px, of checked evidence;
    digest : M_t's; max_iterations : each method's iteration cap; seed : the frame's RANSAC seed. The re-runs of
    the methods computed share one :func:`~poseintegrity.localization.pnp.solve_methods` call per seed (the
    classic RANSAC shared); a method without a pose is not re-run (all NaN).
    """
    seeds = rerun_seeds(seed, params.consensus.n_reruns)
    keys = {method: consensus_key(pnp_key(method, object_points, image_points, K, digest, params,
                                          max_iterations[method], seed), result, seeds, params.consensus)
            for method, result in results.items()}
    stored = _stored(path)
    missing = [method for method in results if stored.get(method, ("",))[0] != keys[method]]
    if missing:
        stale_entries(stored, missing)
        computed = _computed(object_points, image_points, K, {m: results[m] for m in missing}, max_iterations,
                             params, seed, seeds)
        stored |= {method: (keys[method], values) for method, values in computed.items()}  # the others stay
        write_entry(path, FILE_KEY, dict(
            methods=np.array(list(stored), dtype=str), keys=np.array([key for key, _ in stored.values()], dtype=str),
            values=np.array([values for _, values in stored.values()], dtype=np.float64).reshape(-1, 4)))
    return {method: dict(zip(CONSENSUS_COLUMNS, map(float, stored[method][1]))) for method in results}


def consensus_key(pnp_key_: str, result: PnPResult, seeds: Sequence[int], settings: ConsensusParams) -> str:
    """Hash of everything a method's consensus columns depend on: its PnP result's key (:func:`frame_pnp.pnp_key`:
    the correspondences, K, M_t, the method and its settings, the frame's seed), the result's pose
    and inliers, the re-run seeds and the ``extract.consensus`` settings."""
    header = [CONSENSUS_CACHE_VERSION, pnp_key_, list(seeds), settings.n_bootstrap, settings.n_reruns,
              settings.elsewhere_mm, settings.elsewhere_deg]
    arrays = (np.ascontiguousarray(result.T_cam_model, np.float64).tobytes()
              + np.ascontiguousarray(result.inliers, np.int64).tobytes())
    return hashlib.sha1(json.dumps(header).encode() + arrays).hexdigest()


def _stored(path: Path) -> dict[str, tuple[str, np.ndarray]]:
    """The entries of a cache file: method -> (its key, its (4,) values); {} when the file is damaged or foreign."""
    stored = read_entry(path, FILE_KEY)
    if isinstance(stored, Miss) or any(field not in stored for field in FIELDS):
        return {}
    methods, keys, values = (stored[field] for field in FIELDS)
    if methods.ndim != 1 or keys.shape != methods.shape or values.shape != (len(methods), 4):
        return {}
    return {method: (str(keys[i]), values[i]) for i, method in enumerate(methods.tolist())}


def _computed(
    object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, results: Mapping[str, PnPResult],
    max_iterations: Mapping[str, int], params: ExtractParams, seed: int, seeds: Sequence[int],
) -> dict[str, np.ndarray]:
    """The (4,) :data:`CONSENSUS_COLUMNS` values of every method of ``results`` (module docstring)."""
    settings = params.consensus
    posed = [method for method, result in results.items() if result.status == "ok"]
    reruns = [solve_methods(object_points, image_points, K, posed, params.reprojection_threshold_px,
                            params.ransac_confidence, max_iterations, rerun_seed, params.usac_refine_lm)
              for rerun_seed in seeds] if posed else []
    values = {method: np.full(4, np.nan) for method in results}
    for method in posed:
        T = results[method].T_cam_model
        rng = keyed_rng(seed, "consensus", method)
        dispersion = bootstrap_dispersion(object_points, image_points, K, T, results[method].inliers,
                                          settings.n_bootstrap, rng)
        T_reruns = np.array([run[method].T_cam_model for run in reruns]).reshape(-1, 4, 4)
        values[method][:] = (*dispersion, *elsewhere(T_reruns, T, settings.elsewhere_mm, settings.elsewhere_deg))
    return values


def stop_spread(table: pd.DataFrame) -> pd.DataFrame:
    """:data:`STOP_SPREAD_COLUMNS` of an artifacts table's rows (its index; module docstring): per (dataset, method,
    stop), the RMS E_t (mm) and E_r (deg) of its posed rows' ``T_cam_board_est`` (16 numbers, NaN without a pose)
    against their mean pose, on every row of the stop; NaN with fewer than 2 posed rows."""
    group = table.groupby(STOP_KEYS, sort=False).ngroup().to_numpy()
    T = np.array(table["T_cam_board_est"].tolist(), dtype=np.float64).reshape(-1, 4, 4)
    posed = np.isfinite(T).all(axis=(1, 2))
    g, T = group[posed], T[posed]
    n_groups = int(group.max()) + 1 if len(group) else 0
    count = np.bincount(g, minlength=n_groups)
    spread = count >= 2
    T_mean = np.tile(np.eye(4), (n_groups, 1, 1))
    t_sum = np.stack([np.bincount(g, T[:, axis, 3], n_groups) for axis in range(3)], axis=1)
    T_mean[spread, :3, 3] = t_sum[spread] / count[spread, None]
    T_mean[spread, :3, :3] = chordal_mean(Rotation.from_matrix(T[:, :3, :3]).as_quat(), g, n_groups)[spread]
    E_t, E_r = pose_errors(T, T_mean[g])
    rms = {name: np.where(spread, np.sqrt(np.bincount(g, E**2, n_groups) / np.maximum(count, 1)), np.nan)[group]
           for name, E in zip(STOP_SPREAD_COLUMNS, (E_t, E_r))}
    return pd.DataFrame(rms, index=table.index)


def chordal_mean(quaternions: np.ndarray, group: np.ndarray, n_groups: int) -> np.ndarray:
    """(n_groups, 3, 3): the chordal L2 mean rotation of each group's unit quaternions (n, 4) (group : (n,) in
    0 .. n_groups - 1): the eigenvector of the largest eigenvalue of sum q q^T (Markley et al. 2007), as
    ``Rotation.mean`` computes it for one group; the identity for a group without rotations."""
    M = np.zeros((n_groups, 4, 4))
    np.add.at(M, group, quaternions[:, :, None] * quaternions[:, None, :])
    M[np.bincount(group, minlength=n_groups) == 0] = np.diag([0.0, 0.0, 0.0, 1.0])  # scalar-last: the identity
    return Rotation.from_quat(np.linalg.eigh(M)[1][:, :, -1]).as_matrix()
