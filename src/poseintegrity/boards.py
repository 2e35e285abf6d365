"""The ground-truth board of Windsor et al. IV-C, as a dataset describes it (meta.json's ``board``, a recording's
board.yaml): an ArUco GridBoard (the paper's "ArUco marker board [35]") or a ChArUco board (an ArUco-identified
chessboard, whose corners are saddle points located to a few hundredths of a pixel and without the inward pull of a
marker's corner; docs/references.md, "Ground-truth boards").

The board frame is OpenCV's: origin at the board's top-left corner, x right, y down, z into the board, mm. A
printed board is not its drawing: ``scale`` is the printed size over the drawn size along x and y, as the lab measured
it with calipers (1, 1 when not measured). Every board point the pipeline uses is the drawing's point scaled by it.

A leaf (OpenCV and numpy only): the scenes draw the board, the localization stage detects it, the recorded-data reader
checks it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import cv2
import numpy as np

from poseintegrity.errors import ArgumentError

BOARD_TYPES = ("aruco_grid", "charuco")


def aruco_dictionary(name: object, key: str = "board.dictionary") -> int:
    """OpenCV's id of the predefined ArUco dictionary ``name`` ("DICT_4X4_50", ...); :class:`ArgumentError` naming
    ``key`` and the known names otherwise."""
    value = getattr(cv2.aruco, name, None) if isinstance(name, str) and name.startswith("DICT_") else None
    if isinstance(value, bool) or not isinstance(value, int):
        known = sorted(k for k in dir(cv2.aruco) if k.startswith("DICT_"))
        raise ArgumentError(f"{key}: unknown ArUco dictionary {name!r}; OpenCV knows {', '.join(known)}")
    return value


def dictionary_size(name: str) -> int:
    """How many markers the predefined ArUco dictionary ``name`` holds (:func:`aruco_dictionary` checks the name)."""
    return int(cv2.aruco.getPredefinedDictionary(aruco_dictionary(name)).bytesList.shape[0])


@dataclass(frozen=True)
class ArucoGrid:
    """An ArUco GridBoard: markers_x x markers_y markers of ``marker_length_mm``, ``separation_mm`` apart, ids from
    ``first_id``. Its points come in groups of four: the corners of one marker."""

    dictionary: str
    markers_x: int
    markers_y: int
    marker_length_mm: float
    separation_mm: float
    first_id: int = 0
    scale: tuple[float, float] = (1.0, 1.0)
    type: str = field(default="aruco_grid", init=False)

    @property
    def n_markers(self) -> int:
        return self.markers_x * self.markers_y

    def cv_board(self) -> "cv2.aruco.GridBoard":
        ids = np.arange(self.first_id, self.first_id + self.n_markers)
        return cv2.aruco.GridBoard((self.markers_x, self.markers_y), self.marker_length_mm, self.separation_mm,
                                   cv2.aruco.getPredefinedDictionary(aruco_dictionary(self.dictionary)), ids)

    @property
    def size_mm(self) -> tuple[float, float]:
        """Width and height of the drawing's markers' area, mm."""
        return (self.markers_x * self.marker_length_mm + (self.markers_x - 1) * self.separation_mm,
                self.markers_y * self.marker_length_mm + (self.markers_y - 1) * self.separation_mm)

    def as_dict(self) -> dict[str, Any]:
        return {"type": self.type, "dictionary": self.dictionary, "markers_x": self.markers_x,
                "markers_y": self.markers_y, "marker_length_mm": self.marker_length_mm,
                "separation_mm": self.separation_mm, "first_id": self.first_id, "scale": list(self.scale)}


@dataclass(frozen=True)
class Charuco:
    """A ChArUco board: squares_x x squares_y chessboard squares of ``square_mm`` with ArUco markers of ``marker_mm``
    in the white ones (ids from ``first_id``: a second board in the same view has ids of its own); its points are the
    inner chessboard corners, each a group of its own."""

    dictionary: str
    squares_x: int
    squares_y: int
    square_mm: float
    marker_mm: float
    first_id: int = 0
    scale: tuple[float, float] = (1.0, 1.0)
    type: str = field(default="charuco", init=False)

    @property
    def n_markers(self) -> int:
        """One marker in every white square."""
        return self.squares_x * self.squares_y // 2

    def cv_board(self) -> "cv2.aruco.CharucoBoard":
        return cv2.aruco.CharucoBoard((self.squares_x, self.squares_y), self.square_mm, self.marker_mm,
                                      cv2.aruco.getPredefinedDictionary(aruco_dictionary(self.dictionary)),
                                      np.arange(self.first_id, self.first_id + self.n_markers))

    @property
    def size_mm(self) -> tuple[float, float]:
        return self.squares_x * self.square_mm, self.squares_y * self.square_mm

    def as_dict(self) -> dict[str, Any]:
        return {"type": self.type, "dictionary": self.dictionary, "squares_x": self.squares_x,
                "squares_y": self.squares_y, "square_mm": self.square_mm, "marker_mm": self.marker_mm,
                "first_id": self.first_id, "scale": list(self.scale)}


Board = ArucoGrid | Charuco
_FIELDS = {"aruco_grid": ("dictionary", "markers_x", "markers_y", "marker_length_mm", "separation_mm"),
           "charuco": ("dictionary", "squares_x", "squares_y", "square_mm", "marker_mm")}


def board_from_dict(spec: dict[str, Any], where: str = "board") -> Board:
    """The board a dataset describes (meta.json's ``board``, a board.yaml): ``type`` ``aruco_grid`` (the default,
    the paper's board) or ``charuco``, the fields of that type, and optionally ``first_id`` (the first marker's id,
    default 0) and ``scale`` [x, y] (measured printed size over drawn size). A missing field, an unknown type or
    dictionary, or a value that is not a positive number (an
    integer for counts) raises :class:`ArgumentError` naming ``where`` and the key."""
    if not isinstance(spec, dict):
        raise ArgumentError(f"{where}: expected a mapping of the board's fields, got {type(spec).__name__}")
    kind = spec.get("type", "aruco_grid")
    if kind not in BOARD_TYPES:
        raise ArgumentError(f"{where}.type: unknown board type {kind!r}; expected one of {BOARD_TYPES}")
    missing = [key for key in _FIELDS[kind] if key not in spec]
    if missing:
        raise ArgumentError(f"{where}: a {kind} board needs {', '.join(missing)} (missing)")
    aruco_dictionary(spec["dictionary"], f"{where}.dictionary")
    values = {key: _checked(spec[key], f"{where}.{key}", integer=key.endswith(("_x", "_y")))
              for key in _FIELDS[kind][1:]}
    values["dictionary"] = spec["dictionary"]
    scale = spec.get("scale", (1.0, 1.0))
    if not isinstance(scale, (list, tuple)) or len(scale) != 2:
        raise ArgumentError(f"{where}.scale: expected [x, y], the printed over the drawn size, got {scale!r}")
    scale = tuple(_checked(s, f"{where}.scale", integer=False) for s in scale)
    values["first_id"] = _checked(spec.get("first_id", 0), f"{where}.first_id", integer=True, allow_zero=True)
    board = Charuco(**values, scale=scale) if kind == "charuco" else ArucoGrid(**values, scale=scale)
    first, size = board.first_id, dictionary_size(board.dictionary)
    if first + board.n_markers > size:
        raise ArgumentError(f"{where}: markers {first} .. {first + board.n_markers - 1} do not fit {board.dictionary} "
                            f"({size} markers)")
    return board


def _checked(value: object, key: str, integer: bool, allow_zero: bool = False) -> int | float:
    """A board field as a number: a positive (or, with ``allow_zero``, non-negative) integer or finite float;
    :class:`ArgumentError` naming ``key`` otherwise (text, NaN, a bool, a fraction where a count is wanted)."""
    number = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    if number and np.isfinite(value) and (value > 0 or (allow_zero and value == 0)) and (
            not integer or float(value).is_integer()):
        return int(value) if integer else float(value)
    wanted = "a non-negative integer" if allow_zero else "a positive integer" if integer else "a positive number"
    raise ArgumentError(f"{key}: expected {wanted}, got {value!r}")


def scaled(points: np.ndarray, board: Board) -> np.ndarray:
    """Board points (n, 3) of the drawing, mm, as printed: x and y times the board's measured ``scale``."""
    return np.asarray(points, dtype=np.float64) * np.array([*board.scale, 1.0])


def board_description(spec: dict[str, Any]) -> str:
    """A board dict in a few words, for messages: "DICT_4X4_50, 3 x 2 markers from id 0", "DICT_4X4_50, ChArUco 7 x
    5 squares"."""
    board = board_from_dict(spec)
    if isinstance(board, Charuco):
        ids = f", markers from id {board.first_id}" if board.first_id else ""
        return (f"{board.dictionary}, ChArUco {board.squares_x} x {board.squares_y} squares of {board.square_mm:g} mm"
                f"{ids}")
    return f"{board.dictionary}, {board.markers_x} x {board.markers_y} markers from id {board.first_id}"
