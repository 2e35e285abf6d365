"""Properties of the rendered world a reader should check before trusting later stages."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from poseintegrity.scenes.camera import true_camera


def target_appearance(root: Path, index: pd.DataFrame) -> pd.DataFrame:
    """Per scene, on model image 0: the target's RMS contrast (std / mean of its pixels) and the number of SIFT
    keypoints on the target without and with CLAHE (clip limit 2, 8 x 8 tiles, as used in stage 02).

    Bone-like targets should be low in contrast, so that CLAHE matters (Windsor et al. IV-C).
    """
    sift = cv2.SIFT_create()
    clahe = cv2.createCLAHE(clipLimit=2.0, tileGridSize=(8, 8))
    rows = []
    for scene, group in index.groupby("scene", sort=True):
        folder = Path(root) / group["dataset"].iloc[0]
        meta = json.loads((folder / "meta.json").read_text())
        image = cv2.imread(str(folder / meta["model"]["images"][0]), cv2.IMREAD_GRAYSCALE)
        mask = cv2.imread(str(folder / meta["model"]["masks"][0]), cv2.IMREAD_GRAYSCALE)
        pixels = image[mask > 0].astype(float)
        rows.append({
            "scene": scene, "targets": "+".join(meta.get("targets", [])),  # none named in recorded meta.json
            "target_area_px": int((mask > 0).sum()),
            "rms_contrast": float(pixels.std() / pixels.mean()) if pixels.size else np.nan,
            "keypoints_raw": len(sift.detect(image, mask)),
            "keypoints_clahe": len(sift.detect(clahe.apply(image), mask)),
        })
    return pd.DataFrame(rows)


def calibration_errors(worlds: dict) -> pd.DataFrame:
    """Per world (``dataset.generate``'s plans): the calibration's RMS, views used, and the estimate's errors against
    the true camera: focal lengths (%), principal point (px), and how far the estimated lens puts the image corners'
    and centre's rays (undistorted pixels) from where the true lens does (px, the largest)."""
    rows = {}
    for name, w in worlds.items():
        estimate, truth = w.calibration.calibration.camera, true_camera(w.params.camera)
        probe = np.array([[0.0, 0.0], [truth.width - 1, 0.0], [0.0, truth.height - 1],
                          [truth.width - 1, truth.height - 1], [(truth.width - 1) / 2, (truth.height - 1) / 2]])
        rows[name] = {
            "rms_px": w.calibration.calibration.rms_px, "n_views_used": len(w.calibration.calibration.views_used),
            "fx_error_pct": 100 * (estimate.K[0, 0] / truth.K[0, 0] - 1),
            "fy_error_pct": 100 * (estimate.K[1, 1] / truth.K[1, 1] - 1),
            "principal_point_error_px": float(np.hypot(*(estimate.K[:2, 2] - truth.K[:2, 2]))),
            "ray_error_px_max": float(np.max(np.linalg.norm(
                estimate.undistort(probe) - estimate.K[:2, 2] - (truth.undistort(probe) - truth.K[:2, 2]), axis=1))),
        }
    return pd.DataFrame(rows).T.rename_axis("world")


def folder_size_bytes(root: Path) -> int:
    """Total size of the files below ``root``."""
    return sum(p.stat().st_size for p in Path(root).rglob("*") if p.is_file())


def board_layout(worlds: dict) -> pd.DataFrame:
    """Per world, scene, session and board (``dataset.generate``'s plans): where each ground-truth board stands.
    Columns: ``board_index`` (0, or 1 for a second board), ``square_mm``, ``first_id``, ``trajectories`` (the
    trajectories it is the ground truth of, by index in ``arcs.azimuths_deg`` / ``lines.offsets_deg``),
    ``lever_arm_mm``, the distance from the board origin (where E_t is measured, IV-C) to the aim point the arcs turn
    about (the target); ``in_view``, the share of the board inside the image at its worst commanded pose (standing
    boards; NaN when it lies flat); ``predicted_sigma_t_mm``, its pose's predicted RMS error at its origin at the
    worst stop it serves (planned boards, :mod:`.board_plan`; else NaN); ``scale_x``, ``scale_y``, the printed size
    over the drawn size as the lab measured it."""
    rows = []
    for name, w in worlds.items():
        for (index, session), scene in w.scenes.items():
            for k, board in enumerate(scene.boards):
                rows.append({"world": name, "scene": scene.name, "session": session, "board_index": k,
                             "placement": w.params.board.placement, "board": w.params.board.type,
                             "square_mm": getattr(board.drawing, "square_mm", np.nan),
                             "first_id": board.drawing.first_id,
                             "trajectories": [t for t, b in enumerate(scene.board_of) if b == k],
                             "lever_arm_mm": float(np.linalg.norm(board.T_world_board[:3, 3] - scene.aim)),
                             "in_view": board.placement.in_view if board.placement is not None else np.nan,
                             "predicted_sigma_t_mm": board.sigma_t_mm,
                             "scale_x": board.board.scale[0], "scale_y": board.board.scale[1]})
    return pd.DataFrame(rows)
