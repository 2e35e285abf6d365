"""poseintegrity.lens against OpenCV's own forward model of the lens (cv2.projectPoints), the project's renderer and
the ROS camera_info file layout: undistortion inverts projectPoints over the whole image, the sensor maps send every
ray where projectPoints puts it (pointwise, through cv2.remap, and for a rendered chessboard), folding coefficients
are refused (and do fold: two rays on one pixel), camera.yaml round trips and refuses bad fields naming them."""

import cv2
import numpy as np
import pytest
from scipy import ndimage

from params_cases import refusal
from poseintegrity.config import load_params
from poseintegrity.lens import Camera, CameraFileError, LensError, check_folding, read_camera_yaml, write_camera_yaml
from poseintegrity.scenes import foam, mesh, renderer
from poseintegrity.scenes.camera import true_camera
from poseintegrity.scenes.textures import build_atlas
from repository import ROOT

CAMERA = true_camera(load_params(ROOT / "params.yaml").generate.camera)  # the paper-scale lens of params.yaml
NO_ROTATION, NO_TRANSLATION = np.zeros(3), np.zeros(3)


def project(points_cam: np.ndarray, K: np.ndarray, dist: np.ndarray | None) -> np.ndarray:
    """(n, 3) camera-frame points -> (n, 2) pixels by cv2.projectPoints (the reference model)."""
    pixels, _ = cv2.projectPoints(points_cam, NO_ROTATION, NO_TRANSLATION, K, dist)
    return pixels.reshape(-1, 2)


def rays_in_view(camera: Camera, n: int, seed: int, depth_mm: float = 350.0, border_px: float = 0.0) -> np.ndarray:
    """(n, 3) camera-frame points whose distorted pixels lie in the image, ``border_px`` inside its edges
    (drawn on the ideal canvas, kept where projectPoints with the lens lands inside)."""
    rng = np.random.default_rng(seed)
    K_canvas, width, height = camera.canvas
    uv = rng.uniform([0, 0], [width - 1, height - 1], size=(4 * n, 2))
    xy = (uv - K_canvas[:2, 2]) / K_canvas[[0, 1], [0, 1]]
    points = np.column_stack([xy * depth_mm, np.full(len(xy), depth_mm)])
    pixels = project(points, camera.K, camera.dist)
    inside = ((pixels >= border_px) & (pixels <= [camera.width - 1 - border_px, camera.height - 1 - border_px])).all(1)
    return points[inside][:n]


def test_undistort_inverts_project_points_over_the_whole_image():
    """Every pixel of the 968 x 608 image, corners included: undistorted, then projected by OpenCV with the lens,
    it comes back within 1e-3 px (measured 1e-10 px); the corners move ~10 px."""
    u, v = np.meshgrid(np.arange(CAMERA.width, dtype=float), np.arange(CAMERA.height, dtype=float))
    pixels = np.column_stack([u.ravel(), v.ravel()])
    ideal = CAMERA.undistort(pixels)
    rays = np.column_stack([(ideal - CAMERA.K[:2, 2]) / CAMERA.K[[0, 1], [0, 1]], np.ones(len(ideal))])
    error = np.linalg.norm(project(rays, CAMERA.K, CAMERA.dist) - pixels, axis=1)
    assert error.max() < 1e-3
    corners = [0, CAMERA.width - 1, (CAMERA.height - 1) * CAMERA.width, CAMERA.height * CAMERA.width - 1]
    assert np.linalg.norm(ideal[corners] - pixels[corners], axis=1).min() > 3.0  # the corners do move (barrel)


def test_distort_is_project_points():
    points = rays_in_view(CAMERA, 500, seed=1)
    ideal = project(points, CAMERA.K, None)
    assert np.abs(CAMERA.distort(ideal) - project(points, CAMERA.K, CAMERA.dist)).max() < 1e-9


def test_sensor_maps_send_each_ray_where_project_points_puts_it():
    """For rays anywhere in the image: the maps, read (bilinearly, in float64) at the pixel where projectPoints puts
    the ray through the lens, give the canvas pixel where projectPoints puts it through the canvas' pinhole
    (within 0.01 px; measured 5e-5 px, the float32 maps' rounding)."""
    points = rays_in_view(CAMERA, 2000, seed=2)
    sensor = project(points, CAMERA.K, CAMERA.dist)
    K_canvas, _, _ = CAMERA.canvas
    map_x, map_y = CAMERA.sensor_maps
    at = [sensor[:, 1], sensor[:, 0]]
    read = np.column_stack([ndimage.map_coordinates(m.astype(np.float64), at, order=1) for m in (map_x, map_y)])
    assert np.linalg.norm(read - project(points, K_canvas, None), axis=1).max() < 0.01


