"""The calibration session's views (scenes/calibration_views.py): the printed board renders where the true camera
projects it, and the drawn poses cover the whole image, corners included."""

import cv2
import numpy as np
import pytest

from poseintegrity.calibration import detect_corners
from poseintegrity.config import load_params
from poseintegrity.poses import pose_matrix
from poseintegrity.scenes import calibration_views as views
from poseintegrity.scenes.camera import true_camera
from poseintegrity.seeding import keyed_rng
from repository import ROOT

GENERATE = load_params(ROOT / "params.yaml").generate  # the paper-scale camera: 968 x 608 px, f = 1024 px


def projected_corners(T_cam_board: np.ndarray, board_points: np.ndarray) -> np.ndarray:
    camera = true_camera(GENERATE.camera)
    pixels, _ = cv2.projectPoints(board_points, cv2.Rodrigues(T_cam_board[:3, :3])[0], T_cam_board[:3, 3], camera.K,
                                  camera.dist)
    return pixels.reshape(-1, 2)


@pytest.mark.parametrize("tilt_deg", [0.0, 30.0])
def test_the_board_renders_where_the_true_camera_projects_it(tilt_deg):
    """Noise-free views of the board 300 mm away: its detected ChArUco corners lie where cv2.projectPoints puts the
    board's corners through the true lens, within 0.12 px RMS (measured 0.073 px facing the camera, 0.094 px tilted;
    a plane of the print's full size, stretched by n / (n - 1) texels, gave 0.16 px)."""
    quiet = GENERATE.model_copy(update={"sensor": GENERATE.sensor.model_copy(
        update={"read_noise_dn": 0.0, "shot_noise_dn_per_dn": 0.0, "flicker": 0.0}),
        "printed_boards": GENERATE.printed_boards.model_copy(  # the board exactly as drawn
        update={"scale_std": 0.0, "calibration_sag_std_mm": 0.0})})
    spec = views.charuco_spec(GENERATE)
    R = cv2.Rodrigues(np.array([np.radians(tilt_deg), 0.2, 0.05]))[0]
    width_mm, height_mm = spec.size_mm
    T_cam_board = pose_matrix(R, np.array([0.0, 0.0, 300.0]) - R @ np.array([width_mm / 2, height_mm / 2, 0.0]))
    board_points, pixels = detect_corners(views.render_view(quiet, T_cam_board, np.random.default_rng(0)), spec)
    assert len(board_points) == (spec.squares_x - 1) * (spec.squares_y - 1)  # every corner found
    errors = projected_corners(T_cam_board, board_points) - pixels
    assert np.sqrt(np.mean(np.sum(errors**2, axis=1))) < 0.12


def test_the_views_cover_the_image_corners_included():
    """The board's corners over the session's poses (inside the image) fall in every cell of an 8 x 8 grid of the
    image, and come within 10 % of the diagonal of each image corner (measured 2-8 %)."""
    camera, spec, session = true_camera(GENERATE.camera), views.charuco_spec(GENERATE), GENERATE.calibration
    board_points = spec.cv_board().getChessboardCorners()
    seen = []
    for i in range(session.n_views):
        T = views.view_pose(camera, spec, session.distance_mm, session.max_tilt_deg,
                            keyed_rng(GENERATE.seed, "calibration", i))
        pixels = projected_corners(T, board_points)
        seen.append(pixels[((pixels >= 0) & (pixels <= [camera.width - 1, camera.height - 1])).all(axis=1)])
    seen = np.concatenate(seen)
    cells, _, _ = np.histogram2d(seen[:, 0], seen[:, 1], bins=8, range=[[0, camera.width], [0, camera.height]])
    assert cells.min() > 0
    corners = np.array([[0, 0], [camera.width - 1, 0], [0, camera.height - 1], [camera.width - 1, camera.height - 1]])
    nearest = [np.linalg.norm(seen - corner, axis=1).min() for corner in corners]
    assert max(nearest) < 0.1 * np.hypot(camera.width, camera.height)


def test_a_view_pose_is_its_key_s():
    camera, spec, session = true_camera(GENERATE.camera), views.charuco_spec(GENERATE), GENERATE.calibration
    pose = lambda *key: views.view_pose(camera, spec, session.distance_mm, session.max_tilt_deg,  # noqa: E731
                                        keyed_rng(*key))
    assert np.array_equal(pose(GENERATE.seed, "calibration", 3), pose(GENERATE.seed, "calibration", 3))
    assert not np.allclose(pose(GENERATE.seed, "calibration", 3), pose(GENERATE.seed + 1, "calibration", 3))
