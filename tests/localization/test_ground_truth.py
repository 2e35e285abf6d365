"""The board's ground truth (localization/ground_truth.py): exact poses of warped board images, the lens, the
consistency check against known corrupted corners, the predicted uncertainty against a Monte Carlo, the trust
statuses, and what a ground-truth error adds to E_t (truth_error) on known answers."""

import dataclasses

import cv2
import numpy as np
import pytest

import loc_synthetic as synthetic
from poseintegrity.boards import ArucoGrid, Charuco, board_from_dict, scaled
from poseintegrity.errors import ArgumentError
from poseintegrity.lens import Camera
from poseintegrity.localization import ground_truth
from poseintegrity.localization.ground_truth import (
    BoardPose, ImageMarkers, board_pose, consistent_fit, detect_board_points, detector_parameters, handed_over,
    handover, no_pose, predicted_uncertainty, sigma_t_at, truth_error, truth_scale,
)
from poseintegrity.params.extract import GroundTruthParams
from poseintegrity.poses import pose_errors, pose_from_rvec_tvec, pose_matrix
from scipy.spatial.transform import Rotation

CHECKS = synthetic.CHECKS


def test_board_pose_of_a_warped_board_image_is_the_known_pose():
    """GridBoard.generateImage placed on the plane and warped by the exact homography K [r1 r2 t] A."""
    plane, _ = synthetic.canvas(np.random.default_rng(0))
    for theta in (0.0, 20.0, 40.0):
        T = synthetic.arc_pose(theta, azimuth_deg=90.0)
        result = board_pose(synthetic.render(plane, T), synthetic.BOARD, synthetic.CAMERA, CHECKS)
        E_t_mm, E_r_deg = pose_errors(result.T_cam_board, T)
        assert result.status == "ok" and result.n_points == 24 and result.n_dropped == 0
        assert E_t_mm < 1.0 and E_r_deg < 0.5


def test_a_charuco_board_image_gives_the_known_pose_from_its_corners():
    board = Charuco("DICT_4X4_50", 7, 5, 15.0, 11.0)
    px_per_mm, margin = 6, 30
    image = board.cv_board().generateImage((105 * px_per_mm + 2 * margin, 75 * px_per_mm + 2 * margin),
                                           marginSize=margin)
    A = np.array([[1 / px_per_mm, 0, 0.5 / px_per_mm - margin / px_per_mm],
                  [0, 1 / px_per_mm, 0.5 / px_per_mm - margin / px_per_mm], [0, 0, 1]])  # texel -> board mm
    T = pose_matrix(Rotation.from_euler("xy", [20, -15], degrees=True).as_matrix(), [-50.0, -35.0, 300.0])
    # rendered at 4 x and averaged down (INTER_AREA): an anti-aliased image, as a lens and a sensor make one
    up = np.diag([4.0, 4.0, 1.0]) @ np.array([[1, 0, 0.375], [0, 1, 0.375], [0, 0, 1]])  # pixel centres at 4 x
    H = up @ synthetic.K @ np.column_stack([T[:3, 0], T[:3, 1], T[:3, 3]]) @ A
    large = cv2.warpPerspective(image, H, (4 * synthetic.IMAGE_SIZE[0], 4 * synthetic.IMAGE_SIZE[1]),
                                flags=cv2.INTER_LINEAR, borderValue=128)
    frame = cv2.resize(large, synthetic.IMAGE_SIZE, interpolation=cv2.INTER_AREA)
    result = board_pose(frame, board.as_dict(), synthetic.CAMERA, CHECKS)
    assert result.status == "ok" and result.n_points == 24
    E_t_mm, E_r_deg = pose_errors(result.T_cam_board, T)
    assert E_t_mm < 0.3 and E_r_deg < 0.2


