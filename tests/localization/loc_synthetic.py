"""Tiny synthetic scenes and datasets for the localization tests, made independently of the renderer.

The scene is the board plane z = 0 (board frame of ``GridBoard.getObjPoints()``, mm): an ArUco GridBoard at the
origin and a richly textured target rectangle beside it. Images are exact perspective views of that plane,
``cv2.warpPerspective`` of a canvas by the homography K [r1 r2 t] A (A: canvas pixel -> board mm), so every
pose is known exactly. :func:`write_dataset` writes the stage-01 format (meta.json, camera.yaml, frames.parquet, PNGs).
"""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from poseintegrity.lens import Camera, write_camera_yaml
from poseintegrity.params.extract import GroundTruthParams

BOARD = dict(dictionary="DICT_4X4_50", markers_x=3, markers_y=2, marker_length_mm=20.0, separation_mm=5.0, first_id=0)
CANVAS_MM = (-20.0, -30.0, 180.0, 80.0)  # x_min, y_min, x_max, y_max of the scene plane
TARGET_MM = (85.0, -20.0, 165.0, 65.0)  # textured target rectangle
PX_PER_MM = 4
IMAGE_SIZE = (640, 400)  # width, height
K = np.array([[600.0, 0.0, 320.0], [0.0, 600.0, 200.0], [0.0, 0.0, 1.0]])
CENTRE_MM = np.array([80.0, 25.0, 0.0])  # the camera looks at this point of the plane
DISTANCE_MM = 260.0
CAMERA = Camera(K, np.zeros(5), *IMAGE_SIZE)  # an exact pinhole camera: these images have no lens distortion
# The board checks for these images: a 3 x 2 board of 20 mm markers at 260 mm and 600 px focal length is predicted
# to 0.17-0.36 mm / 0.37-0.70 deg, beyond params.yaml's 0.15 (set for the rendered lab's ChArUco board at 1 080 px)
CHECKS = GroundTruthParams(consistency_factor=4.0, noise_floor_px=0.05, min_markers=3, min_corners=6,
                           max_sigma_t_mm=0.5, max_sigma_r_deg=1.0)


