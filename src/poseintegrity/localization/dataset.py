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
from typing import Annotated, Any, Literal

import numpy as np
import pandas as pd
import pyarrow
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from poseintegrity.boards import aruco_dictionary, dictionary_size
from poseintegrity.errors import ArgumentError, PoseIntegrityError, not_numbers
from poseintegrity.lens import Camera, CameraFileError, read_camera_yaml

INDEX_COLUMNS = ("dataset", "path")
FRAME_TABLE_COLUMNS = ("dataset", "stop", "image", "theta_deg", "x_mm", "file", "T_cam_board")
RIGID_TOLERANCE = 1e-6  # |R^T R - I| and |bottom row - (0, 0, 0, 1)|: stage 01 writes poses exact to ~1e-15


class DatasetError(PoseIntegrityError):
    """A dataset on disk is missing, unreadable or inconsistent (stops the stage, naming the dataset and file)."""


def pose_problem(values: Any) -> str | None:
    """What is wrong with a board -> camera pose given as 16 row-major numbers or a (4, 4) array; None if it is a
    finite rigid transform (rotation orthonormal with determinant +1, bottom row 0 0 0 1)."""
    try:
        T = np.asarray(values, dtype=np.float64).reshape(4, 4)
    except (TypeError, ValueError):
        return f"is not 16 numbers (got {np.size(values) if values is not None else 'nothing'})"
    if not np.all(np.isfinite(T)):
        return "holds NaN or inf"
    R = T[:3, :3]
    if (np.abs(T[3] - [0.0, 0.0, 0.0, 1.0]).max() > RIGID_TOLERANCE
            or np.abs(R.T @ R - np.eye(3)).max() > RIGID_TOLERANCE or np.linalg.det(R) < 0):
        return "is not a rigid transform"
    return None


def _pose(values: Any, which: str) -> list[list[float]]:
    problem = pose_problem(values)
    if problem:
        raise ValueError(f"{which} {problem}")
    return np.asarray(values, dtype=np.float64).reshape(4, 4).tolist()


class _Read(BaseModel):
    """The part of meta.json this stage reads; stage 01 writes more (scene, targets, ...), which is ignored."""

    model_config = ConfigDict(extra="ignore", frozen=True, allow_inf_nan=False)


