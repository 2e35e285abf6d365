"""Board-based ground truth (Windsor et al. IV-C), checked before it judges anything.

The board's points are found (an ArUco GridBoard: ``ArucoDetector`` with sub-pixel corners, four per marker; a
ChArUco board: ``CharucoDetector.detectBoard``, whose chessboard corners are refined by ``cornerSubPix``; an image's
markers detected once for all its boards, :class:`ImageMarkers`; OpenCV 5 API, docs/references.md "OpenCV 5"),
undistorted by the calibrated lens and matched to the printed board's points (:mod:`poseintegrity.boards`). Then,
before a pose is trusted:

1. **Consistency of each group** (a marker's four corners; a ChArUco corner on its own). A marker partly hidden by the
   target is still decoded by OpenCV, with a corner several pixels off, and a fit through it is millimetres off. Each
   group is predicted by the pose fitted to all the *other* groups (leave one out, Levenberg-Marquardt from the full
   fit), and its RMS distance from that prediction is compared with the residual scale of that fit (what the rest of
   the board says its points agree to, floored at ``noise_floor_px``). The group whose ratio exceeds
   ``consistency_factor`` most is dropped, and the check repeats on the rest (:func:`consistent_fit`). Nothing here
   reads an exact pose.
2. **Enough groups to check**: at least ``min_markers`` markers or ``min_corners`` ChArUco corners must remain.
3. **Predicted uncertainty**: the covariance of the fitted pose, s^2 (J^T J)^-1, J the Jacobian of the projections
   with respect to (rvec, tvec) at the solution and s^2 = SSR / (2n - 6) the residual variance per coordinate
   (floored at ``noise_floor_px``^2); sigma_t (mm) is the RMS error it predicts for the board origin, where E_t is
   measured, sigma_r (deg) for the rotation. Above ``max_sigma_t_mm`` or ``max_sigma_r_deg`` the pose is too weak
   to judge a localization error of the tolerances' size.

A pose that passes has status ``ok``; one that fails 2 or 3 has status ``bad_ground_truth`` and a reason, and is no
ground truth (its frame's errors are NaN, the frame is listed, not counted as a localization error). ``board_not_
detected`` / ``board_pnp_failed``: nothing to check.

**Handover boards** (issue 39). Where the target or the image's edge takes the dataset's own board (A) from a frame,
another board of the scene (B, meta.json's ``handover_boards``) may judge it: the camera's motion since model image 0
read from B, T_cam_B T_cam0_B^-1, carried to where M_t was placed, T_cam0_A. So T_cam_A = T_cam_B T_BA with
T_BA = T_cam0_B^-1 T_cam0_A, both poses of model image 0 (:func:`handover`, :func:`handed_over`). Model image 0's own
pose T_cam0_A then cancels from what the ground truth adds to E_t, as M_t carries it: a perfect localization
returns T_cam_cam0 T_cam0_A, and so does a perfect B. (A T_BA averaged over the images where both boards are seen
would not: on the synthetic two-board scene of tests/localization/test_extract.py it added model image 0's own
0.7 mm error to every handed-over frame.) The handed-over pose is trusted when step 3's rule holds at A's origin: the
error it predicts there, sqrt(sigma_B(p)^2 + sigma_B0(p)^2), p = A's origin in B's frame, sigma_B(p) and
sigma_B0(p) what the covariances of B's pose in the frame and in model image 0 predict for p (:func:`sigma_t_at`,
which at p = 0 is sigma_t), and the rotation's, the two poses' sigma_r combined alike, stay within
``max_sigma_t_mm`` and ``max_sigma_r_deg``. The frame then says which board judged it (``board``: 0 its own, n its
n-th handover board). B must be trusted in model image 0.

**Per tolerance** (issue 39). Step 3's limits keep the ground truth's own error within R11's bar, a quarter of the
tightest tolerance (docs/references.md, "The trust rule and R11's bar"). A tolerance k_t times looser in E_t and k_r
times in E_r (4 mm / 10 deg against 2 mm / 3 deg: 2 and 3.3) has a bar that many times larger, so a pose refused by
step 3 alone, whose :func:`truth_scale` is within (k_t, k_r), still judges it: the envelopes read each tolerance from
the poses fine enough for it (:func:`~poseintegrity.localization.envelope.judged_errors`), and R11 is checked per
tolerance against its own bar (:mod:`~poseintegrity.localization.truth_accuracy`). A pose's status stays that of the
tightest tolerance.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

from poseintegrity.boards import Board, Charuco, board_from_dict, scaled
from poseintegrity.config import published
from poseintegrity.errors import ArgumentError
from poseintegrity.grayscale import as_gray8
from poseintegrity.lens import Camera
from poseintegrity.params.extract import GroundTruthParams
from poseintegrity.poses import NAN_POSE, inverse, pose_errors, pose_from_rvec_tvec

__all__ = ["BoardPose", "Handover", "ImageMarkers", "board_from_dict", "board_pose", "detect_board_points",
           "consistent_fit", "handed_over", "handover", "sigma_t_at", "truth_error", "truth_scale"]

LM_CRITERIA = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 50, 1e-12)


@dataclass(frozen=True)
class BoardPose:
    """The board's pose in one image and how far it can be trusted.

    T_cam_board : (4, 4) float, mm: NaN unless ``status`` is "ok" or "bad_ground_truth" (then the fit it refused)
    status : "ok", "bad_ground_truth", "board_not_detected", "board_pnp_failed" (or, set by callers, "no_board",
        "bad_image"); reason : why it is not "ok" ("" when it is)
    n_points : board points of the final fit; n_dropped : groups dropped by the consistency check
    rms_px : RMS reprojection residual of the final fit; sigma_t_mm, sigma_r_deg : its predicted uncertainty at the
        board origin (NaN without a fit); covariance : (6, 6) of (rvec, tvec) (rad, mm), s^2 (J^T J)^-1 (NaN without
        a fit)
    board : which board gave the pose: 0 the dataset's own, n > 0 its n-th handover board (module docstring)
    consistent : checks 1 and 2 passed (a pose refused by step 3 alone judges looser tolerances, :func:`truth_scale`)
    """

    T_cam_board: np.ndarray
    status: str
    reason: str = ""
    n_points: int = 0
    n_dropped: int = 0
    rms_px: float = float("nan")
    sigma_t_mm: float = float("nan")
    sigma_r_deg: float = float("nan")
    covariance: np.ndarray = field(default_factory=lambda: np.full((6, 6), np.nan))
    board: int = 0
    consistent: bool = False

    @property
    def trusted(self) -> bool:
        return self.status == "ok"


def truth_scale(pose: BoardPose, params: GroundTruthParams) -> tuple[float, float]:
    """The pose's predicted uncertainty in units of step 3's limits, (sigma_t / ``max_sigma_t_mm``, sigma_r /
    ``max_sigma_r_deg``): both at most 1 for a trusted pose; NaN where checks 1 and 2 failed. The limits keep the
    ground truth's own error within R11's bar, a quarter of the tightest tolerance; a tolerance k_t times looser in
    E_t and k_r times in E_r has a bar that many times larger and is judged by the poses of scales up to (k_t, k_r)
    (module docstring, "Per tolerance")."""
    if not pose.consistent:
        return float("nan"), float("nan")
    return float(pose.sigma_t_mm / params.max_sigma_t_mm), float(pose.sigma_r_deg / params.max_sigma_r_deg)


def no_pose(status: str, reason: str, n_points: int = 0) -> BoardPose:
    return BoardPose(NAN_POSE.copy(), status, reason, n_points)


class ImageMarkers:
    """The ArUco markers of one 8-bit gray image (h, w), detected once per dictionary (and corner refinement: a
    GridBoard's are sub-pixel, a ChArUco board's not) and shared by every board drawn from it: a frame's own board
    and its handover boards (ids from their ``first_id``, one dictionary) read the same detection. Each board then
    recovers its own missed markers from it, as the per-board detection did: the same OpenCV calls on the same
    arrays, so the same points, bit for bit (tests/localization/test_ground_truth.py). Why: marker detection on the
    whole image is most of a board's cost; a profile of stage 02 on an arc dataset with a handover board spent
    12.4 s of 40.6 s in 402 ``detectBoard`` calls for 200 frames, each detecting the markers anew.

    image : (h, w) uint8, the image every board is found in (:func:`detect_board_points` checks it is this one)
    """

    def __init__(self, image: np.ndarray) -> None:
        self.image = image
        self._detected: dict[tuple[str, bool], tuple] = {}

    def of_board(self, board: Board, cv_board: "cv2.aruco.Board") -> tuple[tuple[np.ndarray, ...], np.ndarray | None]:
        """The markers of ``board`` (its OpenCV board ``cv_board``): corners, n arrays (1, 4, 2) float32 sensor px,
        and ids (n, 1) int32 (None when none is found). Those detected in the image (any id of the dictionary), then
        those the board's layout predicts, searched again among the rejected candidates (defocused, far views;
        ``refineDetectedMarkers`` on copies: it may edit what it is given, and every board starts from the
        detection). A ChArUco board's markers are detected as ``CharucoDetector.detectBoard`` with
        ``tryRefineMarkers`` detects them itself (OpenCV's default RefineParameters); a GridBoard's with sub-pixel
        corners, the points of its pose."""
        subpixel = not isinstance(board, Charuco)
        if (board.dictionary, subpixel) not in self._detected:
            parameters = detector_parameters()
            if subpixel:
                parameters.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
            detector = cv2.aruco.ArucoDetector(cv_board.getDictionary(), parameters)
            self._detected[board.dictionary, subpixel] = (detector, *detector.detectMarkers(self.image))
        detector, corners, ids, rejected = self._detected[board.dictionary, subpixel]
        if ids is None or len(ids) == 0:
            return (), None
        corners, ids, _, _ = detector.refineDetectedMarkers(self.image, cv_board, [c.copy() for c in corners],
                                                            ids.copy(), [r.copy() for r in rejected])
        return corners, ids


def detect_board_points(image: np.ndarray, board: Board, markers: ImageMarkers | None = None
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The board points found in an 8-bit gray image (h, w): printed board points (n, 3) mm, their image points
    (n, 2) sensor px, and each point's group (n,) int (a marker's four corners share one; ChArUco corners are one
    each). Empty arrays when nothing is found. ``markers``: the image's :class:`ImageMarkers`, shared with the other
    boards found in it (detected here when None)."""
    markers = ImageMarkers(image) if markers is None else markers
    if markers.image is not image:
        raise ArgumentError("markers: detected in another image than the one the board is searched in")
    cv_board = board.cv_board()
    corners, ids = markers.of_board(board, cv_board)
    if ids is None or len(ids) == 0:  # (detectBoard given no markers would detect them itself)
        return np.empty((0, 3)), np.empty((0, 2)), np.empty(0, int)
    if isinstance(board, Charuco):  # the chessboard corners between the markers, refined by cornerSubPix
        corners, ids, _, _ = cv2.aruco.CharucoDetector(cv_board, cv2.aruco.CharucoParameters(), detector_parameters()
                                                       ).detectBoard(image, markerCorners=corners, markerIds=ids)
        if ids is None or len(ids) == 0:
            return np.empty((0, 3)), np.empty((0, 2)), np.empty(0, int)
        object_points = cv_board.getChessboardCorners()[ids.ravel()]
        image_points, groups = corners.reshape(-1, 2), np.arange(len(ids))
    else:
        object_points, image_points = cv_board.matchImagePoints(corners, ids)
        if object_points is None or len(object_points) == 0:
            return np.empty((0, 3)), np.empty((0, 2)), np.empty(0, int)
        object_points, image_points = object_points.reshape(-1, 3), image_points.reshape(-1, 2)
        groups = np.repeat(np.arange(len(object_points) // 4), 4)
    return scaled(object_points, board), np.asarray(image_points, np.float64), groups


def detector_parameters() -> "cv2.aruco.DetectorParameters":
    """OpenCV's marker detection with thresholding windows up to 53 px and 8 px per bit when a marker is read: a
    marker blurred by defocus (the lines' far stops are 150 mm beyond the focus) is then still found and decoded;
    the defaults (23 px, 4 px per bit) lost most markers there (docs/references.md, "Ground-truth boards")."""
    parameters = cv2.aruco.DetectorParameters()
    parameters.adaptiveThreshWinSizeMax = 53
    parameters.perspectiveRemovePixelPerCell = 8
    return parameters


def _fit(object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray,
         start: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """(rvec, tvec) of the least-squares pose of ideal-pinhole image points: IPPE (planar points) then LM, or LM from
    ``start``; None when OpenCV finds none."""
    obj, img = object_points.astype(np.float64), image_points.astype(np.float64)
    try:
        if start is None:
            found, rvec, tvec = cv2.solvePnP(obj, img, K, None, flags=cv2.SOLVEPNP_IPPE)
            if not found:
                return None
        else:  # (3, 1): OpenCV refines a (3,) vector in a copy and hands the start back unchanged
            rvec, tvec = start[0].reshape(3, 1).copy(), start[1].reshape(3, 1).copy()
        rvec, tvec = cv2.solvePnPRefineLM(obj, img, K, None, rvec, tvec, criteria=LM_CRITERIA)
    except cv2.error:
        return None
    if not (np.all(np.isfinite(rvec)) and np.all(np.isfinite(tvec))):
        return None
    return rvec.reshape(3), tvec.reshape(3)


def _residuals(object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, pose) -> np.ndarray:
    projected, _ = cv2.projectPoints(object_points, pose[0], pose[1], K, None)
    return np.linalg.norm(projected.reshape(-1, 2) - image_points, axis=1)


def consistent_fit(object_points: np.ndarray, image_points: np.ndarray, groups: np.ndarray, K: np.ndarray,
                   params: GroundTruthParams) -> tuple[tuple[np.ndarray, np.ndarray] | None, np.ndarray]:
    """Step 1 of the module docstring: the pose (rvec, tvec) fitted to the groups that agree with the others, and
    the mask (n,) of the points kept. object_points (n, 3) mm; image_points (n, 2) ideal-pinhole px of K.

    Each group g is predicted by the pose fitted to the others; its score is its RMS distance from that prediction
    over the residual scale of that fit, sqrt(SSR / (2 n - 6)) of the other points (a deleted residual in units of
    the fit's own noise; the scale floored at ``noise_floor_px``). A group that disagrees with a board its removal
    leaves consistent scores far above 1; one that fits scores about 1. The highest score above
    ``consistency_factor`` is dropped, and the check repeats on the rest while 3 groups remain."""
    keep = np.ones(len(groups), bool)
    pose = _fit(object_points, image_points, K)
    while pose is not None and len(np.unique(groups[keep])) >= 3:
        scores = {}
        for g in np.unique(groups[keep]):
            others, mine = keep & (groups != g), keep & (groups == g)
            fitted = _fit(object_points[others], image_points[others], K, start=pose)
            if fitted is None:
                scores[g] = np.inf
                continue
            spread = _residuals(object_points[others], image_points[others], K, fitted)
            scale = max(float(np.sqrt(np.sum(spread**2) / max(2 * others.sum() - 6, 1))), params.noise_floor_px)
            scores[g] = float(np.sqrt(np.mean(_residuals(object_points[mine], image_points[mine], K, fitted) ** 2)
                                      )) / scale
        worst = max(scores, key=scores.get)
        if scores[worst] <= params.consistency_factor:
            break
        keep &= groups != worst
        pose = _fit(object_points[keep], image_points[keep], K, start=pose)
    return pose, keep


def predicted_uncertainty(object_points: np.ndarray, image_points: np.ndarray, K: np.ndarray, pose,
                          noise_floor_px: float) -> tuple[float, float, float, np.ndarray]:
    """Step 3: (rms_px, sigma_t_mm, sigma_r_deg, covariance (6, 6) of (rvec, tvec)) of a fitted pose, from
    s^2 (J^T J)^-1 (module docstring)."""
    projected, jacobian = cv2.projectPoints(object_points, pose[0], pose[1], K, None)
    residual = projected.reshape(-1, 2) - image_points
    n = len(object_points)
    rms = float(np.sqrt(np.mean(np.sum(residual**2, axis=1))))
    s2 = max(float(np.sum(residual**2)) / max(2 * n - 6, 1), noise_floor_px**2)
    J = jacobian[:, :6]  # d(u, v) / d(rvec, tvec)
    try:
        covariance = s2 * np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        return rms, float("inf"), float("inf"), np.full((6, 6), np.inf)
    sigma_r = float(np.degrees(np.sqrt(max(np.trace(covariance[:3, :3]), 0.0))))
    sigma_t = float(np.sqrt(max(np.trace(covariance[3:, 3:]), 0.0)))
    return rms, sigma_t, sigma_r, covariance


def board_pose(image: np.ndarray, board: Board | dict, camera: Camera, params: GroundTruthParams | None = None,
               markers: ImageMarkers | None = None) -> BoardPose:
    """The checked pose of ``board`` in an 8-bit gray image (h, w) of ``camera`` (module docstring).

    image : (h, w) uint8 (colour or 16-bit images are converted, anything else refused,
    :func:`~poseintegrity.grayscale.as_gray8`); board : a :mod:`poseintegrity.boards` board or its dict; camera : a
    checked :class:`~poseintegrity.lens.Camera`; params : ``extract.ground_truth`` (params.yaml's by default);
    markers : the image's :class:`ImageMarkers` when other boards are found in the same (h, w) uint8 image (one
    marker detection for them all; the same pose as without). Never raises on what an image shows: a board not
    found, too few consistent points or too uncertain a pose are statuses.
    """
    if not isinstance(camera, Camera):
        raise ArgumentError(f"camera: expected a poseintegrity.lens.Camera, got {type(camera).__name__}")
    board = board_from_dict(board) if isinstance(board, dict) else board
    if not hasattr(board, "cv_board"):
        raise ArgumentError(f"board: expected a poseintegrity.boards board or its dict, got {type(board).__name__}")
    params = published("extract.ground_truth") if params is None else params
    image = as_gray8("image", image)
    object_points, sensor_points, groups = detect_board_points(image, board, markers)
    if len(object_points) < 4:
        return no_pose("board_not_detected", f"{len(object_points)} board points found (a pose needs 4)",
                       len(object_points))
    K = np.asarray(camera.K, np.float64)
    image_points = camera.undistort(sensor_points)
    pose, keep = consistent_fit(object_points, image_points, groups, K, params)
    if pose is None:
        return no_pose("board_pnp_failed", "OpenCV found no pose for the board's points", len(object_points))
    n_groups, n_dropped = len(np.unique(groups[keep])), len(np.unique(groups)) - len(np.unique(groups[keep]))
    rms, sigma_t, sigma_r, covariance = predicted_uncertainty(object_points[keep], image_points[keep], K, pose,
                                                              params.noise_floor_px)
    T = pose_from_rvec_tvec(*pose)
    checked = dict(T_cam_board=T, n_points=int(keep.sum()), n_dropped=n_dropped, rms_px=rms, sigma_t_mm=sigma_t,
                   sigma_r_deg=sigma_r, covariance=covariance)
    unit, needed = ("corners", params.min_corners) if isinstance(board, Charuco) else ("markers", params.min_markers)
    if n_groups < needed:
        return BoardPose(status="bad_ground_truth", reason=f"{n_groups} consistent board {unit} ({n_dropped} "
                         f"dropped): fewer than {needed} to check each against the others", **checked)
    if sigma_t > params.max_sigma_t_mm or sigma_r > params.max_sigma_r_deg:
        return BoardPose(status="bad_ground_truth", reason=f"predicted uncertainty {sigma_t:.3f} mm / "
                         f"{sigma_r:.3f} deg at the board origin exceeds {params.max_sigma_t_mm:g} mm / "
                         f"{params.max_sigma_r_deg:g} deg ({n_groups} {unit}, RMS {rms:.2f} px)", consistent=True,
                         **checked)
    return BoardPose(status="ok", consistent=True, **checked)


def truth_error(T_cam_board: np.ndarray, T_cam_board_exact: np.ndarray, T_cam0_board: np.ndarray,
                T_cam0_board_exact: np.ndarray) -> tuple[float, float]:
    """(E_t mm, E_r deg) that the board's ground truth adds to a frame's E_t and E_r (R11, issue 30).

    M_t is placed by the board's pose in model image 0 (T_cam0_board), so a perfect localization of a frame returns
    T_cam_cam0 T_cam0_board, T_cam_cam0 the frame camera's true motion since model image 0 (T_cam_board_exact
    T_cam0_board_exact^-1). E_t and E_r compare it with the frame's board pose T_cam_board: their difference, which
    this returns (IV-C's E_t and E_r, :func:`~poseintegrity.poses.pose_errors`), is the ground truth's error as E_t
    sees it, the board pose relative to model image 0's against the same relative exact pose. All (4, 4), mm; NaN
    when any pose is unknown."""
    perfect = T_cam_board_exact @ inverse(T_cam0_board_exact) @ T_cam0_board
    return tuple(float(e) for e in pose_errors(T_cam_board, perfect))


def sigma_t_at(pose: BoardPose, point: np.ndarray) -> float:
    """RMS error (mm) of a board-frame point (3,) mm, in the camera frame, that the pose's covariance predicts:
    sqrt(trace(J C J^T)), J = [d(R(rvec) p) / d rvec, I] (3, 6) (OpenCV's Rodrigues Jacobian); sigma_t at p = 0."""
    rvec, _ = cv2.Rodrigues(np.asarray(pose.T_cam_board[:3, :3], np.float64))
    _, dR = cv2.Rodrigues(rvec)  # (3, 9): row j is d vec(R) / d rvec_j, R row-major
    J = np.hstack([(dR.reshape(3, 3, 3) @ np.asarray(point, np.float64)).T, np.eye(3)])
    return float(np.sqrt(max(np.trace(J @ pose.covariance @ J.T), 0.0)))


@dataclass(frozen=True)
class Handover:
    """How the dataset's own board (A) stands in a handover board's (B) frame (module docstring): T_BA (4, 4) mm,
    from their poses in model image 0, and the errors B's pose there predicts: ``sigma_mm`` at A's origin (RMS),
    ``sigma_r_deg`` of its rotation."""

    T_BA: np.ndarray
    sigma_mm: float
    sigma_r_deg: float


def handover(own: BoardPose, other: BoardPose) -> Handover | None:
    """T_BA of a handover board from the two boards' poses in model image 0 (``own``: A's, ``other``: B's); None
    unless B's is trusted (A's places M_t whatever its status)."""
    if not other.trusted or not np.all(np.isfinite(own.T_cam_board)):
        return None
    T_BA = inverse(other.T_cam_board) @ own.T_cam_board
    return Handover(T_BA, sigma_t_at(other, T_BA[:3, 3]), other.sigma_r_deg)


def handed_over(pose: BoardPose, link: Handover, params: GroundTruthParams, board: int) -> BoardPose:
    """The dataset's own board pose T_cam_A = T_cam_B T_BA read from handover board ``board``'s pose ``pose`` (B's,
    trusted), checked at A's origin (module docstring); ``bad_ground_truth`` with the reason when it fails there."""
    T = pose.T_cam_board @ link.T_BA
    sigma_t = float(np.hypot(sigma_t_at(pose, link.T_BA[:3, 3]), link.sigma_mm))
    sigma_r = float(np.hypot(pose.sigma_r_deg, link.sigma_r_deg))
    checked = dict(T_cam_board=T, n_points=pose.n_points, n_dropped=pose.n_dropped, rms_px=pose.rms_px,
                   sigma_t_mm=sigma_t, sigma_r_deg=sigma_r, board=board, consistent=True)
    if sigma_t > params.max_sigma_t_mm or sigma_r > params.max_sigma_r_deg:
        return BoardPose(status="bad_ground_truth", reason=f"handover board {board}: predicted uncertainty "
                         f"{sigma_t:.3f} mm / {sigma_r:.3f} deg at the dataset board's origin exceeds "
                         f"{params.max_sigma_t_mm:g} mm / {params.max_sigma_r_deg:g} deg", **checked)
    return BoardPose(status="ok", **checked)