def texture(rng: np.random.Generator, shape: tuple[int, int]) -> np.ndarray:
    """(h, w) uint8 blob-rich texture: smooth random fields at several scales plus random discs."""
    h, w = shape
    field = np.zeros(shape, np.float32)
    for cell in (4, 8, 16, 32):
        coarse = rng.random((h // cell + 2, w // cell + 2)).astype(np.float32)
        field += cv2.resize(coarse, (w, h), interpolation=cv2.INTER_CUBIC)
    field = (field - field.min()) / np.ptp(field) * 255
    for _ in range(h * w // 400):
        centre = (int(rng.integers(0, w)), int(rng.integers(0, h)))
        cv2.circle(field, centre, int(rng.integers(2, 9)), float(rng.integers(0, 256)), -1)
    return np.clip(field, 0, 255).astype(np.uint8)


SECOND_BOARD = BOARD | dict(first_id=6)  # a handover board: the same layout, ids of its own
SECOND_AT_MM = (98.0, -28.0)  # where its origin lies in the plane (over the target's top edge)


def make_board(board: dict = BOARD) -> cv2.aruco.GridBoard:
    dictionary = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, board["dictionary"]))
    ids = np.arange(board["first_id"], board["first_id"] + board["markers_x"] * board["markers_y"])
    return cv2.aruco.GridBoard(
        (board["markers_x"], board["markers_y"]), board["marker_length_mm"], board["separation_mm"], dictionary, ids
    )


def canvas(rng: np.random.Generator, with_board: bool = True, second_board: bool = False
           ) -> tuple[np.ndarray, np.ndarray]:
    """The scene plane as (image, target mask), both (h, w) uint8 at PX_PER_MM (X = x_min + (u + 0.5) / s); with
    ``second_board`` SECOND_BOARD at SECOND_AT_MM too (drawn over the target)."""
    x_min, y_min, x_max, y_max = CANVAS_MM
    w, h = int((x_max - x_min) * PX_PER_MM), int((y_max - y_min) * PX_PER_MM)
    image = np.clip(rng.normal(200, 4, (h, w)), 0, 255).astype(np.uint8)  # faint paper texture
    mask = np.zeros((h, w), np.uint8)

    def draw(board: dict, at_mm: tuple[float, float]) -> None:
        grid = make_board(board)
        width_mm, height_mm, _ = grid.getRightBottomCorner()
        margin = 8
        size = (int(width_mm * PX_PER_MM) + 2 * margin, int(height_mm * PX_PER_MM) + 2 * margin)
        board_image = grid.generateImage(size, marginSize=margin)  # board pixel = margin + X * s
        u0, v0 = int((at_mm[0] - x_min) * PX_PER_MM) - margin, int((at_mm[1] - y_min) * PX_PER_MM) - margin
        image[v0 : v0 + size[1], u0 : u0 + size[0]] = board_image

    if with_board:
        draw(BOARD, (0.0, 0.0))
    tx0, ty0, tx1, ty1 = ((np.array(TARGET_MM) - [x_min, y_min, x_min, y_min]) * PX_PER_MM).astype(int)
    image[ty0:ty1, tx0:tx1] = texture(rng, (ty1 - ty0, tx1 - tx0))
    mask[ty0:ty1, tx0:tx1] = 255
    if second_board:
        draw(SECOND_BOARD, SECOND_AT_MM)
    return image, mask


def render(plane: np.ndarray, T_cam_board: np.ndarray, interpolation: int = cv2.INTER_LINEAR,
           K: np.ndarray = K, size: tuple[int, int] = IMAGE_SIZE) -> np.ndarray:
    """Exact perspective image (h, w) of the plane z = 0 seen from T_cam_board (board -> camera, mm) by a pinhole
    camera K of ``size`` (width, height)."""
    x_min, y_min = CANVAS_MM[:2]
    # canvas pixel centre u -> board X = x_min + (u + 0.5) / s (pixel u covers [u, u + 1) / s beyond x_min)
    A = np.array([[1 / PX_PER_MM, 0, x_min + 0.5 / PX_PER_MM], [0, 1 / PX_PER_MM, y_min + 0.5 / PX_PER_MM], [0, 0, 1]])
    H = K @ T_cam_board[:3, [0, 1, 3]] @ A
    return cv2.warpPerspective(plane, H, size, flags=interpolation, borderValue=128)


def look_at(centre_board: np.ndarray, R_board_cam: np.ndarray) -> np.ndarray:
    """T_cam_board of a camera with orientation R_board_cam looking at ``centre_board`` from DISTANCE_MM."""
    c = centre_board - DISTANCE_MM * R_board_cam[:, 2]  # camera centre: the optical axis passes the centre
    T = np.eye(4)
    T[:3, :3] = R_board_cam.T
    T[:3, 3] = -R_board_cam.T @ c
    return T


def arc_pose(theta_deg: float, azimuth_deg: float) -> np.ndarray:
    """Camera on an arc about CENTRE_MM: the fronto-parallel view rotated by theta about an in-plane axis."""
    axis = Rotation.from_euler("z", azimuth_deg, degrees=True).apply([0.0, 1.0, 0.0])
    R = Rotation.from_rotvec(np.radians(theta_deg) * axis).as_matrix()
    return look_at(CENTRE_MM, R)


def shifted(T_cam_board: np.ndarray, offset_cam_mm: np.ndarray) -> np.ndarray:
    """The same camera moved by ``offset_cam_mm`` (3,) expressed in its own frame."""
    T = T_cam_board.copy()
    T[:3, 3] -= offset_cam_mm
    return T


T_BASE_BOARD = np.array([[0.0, -1.0, 0.0, 350.0], [1.0, 0.0, 0.0, -120.0], [0.0, 0.0, 1.0, 40.0],
                         [0.0, 0.0, 0.0, 1.0]])  # where the board stands in the (exact) robot's base frame, mm


def write_dataset(
    data_dir: Path, name: str, rng: np.random.Generator, trajectory: str = "arc", azimuth_deg: float = 0.0,
    stops: tuple[float, ...] = (10.0, 25.0, 40.0, 55.0), images_per_stop: int = 2, noise: float = 2.0,
    second_board: bool = False, hidden_from_stop: int | None = None,
) -> dict:
    """Write one dataset in the stage-01 format under data_dir/datasets/<name>; returns its index row.

    ``stops`` are theta (deg) for arcs and x (mm, backwards along the optical axis) for lines. The robot that
    carries the camera is exact: its reported poses (T_base_cam_robot) put the board at T_BASE_BOARD. With
    ``second_board``, SECOND_BOARD stands in the plane too (meta.json's handover_boards); from stop
    ``hidden_from_stop`` on, the dataset's own board is not in the images (a target in front of it).
    """
    folder = data_dir / "datasets" / name
    (folder / "images").mkdir(parents=True, exist_ok=True)
    (folder / "model").mkdir(exist_ok=True)
    state = rng.bit_generator.state
    plane, target = canvas(rng, second_board=second_board)
    if hidden_from_stop is not None:  # the same plane (the same draws) without the own board
        after = rng.bit_generator.state
        rng.bit_generator.state = state
        hidden, _ = canvas(rng, with_board=False, second_board=second_board)
        rng.bit_generator.state = after
    T_model = arc_pose(0.0, azimuth_deg)
    model_poses = [T_model, shifted(T_model, np.array([20.0, 0.0, 0.0]))]  # IV-D: 2 cm along camera x
    model = dict(images=[], masks=[], T_cam1_cam0=(model_poses[1] @ np.linalg.inv(model_poses[0])).tolist(),
                 exact_T_cam_board=[T.tolist() for T in model_poses],
                 T_base_cam_robot=[(T_BASE_BOARD @ np.linalg.inv(T)).tolist() for T in model_poses])
    for index, T in enumerate(model_poses):
        cv2.imwrite(str(folder / f"model/image_{index}.png"), render(plane, T))
        cv2.imwrite(str(folder / f"model/mask_{index}.png"), render(target, T, cv2.INTER_NEAREST))
        model["images"].append(f"model/image_{index}.png")
        model["masks"].append(f"model/mask_{index}.png")
    rows = []
    for stop, position in enumerate(stops):
        if trajectory == "arc":
            T, theta_deg, x_mm = arc_pose(position, azimuth_deg), position, 0.0
        else:
            T, theta_deg, x_mm = shifted(T_model, np.array([0.0, 0.0, -position])), 0.0, position
        seen = hidden if hidden_from_stop is not None and stop >= hidden_from_stop else plane
        for image in range(images_per_stop):
            picture = render(seen, T).astype(np.float64) + rng.normal(0, noise, IMAGE_SIZE[::-1])
            file = f"images/s{stop:02d}_i{image:02d}.png"
            cv2.imwrite(str(folder / file), np.clip(picture, 0, 255).astype(np.uint8))
            rows.append(dict(dataset=name, stop=stop, image=image, theta_deg=theta_deg, x_mm=x_mm, file=file,
                             T_cam_board=T.ravel().tolist(), T_cam_target=T.ravel().tolist(),
                             T_base_cam_robot=(T_BASE_BOARD @ np.linalg.inv(T)).ravel().tolist()))
    pd.DataFrame(rows).to_parquet(folder / "frames.parquet")
    meta = dict(
        dataset=name, world="main", scene="synthetic", targets=["texture"], trajectory=trajectory,
        azimuth_deg=azimuth_deg, offset_deg=0.0, n_stops=len(stops), images_per_stop=images_per_stop, board=BOARD,
        handover_boards=[SECOND_BOARD] if second_board else [], model=model,
    )
    (folder / "meta.json").write_text(json.dumps(meta))
    write_camera_yaml(folder / "camera.yaml", CAMERA, "synthetic")
    return dict(dataset=name, world="main", scene="synthetic", trajectory=trajectory, azimuth_deg=azimuth_deg,
                offset_deg=0.0, n_frames=len(rows), path=f"datasets/{name}")


def write_index(data_dir: Path, rows: list[dict]) -> None:
    pd.DataFrame(rows).to_parquet(data_dir / "datasets" / "index.parquet")
