"""Recorded dataset folders written the way a user's own script would: plain ``cv2.imwrite``, ``yaml.safe_dump`` and
``csv``, never the project's exporter or camera writer, so that the end-to-end tests do not share its assumptions.

The scene is :mod:`loc_synthetic`'s (the board plane z = 0 with an ArUco GridBoard and a textured target beside it,
seen through exact homographies): a camera of any size looks at it along an arc (theta about an in-plane axis, up
to 180 deg: past 90 deg it sees the plane from behind, as through a transparency) or a straight line backwards
along its optical axis. Images are stored as asked: mono or BGR colour (the channels scaled apart, so that a reader
taking one channel for gray would see other pixels), 8 or 16 bit (v * 257), PNG, JPEG or TIFF.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
import yaml

import loc_synthetic as scene


@dataclass(frozen=True)
class Folder:
    """What one dataset folder holds. ``stops``: theta (deg, arcs) or x (mm, lines) per stop; ``world`` None leaves
    the field out (the format's default); ``positions`` False leaves theta_deg / x_mm out of stops.csv (computed from
    the poses); ``suffix`` of the stop images (the model pair is PNG); the model pair's relative pose is left to be
computed from its poses (model.csv's T_cam_ref)."""

    name: str
    trajectory: str = "arc"
    ground_truth: str = "poses"
    stops: tuple[float, ...] = (5.0, 15.0, 25.0, 35.0)
    images_per_stop: int = 1
    size: tuple[int, int] = (320, 200)
    colour: bool = False
    bits: int = 8
    suffix: str = ".png"
    world: str | None = None
    azimuth_deg: float = 0.0
    positions: bool = True
    baseline_mm: float = 20.0  # the model pair's, along camera 0's x axis
    seed: int = 0
    extra: dict = field(default_factory=dict)  # more dataset.yaml fields
    robot: bool = False  # T_base_cam columns: the camera poses an (exact) robot logged, the reference at T_BASE_REF


T_BASE_REF = np.array([[1.0, 0.0, 0.0, -300.0], [0.0, 0.0, -1.0, 80.0], [0.0, 1.0, 0.0, 250.0], [0.0, 0.0, 0.0, 1.0]])


def _K(size: tuple[int, int]) -> np.ndarray:
    f = 600.0 * size[0] / 640.0  # loc_synthetic's 600 px at 640 px wide: the same view at any size
    return np.array([[f, 0.0, size[0] / 2.0], [0.0, f, size[1] / 2.0], [0.0, 0.0, 1.0]])


def _pose_cell(T: np.ndarray) -> str:
    return " ".join(f"{value:.12g}" for value in T.ravel())


def _store(path: Path, gray: np.ndarray, spec: Folder) -> None:
    image = gray
    if spec.colour:  # B, G, R unequal: only OpenCV's weights give the gray back (within rounding)
        image = np.dstack([gray * 0.9, gray, np.minimum(gray * 1.05, 255)]).astype(np.uint8)
    if spec.bits == 16:
        image = image.astype(np.uint16) * 257
    path.parent.mkdir(parents=True, exist_ok=True)
    assert cv2.imwrite(str(path), image), path


def _write_csv(path: Path, header: list[str], rows: list[list]) -> None:
    with open(path, "w", newline="") as table:
        writer = csv.writer(table)
        writer.writerow(header)
        writer.writerows(rows)


def write_folder(root: Path, spec: Folder) -> Path:
    """The recorded dataset folder ``root / spec.name``; returns it."""
    folder = root / spec.name
    folder.mkdir(parents=True)
    rng = np.random.default_rng(spec.seed)
    K = _K(spec.size)
    plane, target = scene.canvas(rng, with_board=spec.ground_truth == "board")
    T_model = scene.arc_pose(0.0, spec.azimuth_deg)
    model_poses = [T_model, scene.shifted(T_model, np.array([spec.baseline_mm, 0.0, 0.0]))]  # along camera x (IV-D)

    def picture(T: np.ndarray) -> np.ndarray:
        clean = scene.render(plane, T, K=K, size=spec.size).astype(np.float64)
        return np.clip(clean + rng.normal(0.0, 2.0, clean.shape), 0, 255).astype(np.uint8)

    def robot(T: np.ndarray) -> list[str]:  # the robot's log: where it put the camera, in its base frame
        return [_pose_cell(T_BASE_REF @ np.linalg.inv(T))] if spec.robot else []

    model_rows = []
    for k, T in enumerate(model_poses):
        _store(folder / f"model/pair_{k}.png", picture(T), spec)
        mask = scene.render(target, T, cv2.INTER_NEAREST, K=K, size=spec.size)
        cv2.imwrite(str(folder / f"model/pair_{k}_mask.png"), mask)
        model_rows.append([f"model/pair_{k}.png", f"model/pair_{k}_mask.png", _pose_cell(T)] + robot(T))
    _write_csv(folder / "model.csv", ["file", "mask", "T_cam_ref"] + ["T_base_cam"] * spec.robot, model_rows)

    header = ["file", "stop"] + (["theta_deg" if spec.trajectory == "arc" else "x_mm"] if spec.positions else []) \
        + ["T_cam_ref"] + ["T_base_cam"] * spec.robot
    rows = []
    for stop, position in enumerate(spec.stops):
        T = scene.arc_pose(position, spec.azimuth_deg) if spec.trajectory == "arc" else \
            scene.shifted(T_model, np.array([0.0, 0.0, -position]))
        for image in range(spec.images_per_stop):
            file = f"frames/stop{stop}_{image}{spec.suffix}"
            _store(folder / file, picture(T), spec)
            rows.append([file, stop] + ([repr(float(position))] if spec.positions else []) + [_pose_cell(T)]
                        + robot(T))
    _write_csv(folder / "stops.csv", header, rows)

    settings = {"trajectory": spec.trajectory, "ground_truth": spec.ground_truth, **spec.extra}
    if spec.world is not None:
        settings["world"] = spec.world
    (folder / "dataset.yaml").write_text(yaml.safe_dump(settings))
    width, height = spec.size
    (folder / "camera.yaml").write_text(yaml.safe_dump({
        "image_width": width, "image_height": height, "camera_name": "users_camera",
        "camera_matrix": {"rows": 3, "cols": 3, "data": K.ravel().tolist()},
        "distortion_model": "plumb_bob",
        "distortion_coefficients": {"rows": 1, "cols": 5, "data": [0.0] * 5},
    }))
    if spec.ground_truth == "board":
        (folder / "board.yaml").write_text(yaml.safe_dump(dict(scene.BOARD)))
    return folder
