"""Properties of the rendered world a reader should check before trusting later stages."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pandas as pd


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
            "scene": scene, "targets": "+".join(meta["targets"]),
            "target_area_px": int((mask > 0).sum()),
            "rms_contrast": float(pixels.std() / pixels.mean()) if pixels.size else np.nan,
            "keypoints_raw": len(sift.detect(image, mask)),
            "keypoints_clahe": len(sift.detect(clahe.apply(image), mask)),
        })
    return pd.DataFrame(rows)


def folder_size_bytes(root: Path) -> int:
    """Total size of the files below ``root``."""
    return sum(p.stat().st_size for p in Path(root).rglob("*") if p.is_file())