def test_two_charuco_boards_in_one_image_each_find_their_own_corners():
    """A scene's second board has marker ids of its own (first_id, issue 39): side by side in one image, each board
    finds its 24 corners on its own side and none of the other's, and a board.yaml / meta.json of it round-trips."""
    first, second = Charuco("DICT_4X4_50", 7, 5, 15.0, 11.0), Charuco("DICT_4X4_50", 7, 5, 15.0, 11.0, first_id=17)
    tiles = [board.cv_board().generateImage((420 + 60, 300 + 60), marginSize=30) for board in (first, second)]
    image = np.full((360, 1000), 255, np.uint8)
    image[:, 10:490], image[:, 510:990] = tiles
    for board, side in ((first, slice(0, 500)), (second, slice(500, 1000))):
        object_points, image_points, _ = detect_board_points(image, board)
        assert len(object_points) == 24
        assert np.all((image_points[:, 0] >= side.start) & (image_points[:, 0] < side.stop))
    assert board_from_dict(second.as_dict()) == second and second.as_dict()["first_id"] == 17
    with pytest.raises(ArgumentError, match="board: markers 40 .. 56 do not fit DICT_4X4_50"):
        board_from_dict(second.as_dict() | {"first_id": 40})


PLANE_PX = 6  # texels per mm of the two-board plane below; its texel (0, 0) is centred at PLANE_MM[:2] + 0.5 / 6
PLANE_MM = (-20.0, -20.0, 280.0, 100.0)
TWO_BOARD_CAMERA = Camera(np.array([[900.0, 0, 500], [0, 900.0, 300], [0, 0, 1]]), np.zeros(5), 1000, 600)
T_TWO_BOARDS = pose_matrix(Rotation.from_euler("xy", [10, -35], degrees=True).as_matrix(), [-120.0, -40.0, 330.0])


def _two_boards(boards, at_mm, flipped=(), hidden=None) -> np.ndarray:
    """(600, 1000) uint8 image of ``boards`` on one plane (origins at ``at_mm``, mm), seen from T_TWO_BOARDS at
    35 deg, the second board farther. ``flipped``: (board index, marker index, (row, col)) cells of a marker's bit
    grid inverted, a bit error that detection refuses and the board's layout recovers; ``hidden``: (x0, y0, x1, y1)
    mm of the plane painted over, part of a board out of view."""
    x_min, y_min, x_max, y_max = PLANE_MM
    plane = np.full((round((y_max - y_min) * PLANE_PX), round((x_max - x_min) * PLANE_PX)), 200, np.uint8)
    texel = lambda x, y: (round((y - y_min) * PLANE_PX), round((x - x_min) * PLANE_PX))  # noqa: E731
    for board, (x, y) in zip(boards, at_mm):
        tile = board.cv_board().generateImage(tuple(round(s * PLANE_PX) for s in board.size_mm))
        v, u = texel(x, y)
        plane[v:v + tile.shape[0], u:u + tile.shape[1]] = tile
    for index, marker, (row, col) in flipped:
        board, (x, y) = boards[index], at_mm[index]
        cell = board.cv_board().getMarkerLength() / 6  # a 4 x 4 code and its border bits
        corner = board.cv_board().getObjPoints()[marker][0]
        (v0, u0), (v1, u1) = (texel(x + corner[0] + (col + i) * cell, y + corner[1] + (row + i) * cell) for i in (0, 1))
        plane[v0 + 2:v1 - 2, u0 + 2:u1 - 2] = 255 - plane[v0 + 2:v1 - 2, u0 + 2:u1 - 2]
    if hidden is not None:
        (v0, u0), (v1, u1) = texel(*hidden[:2]), texel(*hidden[2:])
        plane[v0:v1, u0:u1] = 90
    A = np.array([[1 / PLANE_PX, 0, x_min + 0.5 / PLANE_PX], [0, 1 / PLANE_PX, y_min + 0.5 / PLANE_PX], [0, 0, 1]])
    H = TWO_BOARD_CAMERA.K @ T_TWO_BOARDS[:3, [0, 1, 3]] @ A
    return cv2.warpPerspective(plane, H, (1000, 600), flags=cv2.INTER_LINEAR, borderValue=128)