class BoardMeta(_Read):
    """The ground-truth board (IV-C; :mod:`poseintegrity.boards`), lengths in mm: ``type`` ``aruco_grid`` (the
    default, the paper's "ArUco marker board": markers_x, markers_y, marker_length_mm, separation_mm) or
    ``charuco`` (squares_x, squares_y, square_mm, marker_mm), its markers' ids from ``first_id`` (default 0);
    ``scale`` [x, y]: the printed size over the drawn size, as measured with calipers (default [1, 1]: the drawing)."""

    type: Literal["aruco_grid", "charuco"] = "aruco_grid"
    dictionary: str = Field(pattern=r"^DICT_\w+$")
    markers_x: int | None = Field(None, ge=1)
    markers_y: int | None = Field(None, ge=1)
    marker_length_mm: float | None = Field(None, gt=0)
    separation_mm: float | None = Field(None, ge=0)
    first_id: int = Field(0, ge=0)
    squares_x: int | None = Field(None, ge=3)
    squares_y: int | None = Field(None, ge=3)
    square_mm: float | None = Field(None, gt=0)
    marker_mm: float | None = Field(None, gt=0)
    scale: tuple[Annotated[float, Field(ge=0.9, le=1.1)], Annotated[float, Field(ge=0.9, le=1.1)]] = (1.0, 1.0)

    @property
    def ids(self) -> set[int]:
        """The ids of the board's markers."""
        count = (self.squares_x * self.squares_y // 2 if self.type == "charuco" else self.markers_x * self.markers_y)
        return set(range(self.first_id, self.first_id + count))

    @field_validator("dictionary")
    @classmethod
    def _known(cls, name: str) -> str:
        aruco_dictionary(name)  # an unknown name would fail only when stage 02 builds the board
        return name

    @model_validator(mode="after")
    def _fields_of_its_type(self) -> "BoardMeta":
        needed = {"aruco_grid": ("markers_x", "markers_y", "marker_length_mm", "separation_mm"),
                  "charuco": ("squares_x", "squares_y", "square_mm", "marker_mm")}[self.type]
        missing = [key for key in needed if getattr(self, key) is None]
        if missing:
            raise ValueError(f"a {self.type} board needs {', '.join(missing)}")
        if self.type == "charuco":
            if self.marker_mm >= self.square_mm:
                raise ValueError(f"marker_mm ({self.marker_mm:g}) must be below square_mm ({self.square_mm:g})")
            first, last = self.first_id, self.first_id + self.squares_x * self.squares_y // 2
        else:
            first, last = self.first_id, self.first_id + self.markers_x * self.markers_y
        size = dictionary_size(self.dictionary)
        if last > size:
            raise ValueError(f"board: markers {first} .. {last - 1} do not fit {self.dictionary}, which has "
                             f"{size} markers")
        return self


class ModelMeta(_Read):
    """The model pair of III-B / IV-D: two images, their target masks and the relative camera pose the robot
    reports between them (camera 0 -> camera 1, mm)."""

    images: tuple[str, str]
    masks: tuple[str, str]
    T_cam1_cam0: list[list[float]]
    T_cam0_ref: list[list[float]] | None = Field(
        default=None, description="model image 0's pose in the reference frame (ground_truth poses: places M_t)")
    exact_T_cam_board: list[list[list[float]]] | None = Field(
        default=None, description="the model images' exact board poses (rendered data: a diagnostic, the reference "
                                  "of the ground truth's own accuracy, R11)")
    T_base_cam_robot: tuple[list[list[float]], list[list[float]]] | None = Field(
        default=None, description="the model images' camera poses as the robot reports them, in a frame fixed to "
                                  "its base (mm; with frames.parquet's T_base_cam_robot: kinematic_consistency.py)")

    @field_validator("T_cam1_cam0", mode="before")
    @classmethod
    def _rigid(cls, pose: Any) -> Any:
        return _pose(pose, "the model pair's relative pose")

    @field_validator("T_cam0_ref", mode="before")
    @classmethod
    def _rigid_anchor(cls, pose: Any) -> Any:
        return None if pose is None else _pose(pose, "model image 0's pose T_cam0_ref")

    @field_validator("exact_T_cam_board", mode="before")
    @classmethod
    def _rigid_exact(cls, poses: Any) -> Any:
        return None if poses is None else [_pose(pose, f"model image {k}'s exact board pose")
                                           for k, pose in enumerate(poses)]

    @field_validator("T_base_cam_robot", mode="before")
    @classmethod
    def _rigid_robot(cls, poses: Any) -> Any:
        return None if poses is None else [_pose(pose, f"model image {k}'s robot pose")
                                           for k, pose in enumerate(poses)]


class Meta(_Read):
    """``meta.json`` of one dataset: what stages 02 and 05 read from it."""

    dataset: str = Field(min_length=1)
    world: str = Field(min_length=1, description="the world the dataset belongs to (main, validation, ...)")
    trajectory: Literal["arc", "line"]
    source: Literal["rendered", "recorded"] = Field(
        default="rendered", description="rendered by stage 01, or recorded (poseintegrity.recorded): stage 02's realism "
                                        "bars then describe the data instead of judging it")
    ground_truth: Literal["board", "poses"] = Field(
        default="board", description="board: the ArUco board detected per frame (IV-C, rendered data); poses: "
                                     "frames.parquet's T_cam_board, from an external system (recorded data)")
    board: BoardMeta | None = None
    handover_boards: list[BoardMeta] = Field(
        default_factory=list, description="other boards of the scene, each judging a frame the board cannot "
                                          "(localization/ground_truth.py, \"Handover boards\"); their marker ids "
                                          "must not overlap the board's")
    model: ModelMeta

    @model_validator(mode="after")
    def _truth_source(self) -> "Meta":
        if self.ground_truth == "board" and self.board is None:
            raise ValueError("board: needed with ground_truth board")
        if self.handover_boards and self.board is None:
            raise ValueError("handover_boards: only with a board (ground_truth board)")
        boards = [self.board, *self.handover_boards] if self.board is not None else []
        for k, other in enumerate(boards[1:]):
            for earlier in boards[:k + 1]:
                if earlier.dictionary == other.dictionary and earlier.ids & other.ids:
                    raise ValueError(f"handover_boards[{k}]: its marker ids {min(other.ids)}-{max(other.ids)} overlap "
                                     f"an earlier board's ({min(earlier.ids)}-{max(earlier.ids)}): set its first_id")
        if self.ground_truth == "poses" and self.model.T_cam0_ref is None:
            raise ValueError("model.T_cam0_ref: needed with ground_truth poses (it places M_t in the reference frame)")
        return self


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
