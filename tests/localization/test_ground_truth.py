import cv2
import numpy as np
import pytest

import loc_synthetic as synthetic
from poseintegrity.errors import ArgumentError
from poseintegrity.lens import Camera
from poseintegrity.poses import pose_errors
from poseintegrity.localization.ground_truth import board_pose, make_board


def test_board_pose_of_a_warped_board_image_is_the_known_pose():
    """GridBoard.generateImage placed on the plane and warped by the exact homography K [r1 r2 t] A."""
    plane, _ = synthetic.canvas(np.random.default_rng(0))
    board = make_board(synthetic.BOARD)
    for theta in (0.0, 20.0, 40.0):
        T = synthetic.arc_pose(theta, azimuth_deg=90.0)
        result = board_pose(synthetic.render(plane, T), board, synthetic.CAMERA)
        E_t_mm, E_r_deg = pose_errors(result.T_cam_board, T)
        assert result.status == "ok" and result.n_markers == 6
        assert E_t_mm < 1.0 and E_r_deg < 0.5


def test_board_corners_are_undistorted_by_the_camera_before_the_pose():
    """The board seen through a barrel lens (the pinhole image on the lens' canvas, cv2.remap by its sensor maps):
    with the lens the known pose comes back; taken as a pinhole image it is off by a lot more."""
    lens = Camera(synthetic.K, np.array([-0.25, 0.08, 0.001, -0.0005, 0.0]), *synthetic.IMAGE_SIZE)
    K_canvas, width, height = lens.canvas
    plane, _ = synthetic.canvas(np.random.default_rng(0))
    board = make_board(synthetic.BOARD)
    T = synthetic.arc_pose(25.0, azimuth_deg=0.0)
    image = cv2.remap(synthetic.render(plane, T, K=K_canvas, size=(width, height)), *lens.sensor_maps, cv2.INTER_LINEAR)
    with_lens = pose_errors(board_pose(image, board, lens).T_cam_board, T)
    pinhole = pose_errors(board_pose(image, board, synthetic.CAMERA).T_cam_board, T)
    assert with_lens[0] < 1.0 and with_lens[1] < 0.5
    assert pinhole[0] > 3 * with_lens[0] + 1.0


def test_board_built_from_meta_matches_the_reference_board():
    ours, reference = make_board(synthetic.BOARD), synthetic.make_board()
    np.testing.assert_array_equal(np.array(ours.getObjPoints()), np.array(reference.getObjPoints()))
    np.testing.assert_array_equal(ours.getIds(), reference.getIds())


def test_no_board_gives_nan_pose_and_a_flag():
    result = board_pose(np.full((400, 640), 128, np.uint8), make_board(synthetic.BOARD), synthetic.CAMERA)
    assert result.status == "board_not_detected" and result.n_markers == 0
    assert np.all(np.isnan(result.T_cam_board))


@pytest.mark.parametrize(("change", "words"), [
    (lambda b: b.pop("first_id"), "board: first_id: Field required"),  # was a bare KeyError: 'first_id'
    (lambda b: b.pop("dictionary"), "board: dictionary: Field required"),
    (lambda b: b.__setitem__("markers_x", "three"), "board: markers_x: Input should be a valid integer"),
    (lambda b: b.__setitem__("marker_length_mm", float("nan")), "board: marker_length_mm: Input should be a finite number"),
    (lambda b: b.__setitem__("first_id", 48), "board: .*markers 48 .. 53 do not fit DICT_4X4_50"),
])
def test_a_board_spec_missing_or_spoiling_a_key_is_refused_naming_it(change, words):
    board = dict(synthetic.BOARD)
    change(board)
    with pytest.raises(ArgumentError, match=words):
        make_board(board)
