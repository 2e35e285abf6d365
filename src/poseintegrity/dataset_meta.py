"""The ``meta.json`` of a dataset, as stages 02 and 05 read it: its schema (:class:`Meta`: the ground-truth board,
:class:`BoardMeta`; the model pair, :class:`ModelMeta`), the check of a pose written in it (:func:`pose_problem`) and
the error a dataset that does not hold what it must raises (:class:`DatasetError`). Stage 01 checks what it writes
against it (scenes/dataset_files.py), recorded data what it imports (recorded/), stage 02 what it reads
(localization/dataset.py).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from poseintegrity.boards import aruco_dictionary, dictionary_size
from poseintegrity.errors import PoseIntegrityError

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
