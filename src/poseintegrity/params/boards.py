"""Schema of the boards of the ``generate`` section (stage 01): how printed boards differ from their drawings, and
the scenes' ground-truth board with the keys of its placement plan (scenes/board_plan.py). Every number bounded,
its key named when refused."""

from __future__ import annotations

from typing import Annotated, Literal

import cv2
from pydantic import AfterValidator, Field, model_validator

from poseintegrity.boards import ArucoGrid, Board, Charuco, dictionary_size
from poseintegrity.schema import KeyRule, Section, distinct


def _known_dictionary(name: str) -> str:
    if not isinstance(getattr(cv2.aruco, name, None), int):
        raise ValueError(f"OpenCV has no ArUco dictionary {name!r}")
    return name


Dictionary = Annotated[str, Field(pattern=r"^DICT_\w+$"), AfterValidator(_known_dictionary)]  # both boards' dictionary


class PrintedBoardParams(Section):
    """Printed boards are not their drawings (both the calibration ChArUco and the scenes' ArUco ground-truth board):
    a printer scales each axis a little, and a sheet is not flat. Drawn once per board and world; every stage that
    uses a board assumes its drawing, as a lab does."""

    scale_std: float = Field(ge=0, le=0.01, description="per axis: laser printers scale by ~0.1-0.3 %; 1 % would be "
                                                        "seen with a ruler")
    calibration_sag_std_mm: float = Field(ge=0, le=5, description="bow of the ChArUco card at its centre")
    board_sag_std_mm: float = Field(ge=0, le=5, description="bow of the ground-truth board glued on its stand")
    caliper_std_mm: float | None = Field(
        ge=0, le=5, description="the lab measures the printed ground-truth board's width and height with calipers "
        "(this error each) and uses the measured size; null: the drawing's size is used, unmeasured")


class GroundTruthBoardParams(Section):
    """The scenes' ground-truth board (IV-C: "an ArUco marker board [35]"; its size and layout are unpublished, ours
    are chosen by measurement: docs/references.md, "Ground-truth boards"). ``aruco_grid`` needs markers_x, markers_y,
    marker_length_mm and separation_mm; ``charuco`` squares_x, squares_y, square_mm and marker_mm (the other kind's
    keys are refused). ``placement``: ``planned`` (per scene, a ChArUco board of one of ``sizes_mm`` on a post facing
    the model camera, wholly in view, in focus and predicted within ``plan_sigma_t_mm`` at every stop of the
    trajectories it serves, and up to ``max_boards`` of them: scenes/board_plan.py),
    ``facing_camera`` (one board of square_mm, most of it in view along every trajectory) or
    ``flat`` (lying on a pedestal beside the target)."""

    type: Literal["aruco_grid", "charuco"]
    dictionary: Dictionary
    markers_x: int | None = Field(None, ge=1, le=20)
    markers_y: int | None = Field(None, ge=1, le=20)
    marker_length_mm: float | None = Field(None, gt=0, le=200)
    separation_mm: float | None = Field(None, ge=0, le=100)
    squares_x: int | None = Field(None, ge=3, le=40)
    squares_y: int | None = Field(None, ge=3, le=40)
    square_mm: float | None = Field(None, gt=0, le=200)
    marker_mm: float | None = Field(None, gt=0, le=200)
    margin_mm: float = Field(ge=0, le=100, description="white paper around the pattern")
    px_per_mm: float = Field(ge=2, le=32, description="texels per mm of the printed board's texture")
    placement: Literal["planned", "facing_camera", "flat"]
    sizes_mm: distinct(Annotated[float, Field(gt=0, le=200)]) | None = Field(
        None, min_length=1, description="planned: the square sizes the lab may print the board at (marker_mm scales "
                                        "with square_mm); the plan picks one per board")
    max_boards: int | None = Field(
        None, ge=1, le=2, description="planned: boards per scene at most (a second one where no place keeps one in "
                                      "view on every trajectory)")
    plan_sigma_t_mm: float | None = Field(
        None, gt=0, le=100, description="planned: a board serves a trajectory when its pose is predicted within this "
        "(RMS at the board origin, mm) at every stop; extract.ground_truth.max_sigma_t_mm is what stage 02 then trusts")

    @model_validator(mode="after")
    def _fields_of_its_type(self) -> "GroundTruthBoardParams":
        mine = {"aruco_grid": ("markers_x", "markers_y", "marker_length_mm", "separation_mm"),
                "charuco": ("squares_x", "squares_y", "square_mm", "marker_mm")}
        for key in mine[self.type]:
            if getattr(self, key) is None:
                raise KeyRule(key, f"required by a {self.type} board")
        for kind, keys in mine.items():
            for key in keys:
                if kind != self.type and getattr(self, key) is not None:
                    raise KeyRule(key, f"a key of a {kind} board; this board is {self.type}")
        if self.type == "charuco" and self.marker_mm >= self.square_mm:
            raise KeyRule("marker_mm", f"a marker lies inside its square: must be < square_mm ({self.square_mm:g})")
        planned = ("sizes_mm", "max_boards", "plan_sigma_t_mm")
        for key in planned:
            if (getattr(self, key) is None) == (self.placement == "planned"):
                raise KeyRule(key, "required by placement planned" if self.placement == "planned" else
                              f"a key of placement planned; this board's placement is {self.placement}")
        if self.placement == "planned" and self.type != "charuco":
            raise KeyRule("type", "placement planned plans ChArUco boards (their corners stay sharp under blur)")
        n_markers, size = self.drawing().n_markers * (self.max_boards or 1), dictionary_size(self.dictionary)
        if n_markers > size:
            raise KeyRule("dictionary", f"the board(s) hold {n_markers} markers, {self.dictionary} has {size}")
        return self

    def drawing(self, scale: tuple[float, float] = (1.0, 1.0), square_mm: float | None = None,
                first_id: int = 0) -> Board:
        """The board as drawn (:mod:`poseintegrity.boards`), or as measured with ``scale`` (printed / drawn); a
        ChArUco board printed with squares of ``square_mm`` (default: ``square_mm``; its markers scaled alike) and
        ids from ``first_id``."""
        if self.type == "charuco":
            square = self.square_mm if square_mm is None else square_mm
            return Charuco(self.dictionary, self.squares_x, self.squares_y, square,
                           self.marker_mm * square / self.square_mm, first_id, scale)
        return ArucoGrid(self.dictionary, self.markers_x, self.markers_y, self.marker_length_mm, self.separation_mm,
                         0, scale)