def _found_alone(image: np.ndarray, board) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """detect_board_points as it was before the markers were shared: each board detecting the image's markers
    itself (a ChArUco board by detectBoard(image) with tryRefineMarkers; a GridBoard by detectMarkers with sub-pixel
    corners and refineDetectedMarkers)."""
    cv_board, empty = board.cv_board(), (np.empty((0, 3)), np.empty((0, 2)), np.empty(0, int))
    if isinstance(board, Charuco):
        charuco = cv2.aruco.CharucoParameters()
        charuco.tryRefineMarkers = True
        corners, ids, _, _ = cv2.aruco.CharucoDetector(cv_board, charuco, detector_parameters()).detectBoard(image)
        if ids is None or len(ids) == 0:
            return empty
        object_points, image_points, groups = (cv_board.getChessboardCorners()[ids.ravel()], corners.reshape(-1, 2),
                                               np.arange(len(ids)))
    else:
        parameters = detector_parameters()
        parameters.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
        detector = cv2.aruco.ArucoDetector(cv_board.getDictionary(), parameters)
        corners, ids, rejected = detector.detectMarkers(image)
        if ids is not None and len(ids):
            corners, ids, _, _ = detector.refineDetectedMarkers(image, cv_board, corners, ids, rejected)
        if ids is None or len(ids) == 0:
            return empty
        object_points, image_points = (a.reshape(len(a), -1) for a in cv_board.matchImagePoints(corners, ids))
        groups = np.repeat(np.arange(len(object_points) // 4), 4)
    return scaled(object_points, board), np.asarray(image_points, np.float64), groups


def _same_pose(a: BoardPose, b: BoardPose) -> bool:
    """Every field of the two poses equal, bit for bit (NaN where the other has NaN)."""
    return all(np.array_equal(x, y, equal_nan=not isinstance(x, str))
               for x, y in zip(dataclasses.astuple(a), dataclasses.astuple(b)))


@pytest.mark.parametrize("boards", [
    (Charuco("DICT_4X4_50", 7, 5, 15.0, 11.0), Charuco("DICT_4X4_50", 7, 5, 15.0, 11.0, first_id=17)),
    (ArucoGrid("DICT_4X4_50", 4, 3, 20.0, 5.0), ArucoGrid("DICT_4X4_50", 4, 3, 20.0, 5.0, first_id=12)),
], ids=["charuco", "aruco_grid"])
@pytest.mark.parametrize("seen", ["both_whole", "second_hidden_and_far"])
def test_boards_sharing_one_marker_detection_find_what_each_finds_alone(boards, seen, monkeypatch):
    """Two boards of one dictionary (ids from 0 and from a first_id of their own) in one image: found from one
    shared ImageMarkers, in either order, each board's points and checked pose are bit for bit what the board found
    detecting the image's markers alone. Seen whole, and with the second, farther board partly painted over and
    markers of both damaged by a bit, which only each board's own layout recovers (each board's refinement must
    start from the detection, not from what the other's made of it)."""
    flipped, hidden = (((1, 3, (2, 2)), (1, 1, (3, 1)), (0, 2, (1, 1))), (180.0, 30.0, 260.0, 100.0)
                       ) if seen == "second_hidden_and_far" else ((), None)
    image = _two_boards(boards, [(0.0, 0.0), (140.0, 0.0)], flipped, hidden)
    alone = [_found_alone(image, board) for board in boards]
    if seen == "second_hidden_and_far":  # the premise: each board has markers found by its refinement only
        for cv_board in (board.cv_board() for board in boards):
            detector = cv2.aruco.ArucoDetector(cv_board.getDictionary(), detector_parameters())
            corners, detected, rejected = detector.detectMarkers(image)
            refined = detector.refineDetectedMarkers(image, cv_board, corners, detected, rejected)[1]
            assert np.isin(refined, cv_board.getIds()).sum() > np.isin(detected, cv_board.getIds()).sum()
        assert 4 <= len(alone[1][0]) < len(alone[0][0])
    else:
        assert all(len(points) == len(alone[0][0]) > 0 for points, _, _ in alone)
    for order in ((0, 1), (1, 0)):
        markers = ImageMarkers(image)
        for index in order:
            shared = detect_board_points(image, boards[index], markers)
            assert all(np.array_equal(a, b) for a, b in zip(shared, alone[index]))
    markers = ImageMarkers(image)
    shared_poses = [board_pose(image, board, TWO_BOARD_CAMERA, CHECKS, markers) for board in boards]
    monkeypatch.setattr(ground_truth, "detect_board_points", lambda image, board, markers=None: _found_alone(
        image, board))
    for shared, board in zip(shared_poses, boards):
        assert shared.status in ("ok", "bad_ground_truth")
        assert _same_pose(shared, board_pose(image, board, TWO_BOARD_CAMERA, CHECKS))
    with pytest.raises(ArgumentError, match="markers: detected in another image"):
        detect_board_points(image.copy(), boards[0], markers)


def test_board_corners_are_undistorted_by_the_camera_before_the_pose():
    """The board seen through a barrel lens (the pinhole image on the lens' canvas, cv2.remap by its sensor maps):
    with the lens the known pose comes back; taken as a pinhole image it is off by a lot more."""
    lens = Camera(synthetic.K, np.array([-0.25, 0.08, 0.001, -0.0005, 0.0]), *synthetic.IMAGE_SIZE)
    K_canvas, width, height = lens.canvas
    plane, _ = synthetic.canvas(np.random.default_rng(0))
    T = synthetic.arc_pose(25.0, azimuth_deg=0.0)
    image = cv2.remap(synthetic.render(plane, T, K=K_canvas, size=(width, height)), *lens.sensor_maps, cv2.INTER_LINEAR)
    loose = GroundTruthParams(**{**CHECKS.model_dump(), "max_sigma_t_mm": 100.0, "max_sigma_r_deg": 90.0})
    with_lens = pose_errors(board_pose(image, synthetic.BOARD, lens, loose).T_cam_board, T)
    pinhole = pose_errors(board_pose(image, synthetic.BOARD, synthetic.CAMERA, loose).T_cam_board, T)
    assert with_lens[0] < 1.0 and with_lens[1] < 0.5
    assert pinhole[0] > 3 * with_lens[0] + 1.0


def test_board_built_from_meta_matches_the_reference_board():
    ours, reference = board_from_dict(synthetic.BOARD).cv_board(), synthetic.make_board()
    np.testing.assert_array_equal(np.array(ours.getObjPoints()), np.array(reference.getObjPoints()))
    np.testing.assert_array_equal(ours.getIds(), reference.getIds())


@pytest.mark.parametrize("spec, named", [
    ({key: value for key, value in synthetic.BOARD.items() if key != "separation_mm"}, "separation_mm"),
    ({"type": "charuco", "dictionary": "DICT_4X4_50", "squares_x": 7, "squares_y": 5, "square_mm": 15.0}, "marker_mm"),
    ({**synthetic.BOARD, "type": "chessboard"}, "board.type"),
])
def test_a_board_spec_missing_a_key_or_of_an_unknown_type_is_refused_by_name(spec, named):
    with pytest.raises(ArgumentError, match=named):
        board_from_dict(spec)


def test_no_board_gives_nan_pose_and_a_flag():
    result = board_pose(np.full((400, 640), 128, np.uint8), synthetic.BOARD, synthetic.CAMERA, CHECKS)
    assert result.status == "board_not_detected" and result.n_points == 0
    assert np.all(np.isnan(result.T_cam_board))


def test_two_markers_in_view_are_too_few_to_check_and_no_ground_truth():
    plane, _ = synthetic.canvas(np.random.default_rng(0))
    T = synthetic.arc_pose(0.0, azimuth_deg=0.0)
    image = synthetic.render(plane, T)
    corners, ids, _ = cv2.aruco.ArucoDetector(synthetic.make_board().getDictionary()).detectMarkers(image)
    for marker, marker_id in zip(corners, ids.ravel()):
        if marker_id not in (0, 1):  # paint over every marker but two
            cv2.fillConvexPoly(image, np.round(marker.reshape(4, 2)).astype(np.int32), 200)
    result = board_pose(image, synthetic.BOARD, synthetic.CAMERA, CHECKS)
    assert result.status == "bad_ground_truth" and "fewer than 3" in result.reason
    assert np.all(np.isfinite(result.T_cam_board))  # the refused fit is kept, for diagnosis
    assert not result.consistent and np.isnan(truth_scale(result, CHECKS)).all()  # it judges no looser tolerance


def test_a_pose_refused_by_the_limits_alone_has_its_uncertainty_in_units_of_them():
    """The whole board at 40 deg: trusted under the published-like limits; under limits a third of its predicted
    uncertainty, refused by step 3 alone, consistent, at truth scales of 3 on both axes."""
    plane, _ = synthetic.canvas(np.random.default_rng(0))
    image = synthetic.render(plane, synthetic.arc_pose(40.0, azimuth_deg=90.0))
    trusted = board_pose(image, synthetic.BOARD, synthetic.CAMERA, CHECKS)
    assert trusted.trusted and trusted.consistent
    np.testing.assert_allclose(truth_scale(trusted, CHECKS), [trusted.sigma_t_mm / CHECKS.max_sigma_t_mm,
                                                               trusted.sigma_r_deg / CHECKS.max_sigma_r_deg])
    strict = CHECKS.model_copy(update=dict(max_sigma_t_mm=trusted.sigma_t_mm / 3,
                                           max_sigma_r_deg=trusted.sigma_r_deg / 3))
    refused = board_pose(image, synthetic.BOARD, synthetic.CAMERA, strict)
    assert refused.status == "bad_ground_truth" and "predicted uncertainty" in refused.reason and refused.consistent
    np.testing.assert_allclose(truth_scale(refused, strict), [3.0, 3.0])
    np.testing.assert_array_equal(refused.T_cam_board, trusted.T_cam_board)  # the same fit, only judged otherwise


def _projected_board(T: np.ndarray, noise_px: float, rng: np.random.Generator):
    board = ArucoGrid("DICT_4X4_50", 3, 2, 24.0, 6.0)
    objects = np.array(board.cv_board().getObjPoints(), np.float64).reshape(-1, 3)
    rvec = cv2.Rodrigues(T[:3, :3])[0]
    image, _ = cv2.projectPoints(objects, rvec, T[:3, 3], synthetic.K, None)
    return objects, image.reshape(-1, 2) + noise_px * rng.standard_normal((len(objects), 2)), np.repeat(np.arange(6), 4)


def test_the_consistency_check_drops_the_marker_with_a_corner_off_and_recovers_the_pose():
    """A marker whose corner the target pulls 5 px off (a partly hidden marker, still decoded): the fit through it is
    off by millimetres; the check drops exactly that marker and the pose comes back within the noise."""
    rng = np.random.default_rng(3)
    T = pose_matrix(Rotation.from_euler("xy", [25, 10], degrees=True).as_matrix(), [-40.0, -25.0, 350.0])
    objects, image, groups = _projected_board(T, 0.05, rng)
    image[9] += [4.0, 3.0]  # marker 2's second corner
    pose, keep = consistent_fit(objects, image, groups, synthetic.K, CHECKS)
    assert set(groups[~keep]) == {2}
    assert pose_errors(pose_from_rvec_tvec(*pose), T)[0] < 0.3
    all_in = cv2.solvePnP(objects, image, synthetic.K, None, flags=cv2.SOLVEPNP_IPPE)
    assert pose_errors(pose_from_rvec_tvec(all_in[1], all_in[2]), T)[0] > 1.0


def test_the_consistency_check_keeps_every_marker_of_noise_alone():
    rng = np.random.default_rng(4)
    T = pose_matrix(Rotation.from_euler("xy", [30, -20], degrees=True).as_matrix(), [-40.0, -25.0, 350.0])
    dropped = 0
    for _ in range(50):
        objects, image, groups = _projected_board(T, 0.1, rng)
        dropped += (~consistent_fit(objects, image, groups, synthetic.K, CHECKS)[1]).sum()
    assert dropped == 0


def test_the_predicted_uncertainty_matches_a_monte_carlo_of_the_fit():
    """sigma_t, sigma_r of s^2 (J^T J)^-1 against the RMS error of 400 fits to points with 0.2 px noise."""
    rng = np.random.default_rng(5)
    T = pose_matrix(Rotation.from_euler("xy", [20, 15], degrees=True).as_matrix(), [-40.0, -25.0, 350.0])
    errors, predicted = [], []
    for _ in range(400):
        objects, image, _ = _projected_board(T, 0.2, rng)
        ok, rvec, tvec = cv2.solvePnP(objects, image, synthetic.K, None, flags=cv2.SOLVEPNP_IPPE)
        rvec, tvec = cv2.solvePnPRefineLM(objects, image, synthetic.K, None, rvec, tvec)
        errors.append(pose_errors(pose_from_rvec_tvec(rvec, tvec), T))
        predicted.append(predicted_uncertainty(objects, image, synthetic.K, (rvec.ravel(), tvec.ravel()), 0.0)[1:3])
    errors, predicted = np.array(errors), np.array(predicted)
    rms_t, rms_r = np.sqrt(np.mean(errors**2, axis=0))
    assert np.median(predicted[:, 0]) == pytest.approx(rms_t, rel=0.2)
    assert np.median(predicted[:, 1]) == pytest.approx(rms_r, rel=0.2)


def test_truth_error_is_zero_for_the_same_board_frame_error_and_the_offset_otherwise():
    """A board pose off by the same board-frame error in the frame and in model image 0 adds nothing to E_t (M_t was
    placed by the same error); a frame off by another 0.4 mm along board x adds exactly that."""
    rng = np.random.default_rng(6)
    exact_0 = pose_matrix(Rotation.random(random_state=rng).as_matrix(), [10.0, -5.0, 320.0])
    exact_f = pose_matrix(Rotation.random(random_state=rng).as_matrix(), [-30.0, 12.0, 350.0])
    delta = pose_matrix(Rotation.from_rotvec([0.002, -0.001, 0.003]).as_matrix(), [0.3, -0.2, 0.5])
    E_t, E_r = truth_error(exact_f @ delta, exact_f, exact_0 @ delta, exact_0)
    assert E_t == pytest.approx(0.0, abs=1e-9) and E_r == pytest.approx(0.0, abs=1e-6)
    shifted = exact_f @ pose_matrix(np.eye(3), [0.4, 0.0, 0.0]) @ delta
    E_t, E_r = truth_error(shifted, exact_f, exact_0 @ delta, exact_0)
    assert E_t == pytest.approx(0.4, abs=1e-9) and E_r == pytest.approx(0.0, abs=1e-6)
    assert np.isnan(truth_error(exact_f, exact_f, np.full((4, 4), np.nan), exact_0)[0])


@pytest.mark.parametrize(("change", "words"), [
    (lambda b: b.pop("separation_mm"), "board: a aruco_grid board needs separation_mm"),  # was a bare KeyError
    (lambda b: b.pop("dictionary"), "board: a aruco_grid board needs dictionary"),
    (lambda b: b.__setitem__("markers_x", "three"), "board.markers_x: expected a positive integer, got 'three'"),
    (lambda b: b.__setitem__("markers_x", 2.5), "board.markers_x: expected a positive integer"),
    (lambda b: b.__setitem__("marker_length_mm", float("nan")), "board.marker_length_mm: expected a positive number"),
    (lambda b: b.__setitem__("first_id", 48), "board: markers 48 .. 53 do not fit DICT_4X4_50 .50 markers."),
    (lambda b: b.__setitem__("scale", [1.0]), r"board.scale: expected \[x, y\]"),
])
def test_a_board_spec_missing_or_spoiling_a_key_is_refused_naming_it(change, words):
    board = dict(synthetic.BOARD)
    change(board)
    with pytest.raises(ArgumentError, match=words):
        board_from_dict(board)


def _fitted(T: np.ndarray, noise_px: float, rng: np.random.Generator) -> BoardPose:
    """The board pose fitted to the board's corners seen from T with ``noise_px`` of Gaussian noise, with its
    predicted covariance (what board_pose returns for a trusted pose)."""
    objects, image, _ = _projected_board(T, noise_px, rng)
    _, rvec, tvec = cv2.solvePnP(objects, image, synthetic.K, None, flags=cv2.SOLVEPNP_IPPE)
    rvec, tvec = cv2.solvePnPRefineLM(objects, image, synthetic.K, None, rvec, tvec)
    rms, sigma_t, sigma_r, covariance = predicted_uncertainty(objects, image, synthetic.K,
                                                              (rvec.ravel(), tvec.ravel()), 0.0)
    return BoardPose(pose_from_rvec_tvec(rvec, tvec), "ok", "", len(objects), 0, rms, sigma_t, sigma_r, covariance)


def test_the_error_predicted_at_a_point_is_sigma_t_at_the_origin_and_a_monte_carlo_elsewhere():
    """sigma_t_at(p): sigma_t at p = 0; at a point 150 mm beside the board, the RMS error of that point over 400 fits
    (0.2 px noise), within 15 %, and larger than at the origin (the rotation's error times the lever)."""
    rng = np.random.default_rng(8)
    T = pose_matrix(Rotation.from_euler("xy", [25, -10], degrees=True).as_matrix(), [-40.0, -25.0, 350.0])
    point = np.array([150.0, -60.0, 0.0])
    fits = [_fitted(T, 0.2, rng) for _ in range(400)]
    assert sigma_t_at(fits[0], np.zeros(3)) == pytest.approx(fits[0].sigma_t_mm, rel=1e-9)
    moved = np.array([(f.T_cam_board @ np.append(point, 1.0))[:3] for f in fits]) - (T @ np.append(point, 1.0))[:3]
    rms = np.sqrt(np.mean(np.sum(moved**2, axis=1)))
    predicted = np.median([sigma_t_at(f, point) for f in fits])
    assert predicted == pytest.approx(rms, rel=0.15)
    assert predicted > 1.2 * np.median([f.sigma_t_mm for f in fits])


def test_a_handover_board_carries_the_cameras_motion_to_the_own_boards_origin():
    """Two boards 120 mm apart. With exact poses T_BA is exact and the handed-over pose is the own board's exact
    pose. With noisy ones (0.2 px), over 200 frames, the handed-over pose errs from what a perfect localization
    returns, T_cam_cam0 T_cam0_A (model image 0's own error cancels), by an RMS within 15 % of the predicted
    sigma_t; a sigma_t bar below that prediction refuses it, naming the handover board; a handover board not trusted
    in model image 0 gives no link."""
    rng = np.random.default_rng(9)
    T_AB = pose_matrix(Rotation.from_euler("z", 12, degrees=True).as_matrix(), [120.0, 10.0, 5.0])
    view_0 = pose_matrix(Rotation.from_euler("xy", [10, -5], degrees=True).as_matrix(), [-60.0, -30.0, 330.0])
    frame = pose_matrix(Rotation.from_euler("xy", [-15, 20], degrees=True).as_matrix(), [-50.0, -35.0, 360.0])
    exact = lambda T: BoardPose(T, "ok", "", 24, 0, 0.0, 0.01, 0.01, np.eye(6) * 1e-8)  # noqa: E731
    link = handover(exact(view_0), exact(view_0 @ T_AB))
    np.testing.assert_allclose(link.T_BA, np.linalg.inv(T_AB), atol=1e-9)
    carried = handed_over(exact(frame @ T_AB), link, CHECKS, 1)
    np.testing.assert_allclose(carried.T_cam_board, frame, atol=1e-9)
    assert carried.status == "ok" and carried.board == 1

    errors, predicted = [], []
    for _ in range(200):
        anchor, anchor_B, seen = (_fitted(T, 0.2, rng) for T in (view_0, view_0 @ T_AB, frame @ T_AB))
        carried = handed_over(seen, handover(anchor, anchor_B), CHECKS.model_copy(update=dict(max_sigma_t_mm=9.0)), 1)
        perfect = frame @ np.linalg.inv(view_0) @ anchor.T_cam_board
        errors.append(np.linalg.norm(carried.T_cam_board[:3, 3] - perfect[:3, 3]))
        predicted.append(carried.sigma_t_mm)
    assert np.median(predicted) == pytest.approx(np.sqrt(np.mean(np.square(errors))), rel=0.15)
    assert np.median(predicted) > np.median([seen.sigma_t_mm])  # the lever to A's origin adds the rotation's error
    strict = CHECKS.model_copy(update=dict(max_sigma_t_mm=0.5 * carried.sigma_t_mm, max_sigma_r_deg=9.0))
    refused = handed_over(seen, handover(anchor, anchor_B), strict, 1)
    assert refused.status == "bad_ground_truth" and "handover board 1" in refused.reason
    assert handover(anchor, no_pose("board_not_detected", "")) is None
