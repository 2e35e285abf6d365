"""Reader of the rendered datasets written by stage 01 (``data_dir/datasets/``).

Layout: ``index.parquet`` (one row per dataset) and per dataset a folder with ``meta.json`` (camera K, ArUco
board, model images/masks/poses) and ``frames.parquet`` (one row per image with its exact poses).
Image paths in the tables are relative to the dataset folder (or, failing that, to ``data_dir``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from poseintegrity.localization.features import ImageReadError


@dataclass(frozen=True)
class Dataset:
    """One rendered dataset.

    folder : its folder; meta : ``meta.json``; frames : ``frames.parquet`` (sorted by stop, image)
    K : (3, 3) float, pixels
    """

    data_dir: Path
    folder: Path
    meta: dict[str, Any]
    frames: pd.DataFrame
    K: np.ndarray

    @property
    def name(self) -> str:
        return str(self.meta["dataset"])

    def path(self, relative: str) -> Path:
        """Absolute path of a file named in meta/frames (dataset folder first, then data_dir)."""
        in_folder = self.folder / relative
        return in_folder if in_folder.exists() or not (self.data_dir / relative).exists() else self.data_dir / relative

    def model_T_cam_board(self) -> tuple[np.ndarray, np.ndarray]:
        """Exact board -> camera poses (4, 4, mm) of the two model images."""
        first, second = (np.asarray(T, dtype=np.float64).reshape(4, 4) for T in self.meta["model"]["T_cam_board"])
        return first, second

    def check_images(self) -> None:
        """Stop early, naming the file, if any model image, mask or frame image is missing."""
        relatives = [*self.meta["model"]["images"], *self.meta["model"]["masks"], *self.frames["file"]]
        for relative in relatives:
            if not self.path(relative).is_file():
                raise ImageReadError(f"dataset {self.name}: image file {self.path(relative)} is missing")


def load_index(data_dir: str | Path) -> pd.DataFrame:
    """``data_dir/datasets/index.parquet``: one row per dataset."""
    path = Path(data_dir) / "datasets" / "index.parquet"
    if not path.is_file():
        raise FileNotFoundError(f"dataset index {path} is missing: run stage 01 (generate datasets) first")
    return pd.read_parquet(path)


def load_dataset(data_dir: str | Path, folder: str | Path) -> Dataset:
    """A dataset from its folder (relative to ``data_dir``, as in the index's ``path`` column)."""
    data_dir = Path(data_dir)
    folder = data_dir / folder
    meta = json.loads((folder / "meta.json").read_text())
    frames = pd.read_parquet(folder / "frames.parquet").sort_values(["stop", "image"], ignore_index=True)
    return Dataset(data_dir, folder, meta, frames, np.asarray(meta["K"], dtype=np.float64))
