"""Reader of the rendered datasets written by stage 01 (``data_dir/datasets/``), checked on read.

Layout: ``index.parquet`` (one row per dataset) and per dataset a folder with ``meta.json`` (world, trajectory,
ArUco board, model images and masks, the model pair's relative pose), ``camera.yaml`` (the calibrated camera: K,
distortion, image size; :func:`poseintegrity.lens.read_camera_yaml`) and ``frames.parquet`` (one row per image with
its exact poses, a diagnostic). Image paths in the tables are relative to the dataset folder (or, failing that, to
``data_dir``).

What is checked before any work, each failure a :class:`DatasetError` naming the dataset and the file:

- ``index.parquet`` readable, with a ``dataset`` and a ``path`` column; no dataset or folder named twice; every
  folder it names exists; every dataset folder on disk is in it (a folder left out would be skipped silently);
- ``meta.json`` readable and holding what stages 02 and 05 read (:class:`Meta`): the dataset's name as in the
  index, its world and trajectory, its ground-truth source (``ground_truth``: ``board``, the default, or ``poses``
  for recorded data whose frames' poses come from an external system), the board (a dictionary OpenCV knows, its
  marker ids inside it; needed with ``board``; optional handover boards, whose ids must differ), two model images,
  masks and a rigid finite relative pose (and with ``poses`` model image 0's pose ``T_cam0_ref``);
- ``camera.yaml`` readable, every field valid (positive focal lengths, the plumb_bob model, a lens that does not
  fold the image);
- ``frames.parquet`` readable, with its columns, at least one row, one row per (stop, image) and per file, finite stop positions,
  and every image file present.

A frame's own pose is checked per frame (:func:`pose_problem`): a bad one flags that frame's rows
(status ``bad_pose``; a recorded frame without a known pose holds None instead, and is not flagged) instead of
stopping the stage, as a bad frame image does (``bad_image``, extract.py).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow
from pydantic import ValidationError

from poseintegrity.dataset_meta import DatasetError, Meta
from poseintegrity.errors import not_numbers
from poseintegrity.lens import Camera, CameraFileError, read_camera_yaml

INDEX_COLUMNS = ("dataset", "path")
FRAME_TABLE_COLUMNS = ("dataset", "stop", "image", "theta_deg", "x_mm", "file", "T_cam_board")


@dataclass(frozen=True)
class Dataset:
    """One rendered dataset, checked (module docstring).

    folder : its folder; meta : ``meta.json`` as read; frames : ``frames.parquet`` (sorted by stop, image)
    camera : the calibrated camera of ``camera.yaml`` (K, distortion, image size)
    """

    data_dir: Path
    folder: Path
    meta: dict[str, Any]
    frames: pd.DataFrame
    camera: Camera

    @property
    def K(self) -> np.ndarray:
        """(3, 3) px: the pinhole camera every undistorted pixel position belongs to."""
        return self.camera.K

    @property
    def image_size(self) -> tuple[int, int]:
        """(width, height), px, of every image of the dataset."""
        return self.camera.width, self.camera.height

    @property
    def name(self) -> str:
        return str(self.meta["dataset"])

    def path(self, relative: str) -> Path:
        """Absolute path of a file named in meta/frames (dataset folder first, then data_dir)."""
        in_folder = self.folder / relative
        return in_folder if in_folder.exists() or not (self.data_dir / relative).exists() else self.data_dir / relative

    def model_baseline(self) -> np.ndarray:
        """T_cam1_cam0 (4, 4, mm): camera 0 -> camera 1 of the model pair, as the robot reports it."""
        return np.asarray(self.meta["model"]["T_cam1_cam0"], dtype=np.float64).reshape(4, 4)

    def check_images(self) -> None:
        """:class:`DatasetError` naming the dataset and the file(s) if a model image, mask or frame image is
        missing (their content is checked when they are read: extract.py)."""
        relatives = [*self.meta["model"]["images"], *self.meta["model"]["masks"], *self.frames["file"]]
        missing = [str(self.path(relative)) for relative in relatives if not self.path(relative).is_file()]
        if missing:
            more = f" and {len(missing) - 3} more" if len(missing) > 3 else ""
            raise DatasetError(f"dataset {self.name}: image file(s) {', '.join(missing[:3])}{more} missing")


def _read_parquet(path: Path, prefix: str = "") -> pd.DataFrame:
    if not path.is_file():
        raise DatasetError(f"{prefix}{path} is missing: run stage 01 (generate datasets) first")
    try:
        return pd.read_parquet(path)
    except (OSError, ValueError, pyarrow.ArrowException) as error:
        raise DatasetError(f"{prefix}cannot read {path}: {error}") from None


def _missing_columns(table: pd.DataFrame, columns: tuple[str, ...]) -> list[str]:
    return [column for column in columns if column not in table.columns]


def load_index(data_dir: str | Path) -> pd.DataFrame:
    """``data_dir/datasets/index.parquet``: one row per dataset, checked against the folders on disk."""
    datasets_dir = Path(data_dir) / "datasets"
    path = datasets_dir / "index.parquet"
    index = _read_parquet(path)
    if missing := _missing_columns(index, INDEX_COLUMNS):
        raise DatasetError(f"{path} lacks the column(s) {missing}")
    for column in INDEX_COLUMNS:
        if repeated := sorted(set(index.loc[index[column].duplicated(), column].astype(str))):
            raise DatasetError(f"{path} names {'dataset' if column == 'dataset' else 'folder'}(s) "
                               f"{repeated} more than once")
    absent = [row.dataset for row in index.itertuples() if not (Path(data_dir) / row.path).is_dir()]
    if absent:
        raise DatasetError(f"{path} names dataset(s) {absent} whose folder is missing")
    listed = {(Path(data_dir) / folder).resolve() for folder in index["path"]}
    unlisted = sorted(folder.name for folder in datasets_dir.iterdir()
                      if folder.is_dir() and not folder.name.startswith(".") and folder.resolve() not in listed)
    if unlisted:
        raise DatasetError(f"dataset folder(s) {unlisted} in {datasets_dir} are missing from {path.name}: re-run "
                           f"stage 01, or remove the folder(s)")
    return index


def _read_meta(path: Path, name: str | None) -> dict[str, Any]:
    label = f"dataset {name}: " if name else ""
    if not path.is_file():
        raise DatasetError(f"{label}{path} is missing")
    try:
        meta = json.loads(path.read_text())
    except (OSError, ValueError) as error:
        raise DatasetError(f"{label}cannot read {path}: {error}") from None
    try:
        Meta.model_validate(meta)
    except ValidationError as error:
        lines = [f"  {'.'.join(map(str, item['loc']))}: {item['msg']}" for item in error.errors()]
        raise DatasetError(f"{label}{path} has invalid values:\n" + "\n".join(lines)) from None
    if name is not None and meta["dataset"] != name:
        raise DatasetError(f"dataset {name}: {path} names the dataset {meta['dataset']!r}, the index {name!r}")
    return meta


def _check_frames(frames: pd.DataFrame, path: Path, name: str) -> None:
    if missing := _missing_columns(frames, FRAME_TABLE_COLUMNS):
        raise DatasetError(f"dataset {name}: {path} lacks the column(s) {missing}")
    if frames.empty:
        raise DatasetError(f"dataset {name}: {path} has no rows (a dataset without frames would give an empty stage)")
    for column in ("stop", "image", "theta_deg", "x_mm"):
        if (text := not_numbers(frames[column])).any():
            row = int(np.argmax(text))
            value, stop, image = (frames[key].tolist()[row] for key in (column, "stop", "image"))
            raise DatasetError(f"dataset {name}: {path}: column {column} must hold numbers, got {value!r} in row {row} "
                               f"(stop {stop!r}, image {image!r})")
    if frames[["dataset", "stop", "image", "file"]].isna().any().any():
        raise DatasetError(f"dataset {name}: {path} has empty dataset, stop, image or file entries")
    if others := sorted(set(frames["dataset"].astype(str)) - {name}):
        raise DatasetError(f"dataset {name}: {path} holds rows of dataset(s) {others}")
    for columns in (["stop", "image"], ["file"]):
        repeated = frames[frames.duplicated(columns, keep=False)]
        if len(repeated):
            first = repeated.iloc[0]
            raise DatasetError(f"dataset {name}: {path} has {len(repeated)} rows with the same {' and '.join(columns)} "
                               f"(first: stop {first['stop']}, image {first['image']}, file {first['file']})")
    positions = frames[["theta_deg", "x_mm"]].to_numpy(dtype=np.float64, na_value=np.nan)
    if not np.all(np.isfinite(positions)):
        raise DatasetError(f"dataset {name}: {path} has theta_deg / x_mm values that are not finite numbers")


def recorded_worlds(data_dir: str | Path) -> set[str]:
    """The worlds of ``data_dir``'s datasets that hold recorded data (meta.json ``source: recorded``), checked as
    :func:`load_index` and :func:`load_dataset` check them."""
    index = load_index(data_dir)
    metas = [_read_meta(Path(data_dir) / row.path / "meta.json", row.dataset) for row in index.itertuples()]
    return {meta["world"] for meta in metas if meta.get("source", "rendered") == "recorded"}


def load_dataset(data_dir: str | Path, folder: str | Path, name: str | None = None) -> Dataset:
    """A checked dataset from its folder (relative to ``data_dir``, as in the index's ``path`` column); ``name``:
    the index's name for it, which meta.json must repeat."""
    data_dir = Path(data_dir)
    folder = data_dir / folder
    meta = _read_meta(folder / "meta.json", name)
    name = meta["dataset"]
    frames_path = folder / "frames.parquet"
    frames = _read_parquet(frames_path, f"dataset {name}: ")
    _check_frames(frames, frames_path, name)
    frames = frames.sort_values(["stop", "image"], ignore_index=True)
    try:
        camera = read_camera_yaml(folder / "camera.yaml")
    except CameraFileError as error:
        raise DatasetError(f"dataset {name}: {error}") from None
    dataset = Dataset(data_dir, folder, meta, frames, camera)
    dataset.check_images()
    return dataset