def test_canvas_holds_every_ray_of_the_image_with_room_for_bilinear_sampling():
    _, width, height = CAMERA.canvas
    map_x, map_y = CAMERA.sensor_maps
    assert map_x.shape == map_y.shape == (CAMERA.height, CAMERA.width)
    assert map_x.min() >= 1 and map_y.min() >= 1 and map_x.max() <= width - 2 and map_y.max() <= height - 2


def spot_centroid_errors(image: np.ndarray, expected: np.ndarray, r: int = 7) -> np.ndarray:
    """(n,) distance of each spot's intensity centroid, in a (2r + 1)^2 window, from its expected pixel (n, 2)."""
    errors = []
    for x, y in expected:
        x0, y0 = int(round(x)), int(round(y))
        patch = image[y0 - r: y0 + r + 1, x0 - r: x0 + r + 1].astype(np.float64)
        yy, xx = np.mgrid[y0 - r: y0 + r + 1, x0 - r: x0 + r + 1]
        errors.append(np.hypot((patch * xx).sum() / patch.sum() - x, (patch * yy).sum() / patch.sum() - y))
    return np.array(errors)


def test_remapped_canvas_puts_points_where_project_points_says():
    """Gaussian spots (sigma 1.5 px) drawn on the canvas at the rays' ideal pixels, distorted onto the sensor with the
    maps: resampled by a cubic B-spline, each spot's centroid lies where projectPoints puts its ray through the lens
    within 0.005 px (measured 0.0006 px: the maps are right); by cv2.remap's bilinear interpolation within 0.03 px
    (measured 0.023 px max, 0.010 px RMS: bilinear resampling at the lens' local scale, 0.95 in the corners, shifts
    a small spot by up to ~0.02 px depending on its phase between canvas pixels; exact for a pure shift)."""
    K_canvas, width, height = CAMERA.canvas
    grid = np.stack(np.meshgrid(np.linspace(40, CAMERA.width - 41, 9), np.linspace(40, CAMERA.height - 41, 6)), -1)
    ideal_sensor = CAMERA.undistort(grid.reshape(-1, 2))  # spots spread over the image, corners included
    points = np.column_stack([(ideal_sensor - CAMERA.K[:2, 2]) / CAMERA.K[[0, 1], [0, 1]], np.ones(len(ideal_sensor))])
    on_canvas = project(points, K_canvas, None)
    u, v = np.meshgrid(np.arange(width, dtype=float), np.arange(height, dtype=float))
    sigma = 1.5
    canvas = sum(np.exp(-((u - cu) ** 2 + (v - cv) ** 2) / (2 * sigma**2)) for cu, cv in on_canvas).astype(np.float32)
    expected = project(points, CAMERA.K, CAMERA.dist)
    map_x, map_y = CAMERA.sensor_maps
    spline = ndimage.map_coordinates(canvas.astype(np.float64), [map_y.astype(np.float64), map_x.astype(np.float64)],
                                     order=3)
    assert spot_centroid_errors(spline, expected).max() < 0.005
    bilinear = cv2.remap(canvas, map_x, map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    assert spot_centroid_errors(bilinear, expected).max() < 0.03


def chessboard(squares: int, texels_per_square: int) -> np.ndarray:
    """A black and white chessboard texture, squares x squares."""
    cells = (np.add.outer(np.arange(squares), np.arange(squares)) % 2).astype(np.uint8)
    return np.kron(cells, np.ones((texels_per_square, texels_per_square), np.uint8)) * 200 + 30


def test_rendered_chessboard_corners_land_where_project_points_says():
    """A chessboard plane rendered by the project's renderer on the canvas, distorted by the maps: its inner
    corners, found by cv2.findChessboardCornersSB, lie where projectPoints puts them through the lens (within
    0.06 px RMS, measured 0.043 px; the same detection on a pinhole render of the same board errs as much, 0.044 px)."""
    squares, q, side_mm = 8, 32, 160.0
    texture = chessboard(squares, q)
    n = texture.shape[0]
    R = cv2.Rodrigues(np.array([0.35, -0.25, 0.1]))[0]
    T_cam_board = np.eye(4)
    T_cam_board[:3, :3], T_cam_board[:3, 3] = R, [40.0, 25.0, 330.0]  # off centre, tilted: its corners see distortion
    flip = np.diag([1.0, -1.0, -1.0, 1.0])  # plane() faces +z; the board faces the camera (-z)
    board = mesh.plane(side_mm, side_mm, 8, 8, "board", material=mesh.Material(specular=0.0))
    flat = foam.ReliefVolume(np.zeros((8, 8, 8), np.float32), 0.125, 0.2, 0.0, 1.0)
    scene = renderer.SceneGeometry.from_meshes([("board", board.transformed(T_cam_board @ flip))],
                                               build_atlas({"board": texture}), np.array([0.0, 0.0, -1.0]),
                                               (0.2, 0.8, 0.0, 0.1), flat)
    # texel c lies at (c / (n - 1) - 1/2) side of the plane's centre (test_renderer); a square edge between texels
    k = np.arange(1, squares)
    edges = ((k * q - 0.5) / (n - 1) - 0.5) * side_mm
    X, Y = np.meshgrid(edges, edges)
    corners_plane = np.column_stack([X.ravel(), -Y.ravel(), np.zeros(X.size)])  # texture v runs along -y
    corners_cam = (corners_plane @ np.diag([1.0, -1.0, -1.0])) @ R.T + T_cam_board[:3, 3]

    def found(image: np.ndarray, expected: np.ndarray) -> np.ndarray:
        ok, corners = cv2.findChessboardCornersSB(image, (squares - 1, squares - 1), flags=cv2.CALIB_CB_ACCURACY)
        assert ok
        corners = corners.reshape(-1, 2)
        order = [int(np.argmin(np.linalg.norm(corners - e, axis=1))) for e in expected]  # match by proximity
        return corners[order]

    K_canvas, width, height = CAMERA.canvas
    canvas = renderer.render(scene, K_canvas, width, height, np.eye(4)).radiance
    sensor = cv2.remap(canvas, *CAMERA.sensor_maps, cv2.INTER_LINEAR)
    to_u8 = lambda radiance: np.clip(np.rint(radiance * 255), 0, 255).astype(np.uint8)  # noqa: E731
    expected = project(corners_cam, CAMERA.K, CAMERA.dist)
    rms = np.sqrt(np.mean(np.sum((found(to_u8(sensor), expected) - expected) ** 2, axis=1)))
    pinhole = renderer.render(scene, CAMERA.K, CAMERA.width, CAMERA.height, np.eye(4)).radiance
    expected_pinhole = project(corners_cam, CAMERA.K, None)
    rms_pinhole = np.sqrt(np.mean(np.sum((found(to_u8(pinhole), expected_pinhole) - expected_pinhole) ** 2, axis=1)))
    assert rms < 0.06 and rms < 1.5 * rms_pinhole + 0.01
    assert np.linalg.norm(expected - expected_pinhole, axis=1).max() > 1.0  # the lens moved the corners


def radial(r: np.ndarray, dist) -> np.ndarray:
    k1, k2, _, _, k3 = dist
    return r * (1 + k1 * r**2 + k2 * r**4 + k3 * r**6)


@pytest.mark.parametrize("dist", [[-0.6, 0.0, 0.0, 0.0, 0.0], [0.0, -0.9, 0.0, 0.0, 0.0], [0.1, 0.0, 0.0, 0.0, -3.0]])
def test_radially_folding_coefficients_are_refused_and_do_fold(dist):
    """r_d turns back before the farthest image corner: projectPoints puts two different rays on one pixel (the
    fold is real), and check_folding refuses the coefficients."""
    K = CAMERA.K
    r_corner = np.max(np.hypot(*((np.array([[0, 0], [CAMERA.width - 1, CAMERA.height - 1], [0, CAMERA.height - 1],
                                            [CAMERA.width - 1, 0]]) - K[:2, 2]) / K[0, 0]).T))
    r = np.linspace(0, 3 * r_corner, 30001)
    r_d = radial(r, dist)
    top = int(np.argmax(np.diff(r_d) <= 0))  # where r_d stops increasing
    assert r_d[top] < r_corner  # inside the image
    beyond = top + int(np.argmin(np.abs(r_d[top:] - r_d[top // 2])))  # a second ray with the same distorted radius
    rays = np.array([[r[top // 2], 0.0, 1.0], [r[beyond], 0.0, 1.0]])
    twins = project(rays, K, np.array(dist, float))
    assert abs(rays[1, 0] - rays[0, 0]) > 0.05 and np.abs(twins[0] - twins[1]).max() < 0.5
    with pytest.raises(LensError, match="folds"):
        check_folding(K, np.array(dist, float), CAMERA.width, CAMERA.height)


def test_tangentially_folding_coefficients_are_refused():
    """p1 = 0.6 alone: the Jacobian determinant (1 + 2 p1 y)(1 + 6 p1 y) - 4 p1^2 x^2 < 0 on the image's top rows
    (y ~ -0.3), while the radial mapping is the identity."""
    x, y, p1 = 0.0, -0.29, 0.6
    assert (1 + 2 * p1 * y) * (1 + 6 * p1 * y) - 4 * p1**2 * x**2 < 0
    with pytest.raises(LensError, match="Jacobian"):
        check_folding(CAMERA.K, np.array([0.0, 0.0, p1, 0.0, 0.0]), CAMERA.width, CAMERA.height)


@pytest.mark.parametrize("dist", [[0.0] * 5, [-0.06, 0.02, 0.0002, -0.0001, 0.0], [0.12, -0.05, -0.001, 0.001, 0.01],
                                  [-0.25, 0.08, 0.0, 0.0, 0.0]])
def test_lenses_of_machine_vision_cameras_pass(dist):
    check_folding(CAMERA.K, np.array(dist), CAMERA.width, CAMERA.height)


def test_params_naming_folding_coefficients_are_refused_with_their_key(tiny_raw):
    assert "generate.camera.distortion" in refusal(tiny_raw, "generate.camera.distortion", [-0.6, 0.0, 0.0, 0.0, 0.0])

RATIONAL = Camera(CAMERA.K, np.array([0.12, -0.05, 0.0002, -0.0001, 0.01, 0.18, -0.04, 0.006]), CAMERA.width,
                  CAMERA.height)  # a rational_polynomial lens (8 coefficients), barrel like CAMERA's


def test_rational_polynomial_lens_is_opencvs_eight_coefficient_model():
    """distort and undistort of an 8-coefficient lens agree with cv2.projectPoints given the same 8 numbers."""
    points = rays_in_view(RATIONAL, 500, seed=2)
    ideal = project(points, RATIONAL.K, None)
    sensor = project(points, RATIONAL.K, RATIONAL.dist)
    assert np.abs(RATIONAL.distort(ideal) - sensor).max() < 1e-9
    assert np.abs(RATIONAL.undistort(sensor) - ideal).max() < 1e-6
    assert np.abs(sensor - ideal).max() > 1.0  # the lens does bend rays


def test_rational_polynomial_camera_yaml_round_trips(tmp_path):
    check_folding(RATIONAL.K, RATIONAL.dist, RATIONAL.width, RATIONAL.height)
    write_camera_yaml(tmp_path / "camera.yaml", RATIONAL, "rational")
    assert "distortion_model: rational_polynomial" in (tmp_path / "camera.yaml").read_text()
    read = read_camera_yaml(tmp_path / "camera.yaml")
    assert np.array_equal(read.dist, RATIONAL.dist) and np.array_equal(read.K, RATIONAL.K)


# --- camera.yaml ----------------------------------------------------------------------------------------------------

# A file as ROS camera_calibration_parsers writes it (flow-style data lists; docs/references.md), our lens' numbers.
ROS_FILE = """image_width: 968
image_height: 608
camera_name: u3_3060cp
camera_matrix:
  rows: 3
  cols: 3
  data: [1023.89, 0, 487.2, 0, 1023.7, 300.9, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.0598, 0.0196, 0.00021, -0.00011, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [1023.89, 0, 487.2, 0, 0, 1023.7, 300.9, 0, 0, 0, 1, 0]
"""


def test_camera_yaml_round_trips_exactly(tmp_path):
    K = CAMERA.K + np.array([[0.123456789012, 0, 0.5], [0, -0.1, 1 / 3], [0, 0, 0]])
    camera = Camera(K, CAMERA.dist * (1 + 1e-9), CAMERA.width, CAMERA.height)
    write_camera_yaml(tmp_path / "camera.yaml", camera, "u3_3060cp")
    read = read_camera_yaml(tmp_path / "camera.yaml")
    assert np.array_equal(read.K, camera.K) and np.array_equal(read.dist, camera.dist)
    assert (read.width, read.height) == (camera.width, camera.height)


def test_camera_yaml_reads_the_ros_layout(tmp_path):
    path = tmp_path / "camera.yaml"
    path.write_text(ROS_FILE)
    camera = read_camera_yaml(path)
    assert camera.K[0, 0] == 1023.89 and camera.K[1, 2] == 300.9 and camera.dist[2] == 0.00021
    assert (camera.width, camera.height) == (968, 608)


def test_written_camera_yaml_has_the_ros_layout(tmp_path):
    """Key for key and shape for shape what camera_calibration_parsers writes (docs/references.md)."""
    import yaml

    write_camera_yaml(tmp_path / "camera.yaml", CAMERA, "u3_3060cp")
    ours, ros = yaml.safe_load((tmp_path / "camera.yaml").read_text()), yaml.safe_load(ROS_FILE)
    assert list(ours) == list(ros)
    for key, value in ros.items():
        if isinstance(value, dict):
            assert (ours[key]["rows"], ours[key]["cols"], len(ours[key]["data"])) == (
                value["rows"], value["cols"], len(value["data"]))
    assert ours["rectification_matrix"] == ros["rectification_matrix"]


def edited(text: str, old: str, new: str) -> str:
    assert old in text
    return text.replace(old, new, 1)


BAD_FILES = [  # (what is wrong, the file's text, the field the error names)
    ("zero focal length", edited(ROS_FILE, "data: [1023.89, 0, 487.2, 0, 1023.7", "data: [0.0, 0, 487.2, 0, 1023.7"),
     "camera_matrix"),
    ("negative focal length", edited(ROS_FILE, "0, 1023.7, 300.9, 0, 0, 1]", "0, -1023.7, 300.9, 0, 0, 1]"),
     "camera_matrix"),
    ("NaN in K", edited(ROS_FILE, "487.2, 0, 1023.7", ".nan, 0, 1023.7"), "camera_matrix"),
    ("inf in dist", edited(ROS_FILE, "-0.0598, 0.0196", "-0.0598, .inf"), "distortion_coefficients"),
    ("a word in dist", edited(ROS_FILE, "-0.0598, 0.0196", "-0.0598, barrel"), "distortion_coefficients"),
    ("rational model with 5 coefficients", edited(ROS_FILE, "plumb_bob", "rational_polynomial"),
     "distortion_coefficients"),
    ("fisheye model", edited(ROS_FILE, "plumb_bob", "equidistant"), "distortion_model"),
    ("four coefficients", edited(edited(ROS_FILE, "cols: 5", "cols: 4"), ", -0.00011, 0]", ", -0.00011]"),
     "distortion_coefficients"),
    ("eight coefficients", edited(edited(ROS_FILE, "cols: 5", "cols: 8"), "-0.00011, 0]", "-0.00011, 0, 0, 0, 0]"),
     "distortion_coefficients"),
    ("data shorter than rows x cols", edited(ROS_FILE, ", -0.00011, 0]", ", -0.00011]"), "distortion_coefficients"),
    ("K of 2 x 3", edited(ROS_FILE, "rows: 3\n  cols: 3\n  data: [1023.89", "rows: 2\n  cols: 3\n  data: [1023.89"),
     "camera_matrix"),
    ("folding distortion", edited(ROS_FILE, "-0.0598, 0.0196", "-0.6, 0.0"), "distortion_coefficients"),
    ("zero width", edited(ROS_FILE, "image_width: 968", "image_width: 0"), "image_width"),
    ("fractional height", edited(ROS_FILE, "image_height: 608", "image_height: 608.5"), "image_height"),
    ("missing width", edited(ROS_FILE, "image_width: 968\n", ""), "image_width"),
    ("missing K", ROS_FILE.split("camera_matrix")[0] + "distortion_model" + ROS_FILE.split("distortion_model")[1],
     "camera_matrix"),
    ("missing model", edited(ROS_FILE, "distortion_model: plumb_bob\n", ""), "distortion_model"),
    ("missing coefficients", ROS_FILE.split("distortion_coefficients")[0] + "rectification_matrix"
     + ROS_FILE.split("rectification_matrix")[1], "distortion_coefficients"),
    ("not a mapping", "- 968\n- 608\n", "mapping"),
    ("not YAML", "image_width: [968\n", "YAML"),
]


@pytest.mark.parametrize("what, text, field", BAD_FILES, ids=[case[0] for case in BAD_FILES])
def test_bad_camera_yaml_is_refused_naming_file_and_field(tmp_path, what, text, field):
    path = tmp_path / "camera.yaml"
    path.write_text(text)
    with pytest.raises(CameraFileError) as info:
        read_camera_yaml(path)
    assert str(path) in str(info.value) and field in str(info.value)
    assert isinstance(info.value, ValueError)


def test_missing_camera_yaml_is_refused_naming_the_file(tmp_path):
    with pytest.raises(CameraFileError, match="camera.yaml"):
        read_camera_yaml(tmp_path / "camera.yaml")
