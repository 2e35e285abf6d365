"""Which poses a candidate board serves (scenes/board_criteria.py, issue 39), checked against OpenCV's detector: a
board partly beyond the image serves while half its inner corners are found (its white margin may leave the image:
OpenCV's detector finds every corner of a board whose margin the image cuts off)."""

import cv2
import numpy as np
import pytest

from poseintegrity.config import load_params
from poseintegrity.localization.ground_truth import detect_board_points
from poseintegrity.scenes import textures
from poseintegrity.scenes.board_candidates import Candidates
from poseintegrity.scenes.board_criteria import corners_found, judge
from repository import ROOT


@pytest.fixture(scope="module")
def params():
    return load_params(ROOT / "params.yaml")


def test_a_board_partly_beyond_the_image_serves_while_half_its_corners_are_found(params):
    """A 7 x 5 board facing a camera 300 mm away (K of f = 1024 px, squares of 51.2 px), its pattern's left edge 10 px
    inside the image (its 6 mm white margin beyond the edge), then two and three squares and 10 px beyond it: the plan
    counts 24, 12 and 8 inner corners found (a corner needs its four squares' markers) and serves the first two
    (MIN_PLAN_CORNERS = 12); OpenCV's ChArUco detector, in synthetic images of the printed board so cut, finds all 24
    corners, then at least the 12 the plan counts."""
    generate = params.generate.world("main")
    drawing = generate.board.drawing()
    K, width, height, depth = np.array([[1024.0, 0.0, 484.0], [0.0, 1024.0, 304.0], [0.0, 0.0, 1.0]]), 968, 608, 300.0
    pattern = np.array(drawing.size_mm, float)
    margin = generate.board.margin_mm
    square_px = drawing.square_mm * K[0, 0] / depth
    px_per_mm = 8.0
    texture = textures.board_texture(drawing, px_per_mm, margin)
    scale = K[0, 0] / depth / px_per_mm
    top = K[1, 2] - pattern[1] / 2 * K[1, 1] / depth
    counted, served, found = [], [], []
    for left_px in (10.0, -2 * square_px - 10.0, -3 * square_px - 10.0):
        left_mm = (left_px - K[0, 2]) * depth / K[0, 0]
        centre = np.array([[left_mm + pattern[0] / 2, 0.0, depth]])
        axes = [np.array([v]) for v in np.eye(3)]  # x right, y down, z into the board: its print faces the camera
        c = Candidates(centre, *axes, pattern[None], np.array([drawing.square_mm]), pattern[None] + 2 * margin)
        cells = drawing.cv_board().getDictionary().markerSize + 2
        judged = judge(c, [np.eye(4)], [], (drawing.squares_x, drawing.squares_y), cells,
                       drawing.marker_mm / drawing.square_mm, K, width, height, depth, generate.camera,
                       generate.sensor.blur_sigma_px)
        counted.append(int(corners_found(
            _lattice_in_image(left_px, square_px, drawing, K, width, height), (drawing.squares_x, drawing.squares_y)
        ).sum()))
        served.append(bool(judged.served[0, 0]))
        # the printed board (with its margin) scaled to the camera's px per mm, cut by the image's left edge
        shift = np.array([[scale, 0.0, left_px - margin * px_per_mm * scale],
                          [0.0, scale, top - margin * px_per_mm * scale]])
        image = cv2.warpAffine(texture, shift, (width, height), flags=cv2.INTER_AREA, borderValue=255)
        if left_px > 0:
            assert image[:, 0].min() > 150  # the image's edge cuts the white margin only
        found.append(len(detect_board_points(image, drawing)[0]))
    assert counted == [24, 12, 8] and served == [True, True, False]
    assert found[0] == 24 and found[1] >= 12


def _lattice_in_image(left_px: float, square_px: float, drawing, K, width: int, height: int) -> np.ndarray:
    """(1, lattice) which corners of the squares of a board facing the camera, its left edge at ``left_px``, are in
    the image (rows of board_candidates.lattice)."""
    u = left_px + square_px * np.arange(drawing.squares_x + 1)
    v = K[1, 2] + square_px * (np.arange(drawing.squares_y + 1) - drawing.squares_y / 2)
    uu, vv = np.meshgrid(u, v)
    return ((uu >= 0) & (uu <= width - 1) & (vv >= 0) & (vv <= height - 1)).reshape(1, -1)


