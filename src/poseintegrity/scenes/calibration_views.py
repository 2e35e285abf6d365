"""The calibration session before the robot's data: a ChArUco board held in front of the camera in many poses,
rendered through the true lens and sensor like every dataset image, then calibrated
(:func:`poseintegrity.calibration.calibrate`). The pipeline uses that estimate, never the renderer's
camera: its errors (focal length, principal point, distortion) are the calibration errors a real lab lives with.

Poses are drawn per view (``keyed_rng(seed, "calibration", i)``) so that the board covers the image, centre to
corners: its centre on a uniformly drawn pixel, at a distance drawn from ``distance_mm`` along that pixel's ray,
tilted by up to ``max_tilt_deg`` about a random axis of its plane and turned by up to ROLL_DEG about its normal.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.atomic_write import staged
from poseintegrity.boards import Charuco
from poseintegrity.calibration import Calibration, calibrate
from poseintegrity.lens import Camera, write_camera_yaml
from poseintegrity.params.generate import GenerateParams
from poseintegrity.poses import pose_matrix
from poseintegrity.scenes import mesh, optics, renderer
from poseintegrity.scenes.camera import true_camera
from poseintegrity.scenes.foam import ReliefVolume
from poseintegrity.scenes.printed_boards import measured_scale, print_errors
from poseintegrity.scenes.textures import build_atlas, to_u8
from poseintegrity.seeding import keyed_rng

ROLL_DEG = 20.0  # a hand or a stand turns the board about its normal this much either way
CENTRE_MARGIN = 0.1  # the board's centre is drawn inside the image, this share of a side from its edges
PX_PER_MM = 8.0  # resolution of the printed board's texture
FLAT = ReliefVolume(np.zeros((8, 8, 8), np.float32), 1.0, 1.0, 0.0, 1.0)  # the board is printed paper, no foam


@dataclass(frozen=True)
class CalibrationSession:
    """The views of one world's calibration: images (n, h, w) uint8, their exact T_cam_board (n, 4, 4, mm), and the
    estimate (:class:`~poseintegrity.calibration.Calibration`)."""

    images: list[np.ndarray]
    T_cam_board: list[np.ndarray]
    calibration: Calibration


def charuco_spec(params: GenerateParams, measured: bool = True) -> Charuco:
    """The calibration board: as the lab measured it with calipers (``printed_boards.caliper_std_mm``; what the
    calibration uses), or as drawn (``measured`` False: what is printed, before the printer's scale)."""
    board = params.calibration.board
    drawing = Charuco(board.dictionary, board.squares_x, board.squares_y, board.square_mm, board.marker_mm)
    return drawing if not measured else Charuco(board.dictionary, board.squares_x, board.squares_y, board.square_mm,
                                                board.marker_mm, scale=measured_scale(params, "charuco", drawing))


@lru_cache(maxsize=2)
def _board_geometry(spec: Charuco, lights: tuple[float, float, float, float], scale: tuple[float, float],
                    sag_mm: float) -> renderer.SceneGeometry:
    """The printed board as a textured plane in its own frame (x right, y down, facing -z), gray paper white
    (0.85) and black ink (0.06) as the ArUco board of the scenes, printed at ``scale`` and bowed by ``sag_mm``
    (:func:`~.mesh.printed_sheet`)."""
    width_mm, height_mm = spec.size_mm
    printed = spec.cv_board().generateImage((round(width_mm * PX_PER_MM), round(height_mm * PX_PER_MM)), marginSize=0)
    texture = to_u8(0.06 + 0.79 * printed.astype(np.float32) / 255)
    # the renderer puts the first and last texel centres on the plane's edges (texture coordinates 0 and 1): texel c
    # of the print lies at (c + 1/2) / PX_PER_MM, so the plane spans the texel centres, (n - 1) / PX_PER_MM, about the
    # board's centre. A plane of the print's full size stretched the board by n / (n - 1), more along y (960 texels)
    # than x (1440): the calibration then found fy / fx = 1.0003 for a camera of square pixels
    n_y, n_x = texture.shape
    plane = mesh.plane((n_x - 1) / PX_PER_MM, (n_y - 1) / PX_PER_MM, 18, 12, "charuco",
                       material=mesh.Material(0.02, 10.0))
    board = plane.transformed(pose_matrix(np.diag([1.0, -1.0, -1.0]), [width_mm / 2, height_mm / 2, 0.0]))
    board = mesh.printed_sheet(board, np.array([width_mm / 2, height_mm / 2]), (n_x - 1) / PX_PER_MM / 2, scale, sag_mm)
    return renderer.SceneGeometry.from_meshes([("charuco", board)], build_atlas({"charuco": texture}),
                                              np.array([0.3, -0.5, -1.0]), lights, FLAT)


def view_pose(camera: Camera, spec: Charuco, distance_mm: tuple[float, float], max_tilt_deg: float,
              rng: np.random.Generator) -> np.ndarray:
    """T_cam_board (4, 4, mm) of one calibration view (module docstring)."""
    u = rng.uniform(CENTRE_MARGIN, 1 - CENTRE_MARGIN) * (camera.width - 1)
    v = rng.uniform(CENTRE_MARGIN, 1 - CENTRE_MARGIN) * (camera.height - 1)
    ray = np.linalg.solve(camera.K, [u, v, 1.0])
    centre = rng.uniform(*distance_mm) * ray / np.linalg.norm(ray)
    axis_angle = rng.uniform(0.0, 2 * np.pi)
    tilt = Rotation.from_rotvec(np.radians(rng.uniform(0.0, max_tilt_deg)) * np.array([np.cos(axis_angle),
                                                                                      np.sin(axis_angle), 0.0]))
    R = (tilt * Rotation.from_euler("z", rng.uniform(-ROLL_DEG, ROLL_DEG), degrees=True)).as_matrix()
    width_mm, height_mm = spec.size_mm
    return pose_matrix(R, centre - R @ np.array([width_mm / 2, height_mm / 2, 0.0]))


def render_view(params: GenerateParams, T_cam_board: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One calibration image (h, w) uint8: the board at T_cam_board through the true lens (focused mid-range) and
    sensor, as a dataset image is made (scenes/shots.py)."""
    camera = true_camera(params.camera)
    K_canvas, width, height = camera.canvas
    scale, sag_mm = print_errors(params, "charuco", params.printed_boards.calibration_sag_std_mm)
    frame = renderer.render(_board_geometry(charuco_spec(params, measured=False), params.lights.intensities(), scale,
                                            sag_mm),
                            K_canvas, width, height, T_cam_board)  # the geometry's world frame is the board's
    focus_mm = float(np.mean(params.calibration.distance_mm))
    irradiance = optics.lens(frame.radiance, frame.depth_mm, focus_mm, params.sensor.blur_sigma_px, params.camera)
    sensor = cv2.remap(irradiance, *camera.sensor_maps, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return renderer.expose(sensor, params.sensor, rng)


def calibration_session(params: GenerateParams, key: str) -> CalibrationSession:
    """Render ``params.calibration.n_views`` views and calibrate the camera from them; ``key``: the params key of
    the world's calibration section, named by a :class:`~poseintegrity.calibration.CalibrationError`."""
    camera, spec, session = true_camera(params.camera), charuco_spec(params), params.calibration
    poses = [view_pose(camera, spec, session.distance_mm, session.max_tilt_deg,
                       keyed_rng(params.seed, "calibration", i)) for i in range(session.n_views)]
    images = [render_view(params, T, keyed_rng(params.seed, "calibration noise", i)) for i, T in enumerate(poses)]
    return CalibrationSession(images, poses, calibrate(images, spec, session.max_rms_px, key))


def write_calibration(folder: Path, session: CalibrationSession, params: GenerateParams, camera_name: str,
                      png_flags: list[int]) -> None:
    """A world's calibration session in ``folder``: the views (``views/view_NN.png``), the estimate
    (``camera.yaml``) and ``report.json`` (the fit, the board, and the true camera beside the estimate)."""
    with staged(folder) as tmp:
        (tmp / "views").mkdir()
        for i, image in enumerate(session.images):
            ok, encoded = cv2.imencode(".png", image, png_flags)
            (tmp / "views" / f"view_{i:02d}.png").write_bytes(encoded.tobytes())
        calibration, truth = session.calibration, true_camera(params.camera)
        write_camera_yaml(tmp / "camera.yaml", calibration.camera, camera_name)
        report = {"rms_px": calibration.rms_px, "per_view_rms_px": list(calibration.per_view_rms_px),
                  "views_used": list(calibration.views_used), "n_corners": list(calibration.n_corners),
                  "board": params.calibration.board.model_dump(),
                  "T_cam_board": [T.tolist() for T in session.T_cam_board],
                  "estimate": {"K": calibration.camera.K.tolist(), "dist": calibration.camera.dist.tolist()},
                  "true": {"K": truth.K.tolist(), "dist": truth.dist.tolist()}}
        (tmp / "report.json").write_text(json.dumps(report, indent=1))
