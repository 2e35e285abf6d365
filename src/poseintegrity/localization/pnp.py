"""PnP-RANSAC (paper III-B, IV-C; Fig. 6 variants of V-A).

Two paths, both through ``cv2.solvePnPRansac``:

- ``usac_magsac``: the paper's path, OpenCV USAC with MAGSAC++ scoring, sigma-consensus local optimisation and a
  MAGSAC final polish; USAC always uses a P3P minimal solver (docs/references.md, "OpenCV 5").
- ``epnp``, ``p3p``, ``ap3p``, ``sqpnp``, ``iterative``: classic RANSAC with that ``SOLVEPNP_*`` flag. In
  OpenCV the minimal samples are solved with P3P/AP3P for those flags and with EPnP otherwise, and the final
  refit on the inliers uses the flag (EPnP for P3P/AP3P).

Refinement: USAC's MAGSAC polish can leave the pose well off the least-squares optimum of its own inliers (a
frame of ours with 108 inliers, all true: 2.5 mm / 1.0 deg from USAC, 0.05 mm / 0.05 deg from a least-squares fit
to them). With ``refine_lm`` the USAC pose is therefore polished by Levenberg-Marquardt on its inliers
(``cv2.solvePnPRefineLM``), the step classic ``solvePnPRansac`` takes itself with its final refit.

Iterations of the classic path: OpenCV stops as soon as the best consensus found makes ``confidence`` reached (its
adaptive RANSAC count), capped by ``iterationsCount``. The cap is sized, per method, for a stated inlier ratio w
(``extract.ransac_budget_inlier_ratio``): N = log(1 - p) / log(1 - w^s) (Fischler & Bolles 1981; Hartley &
Zisserman, Multiple View Geometry, 2nd ed., eq. 4.18), s the minimal sample OpenCV draws: 5 points solved by EPnP
for every flag but P3P/AP3P, which draw 4 (:mod:`~poseintegrity.ransac`; docs/references.md, "RANSAC
iteration count").
A frame with a lower inlier ratio may then fail: a budget, not a guarantee.

Shared RANSAC: EPnP, SQPnP and iterative draw the same samples, solve them with EPnP and differ only in the final
refit (:data:`EPNP_KERNEL`, with the proof from OpenCV's source). :func:`solve_methods` runs that RANSAC once per
frame and refits each of the others on its consensus with ``cv2.solvePnP``: the same results as a call per method
at about a third of their cost.

Failures: every run without a pose has a status of :data:`FAILURES` and a reason that says why, with its numbers.

n_i: classic RANSAC reports the inliers of the best *hypothesis*, not of the refined pose it returns (OpenCV
issue 29573; docs/references.md, "OpenCV 5"). For every method the inliers are therefore recounted on the returned pose with
``cv2.projectPoints`` and the same threshold; OpenCV's own count is kept as ``n_inliers_reported``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from poseintegrity.errors import ArgumentError, check_array, check_intrinsics, check_scalar, check_same_length
from poseintegrity.pose_correspondences import MIN_CORRESPONDENCES
from poseintegrity.poses import NAN_POSE, pose_from_rvec_tvec
from poseintegrity.ransac import minimal_sample_size

# names of docs/references.md, "OpenCV 5" (OpenCV 5 renumbered the flags: never use the integers)
CLASSIC_FLAGS = {
    "epnp": cv2.SOLVEPNP_EPNP,
    "p3p": cv2.SOLVEPNP_P3P,
    "ap3p": cv2.SOLVEPNP_AP3P,
    "sqpnp": cv2.SOLVEPNP_SQPNP,
    "iterative": cv2.SOLVEPNP_ITERATIVE,
}
METHODS = ("usac_magsac", *CLASSIC_FLAGS)
# The classic methods whose solvePnPRansac is one and the same RANSAC, differing only in the refit on its consensus
# (OpenCV 5, github.com/opencv/opencv, modules/geometry/src/solvepnp.cpp and ptsetreg.cpp; docs/references.md,
# "RANSAC iteration count"). In solvePnPRansac (classic branch), for any flag but P3P/AP3P:
#   1. the points are converted to float32 (opoints0.convertTo(opoints, CV_32F), the same for ipoints);
#   2. with more than 5 of them, model_points = 5 and ransac_kernel_method = SOLVEPNP_EPNP whatever the flag, and the
#      callback PnPRansacCallback(cameraMatrix, distCoeffs, SOLVEPNP_EPNP, useExtrinsicGuess, rvec, tvec) is made
#      from them alone: its runKernel solves each sample with solvePnP(..., EPNP) (EPnP ignores the uninitialised
#      rvec/tvec guess) and its computeError projects with projectPoints; neither reads the flag;
#   3. createRANSACPointSetRegistrator(cb, 5, reprojectionError, confidence, iterationsCount)->run(opoints, ipoints)
#      (ptsetreg.cpp, RANSACPointSetRegistrator::run) starts its generator from RNG((uint64)-1) on every call and
#      draws, solves, scores and stops (RANSACUpdateNumIters) from those inputs only: the same best model and the
#      same inlier mask for the three flags;
#   4. only then does the flag act: solvePnP on the consensus (the float32 points converted back to float64,
#      compressed in order by the mask) with the flag, SOLVEPNP_ITERATIVE starting from the best model
#      (_local_model, which only its own call sees: hence it leads). The refit of EPnP and of the iterative solver
#      gives one pose whenever it returns (solvePnPGeneric), so a leader's "no pose" means no consensus; SQPnP's
#      can give none (solvePnPRansac then returns false).
EPNP_KERNEL = ("iterative", "epnp", "sqpnp")  # in leading order
FAILURES = (
    "too_few_matches",    # fewer than MIN_CORRESPONDENCES matches
    "degenerate_points",  # collinear or coincident model points: no pose is defined
    "no_consensus",       # OpenCV returned no pose: no hypothesis reached a consensus within its iterations
    "opencv_error",       # cv2.error
    "non_finite_pose",    # OpenCV returned a pose with NaN or inf
    "too_few_inliers",    # fewer than MIN_CORRESPONDENCES matches within the threshold of the returned pose
)


@dataclass(frozen=True)
class PnPResult:
    """Outcome of one PnP-RANSAC run.

    T_cam_model : (4, 4) float, model (board) -> camera, mm; all NaN on failure
    inliers : (n_i,) int, indices of correspondences reprojecting within the threshold under T_cam_model
    n_inliers_reported : int, size of OpenCV's own inlier set
    status : "ok" or one of :data:`FAILURES`
    reason : why it failed, with its numbers ("" when ok)
    """

    T_cam_model: np.ndarray
    inliers: np.ndarray
    n_inliers_reported: int
    status: str
    reason: str = ""

    @property
    def n_inliers(self) -> int:
        return len(self.inliers)


def failed(status: str, reason: str) -> PnPResult:
    """The documented failed value: NaN pose, no inliers, a status and its reason."""
    return PnPResult(NAN_POSE.copy(), np.empty(0, dtype=np.intp), 0, status, reason)


def reprojection_errors(object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, T_cam_model: np.ndarray) -> np.ndarray:
    """Pixel distance between image points (n, 2) and projections of object points (n, 3, mm) under T_cam_model.

    Points behind the camera get an infinite error (they can never be inliers).
    """
    X_cam = object_points @ T_cam_model[:3, :3].T + T_cam_model[:3, 3]
    in_front = X_cam[:, 2] > 0
    x = X_cam @ K.T
    with np.errstate(divide="ignore", invalid="ignore"):
        projected = x[:, :2] / x[:, 2:3]
    errors = np.linalg.norm(projected - image_points, axis=1)
    return np.where(in_front, errors, np.inf)


def _is_degenerate(object_points: np.ndarray) -> bool:
    """True when the 3D points are (nearly) collinear or coincident: no PnP pose is defined."""
    centred = object_points - object_points.mean(axis=0)
    singular_values = np.linalg.svd(centred, compute_uv=False)
    return singular_values[1] <= 1e-6 * max(singular_values[0], 1e-12)


def _usac_params(threshold_px: float, confidence: float, max_iterations: int, seed: int) -> cv2.UsacParams:
    usac = cv2.UsacParams()
    usac.sampler = cv2.SAMPLING_UNIFORM
    usac.score = cv2.SCORE_METHOD_MAGSAC
    usac.loMethod = cv2.LOCAL_OPTIM_SIGMA
    usac.final_polisher = cv2.MAGSAC
    usac.threshold = threshold_px
    usac.confidence = confidence
    usac.maxIterations = max_iterations
    usac.randomGeneratorState = seed
    return usac


def _no_pose(method: str, n: int, threshold_px: float, max_iterations: int) -> str:
    """Why cv2.solvePnPRansac returned no pose (OpenCV 5's solvePnPRansac and RANSAC loop; docs/references.md,
    "RANSAC iteration count")."""
    if method == "usac_magsac":
        return f"USAC_MAGSAC found no pose in at most {max_iterations} iterations at {threshold_px:g} px ({n} matches)"
    s = 4 if n == 4 else minimal_sample_size(method)  # 4 matches: OpenCV takes P3P whatever the flag
    if n == s:  # as many matches as a sample: OpenCV solves them at once, without sampling
        return f"no pose: OpenCV solved the {n} matches at once (as many as a sample) and found none"
    reason = (f"no consensus: none of {max_iterations} samples of {s} of the {n} matches gave a pose with {s} or more "
              f"matches within {threshold_px:g} px")
    # SQPnP's refit on the best consensus can itself find no solution, which OpenCV reports the same way
    return reason + (", or the SQPnP refit on the consensus found none" if method == "sqpnp" else "")


def solve_pnp_ransac(
    object_points: np.ndarray,
    image_points: np.ndarray,
    K: np.ndarray,
    method: str,
    threshold_px: float,
    confidence: float,
    max_iterations: int,
    seed: int,
    refine_lm: bool,
) -> PnPResult:
    """Robust pose of the model from 2D-3D correspondences.

    object_points : (n, 3) float, model (board) frame, mm
    image_points : (n, 2) float, pixels (no lens distortion)
    K : (3, 3) float, camera matrix, pixels
    method : one of :data:`METHODS`
    seed : seeds the RANSAC samples, so that runs repeat exactly: USAC's generator state; on the classic path, whose
        generator OpenCV starts from one fixed state on every call (cv2.setRNGSeed does not reach it;
        docs/references.md, "RANSAC iteration count"), the order in which the matches are handed to OpenCV
    refine_lm : polish a USAC pose by Levenberg-Marquardt on its inliers (the classic path refits by itself)
    Fails (see :class:`PnPResult`, :data:`FAILURES`) with fewer than 4 correspondences, collinear object points, no
    pose from OpenCV, an OpenCV error, a non-finite pose or fewer than 4 recounted inliers; never raises for bad data.
    Arguments are checked once (:class:`~poseintegrity.errors.ArgumentError` naming the argument): finite points of
    shape (n, 3) / (n, 2) (or (n, 1, 3) / (n, 1, 2)) and the same n; K a pinhole matrix with positive focal
    lengths (a zero or NaN K gave a NaN pose or a wrong one); threshold_px > 0; confidence in (0, 1);
    max_iterations >= 1; a known method.
    """
    if method not in METHODS:
        raise ArgumentError(f"method: unknown PnP method {method!r}; expected one of {METHODS}")
    object_points, image_points = _points("object_points", object_points, 3), _points("image_points", image_points, 2)
    check_same_length(object_points=object_points, image_points=image_points)
    check_intrinsics("K", K)
    check_scalar("threshold_px", threshold_px, low=0.0, low_open=True)
    check_scalar("confidence", confidence, low=0.0, high=1.0, low_open=True)
    check_scalar("max_iterations", max_iterations, low=1.0)
    return solve_checked(object_points, image_points, K, method, threshold_px, confidence, max_iterations, seed,
                         refine_lm)


def _points(name: str, points: object, dims: int) -> np.ndarray:
    array = check_array(name, points)
    if array.ndim not in (2, 3) or array.shape[-1] != dims or (array.ndim == 3 and array.shape[1] != 1):
        raise ArgumentError(f"{name}: expected shape (n, {dims}) or (n, 1, {dims}), got {array.shape}")
    return array.reshape(-1, dims)


def solve_checked(
    object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, method: str, threshold_px: float,
    confidence: float, max_iterations: int, seed: int, refine_lm: bool,
) -> PnPResult:
    """:func:`solve_pnp_ransac` without its argument checks: for a per-frame loop whose K comes from a checked
    :class:`~poseintegrity.lens.Camera` and whose points are the matches of checked features."""
    object_points, image_points, K = _float64(object_points, image_points, K)
    n = len(object_points)
    if (early := _unsolvable(object_points)) is not None:
        return early
    try:
        if method == "usac_magsac":
            usac = _usac_params(threshold_px, confidence, max_iterations, seed)
            found, _, rvec, tvec, reported = cv2.solvePnPRansac(object_points, image_points, K, None, params=usac)
        else:
            order = _sample_order(seed, n)
            found, rvec, tvec, reported = _classic_ransac(object_points[order], image_points[order], K, method,
                                                          threshold_px, confidence, max_iterations)
    except cv2.error as error:
        return failed("opencv_error", f"cv2.error in {error.func}: {error.err}")
    return _outcome(found, rvec, tvec, 0 if reported is None else len(reported), object_points, image_points, K,
                    method, threshold_px, max_iterations, refine_lm)


def solve_methods(
    object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, methods: Sequence[str], threshold_px: float,
    confidence: float, max_iterations: Mapping[str, int], seed: int, refine_lm: bool,
) -> dict[str, PnPResult]:
    """:func:`solve_checked` of every method of ``methods`` on the same correspondences (``max_iterations``: each
    method's cap), the classic RANSAC run once for the methods of :data:`EPNP_KERNEL` that share it.

    Equal, value for value, to one :func:`solve_checked` call per method (``tests/localization/test_pnp.py``): those
    methods' classic ``solvePnPRansac`` calls draw the same samples, solve them with EPnP and score them alike, and
    differ only in the refit on the consensus (proof at :data:`EPNP_KERNEL`). The first of them in
    :data:`EPNP_KERNEL` order runs its own ``solvePnPRansac``; each other one refits on the consensus it returns
    with ``cv2.solvePnP`` and its own flag, on the points rounded as OpenCV's RANSAC holds them (float32). Anything
    else (a USAC or P3P/AP3P method, a single method of the group, a frame the RANSAC would not sample, an OpenCV
    error) takes :func:`solve_checked`.
    """
    object_points, image_points, K = _float64(object_points, image_points, K)
    group = [method for method in EPNP_KERNEL if method in methods]
    results = {}
    if len(group) > 1 and len({max_iterations[method] for method in group}) == 1:
        results = _shared_ransac(object_points, image_points, K, group, threshold_px, confidence,
                                 max_iterations[group[0]], seed)
    return {method: results[method] if method in results else
            solve_checked(object_points, image_points, K, method, threshold_px, confidence, max_iterations[method],
                          seed, refine_lm)
            for method in methods}


def _shared_ransac(
    object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, group: list[str], threshold_px: float,
    confidence: float, max_iterations: int, seed: int,
) -> dict[str, PnPResult]:
    """The results of the ``group`` methods (:data:`EPNP_KERNEL` order) from one classic RANSAC; {} when OpenCV
    would not sample (fewer than 6 matches, degenerate points) or raised (each method then runs on its own)."""
    n = len(object_points)
    if n <= minimal_sample_size(group[0]) or _unsolvable(object_points) is not None:
        return {}  # 4 or 5 matches: OpenCV solves them at once (P3P, EPnP), no RANSAC to share
    order = _sample_order(seed, n)
    X, x = object_points[order], image_points[order]
    leader, followers = group[0], group[1:]
    try:
        found, rvec, tvec, reported = _classic_ransac(X, x, K, leader, threshold_px, confidence, max_iterations)
    except cv2.error:
        return {}
    n_reported = 0 if reported is None else len(reported)
    results = {leader: _outcome(found, rvec, tvec, n_reported, object_points, image_points, K, leader, threshold_px,
                                max_iterations, refine_lm=False)}
    if not found:  # the leader's refit (EPnP, iterative) always gives a pose: the RANSAC found no consensus
        return results | {method: failed("no_consensus", _no_pose(method, n, threshold_px, max_iterations))
                          for method in followers}
    consensus = reported.ravel()  # ascending indices of X, x: OpenCV's compressElems keeps the order
    X_consensus = X.astype(np.float32).astype(np.float64)[consensus]  # as solvePnPRansac converts them, both ways
    x_consensus = x.astype(np.float32).astype(np.float64)[consensus]
    for method in followers:
        try:
            found, rvec, tvec = cv2.solvePnP(X_consensus, x_consensus, K, None, flags=CLASSIC_FLAGS[method])
        except cv2.error:
            continue  # solve_checked says what failed
        results[method] = _outcome(found, rvec, tvec, n_reported, object_points, image_points, K, method,
                                   threshold_px, max_iterations, refine_lm=False)
    return results


def _float64(object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, ...]:
    return (np.ascontiguousarray(object_points, dtype=np.float64).reshape(-1, 3),
            np.ascontiguousarray(image_points, dtype=np.float64).reshape(-1, 2), np.asarray(K, dtype=np.float64))


def _unsolvable(object_points: np.ndarray) -> PnPResult | None:
    """The failure of correspondences no PnP can solve (too few, degenerate), None otherwise."""
    n = len(object_points)
    if n < MIN_CORRESPONDENCES:
        return failed("too_few_matches", f"{n} matches, a pose needs {MIN_CORRESPONDENCES}")
    if _is_degenerate(object_points):
        return failed("degenerate_points", f"the {n} matched model points are (nearly) collinear or coincident")
    return None


def _sample_order(seed: int, n: int) -> np.ndarray:
    """The order in which the classic path hands the n matches to OpenCV: its fixed sampler, seeded."""
    return np.random.default_rng(seed).permutation(n)


def _classic_ransac(
    X: np.ndarray, x: np.ndarray, K: np.ndarray, method: str, threshold_px: float, confidence: float,
    max_iterations: int,
) -> tuple[bool, np.ndarray | None, np.ndarray | None, np.ndarray | None]:
    """OpenCV's classic solvePnPRansac with the method's flag: (found, rvec, tvec, its inlier indices)."""
    return cv2.solvePnPRansac(X, x, K, None, iterationsCount=max_iterations, reprojectionError=threshold_px,
                              confidence=confidence, flags=CLASSIC_FLAGS[method])


def _outcome(
    found: bool, rvec: np.ndarray | None, tvec: np.ndarray | None, n_reported: int, object_points: np.ndarray,
    image_points: np.ndarray, K: np.ndarray, method: str, threshold_px: float, max_iterations: int, refine_lm: bool,
) -> PnPResult:
    """The result of OpenCV's answer: its pose checked, (USAC with ``refine_lm``) polished, its inliers recounted."""
    n = len(object_points)
    if not found or rvec is None:
        return failed("no_consensus", _no_pose(method, n, threshold_px, max_iterations))
    if not (np.all(np.isfinite(rvec)) and np.all(np.isfinite(tvec))):
        return failed("non_finite_pose", f"OpenCV returned a non-finite pose: rvec {np.ravel(rvec)}, "
                                         f"tvec {np.ravel(tvec)}")
    T_cam_model = pose_from_rvec_tvec(rvec, tvec)
    inliers = np.flatnonzero(reprojection_errors(object_points, image_points, K, T_cam_model) <= threshold_px)
    if method == "usac_magsac" and refine_lm and len(inliers) >= MIN_CORRESPONDENCES:
        rvec, tvec = cv2.solvePnPRefineLM(object_points[inliers], image_points[inliers], K, None, rvec.copy(), tvec.copy())
        T_cam_model = pose_from_rvec_tvec(rvec, tvec)
        inliers = np.flatnonzero(reprojection_errors(object_points, image_points, K, T_cam_model) <= threshold_px)
    if len(inliers) < MIN_CORRESPONDENCES:
        return failed("too_few_inliers", f"{len(inliers)} of the {n} matches within {threshold_px:g} px of the "
                                         f"returned pose (OpenCV's consensus: {n_reported}), a pose needs "
                                         f"{MIN_CORRESPONDENCES}")
    return PnPResult(T_cam_model, inliers, n_reported, "ok")
