"""A printed board as the lab has it (``generate.printed_boards``): printed with a scale error per axis and bowed
(:func:`print_errors`), then measured with calipers (:func:`measured_scale`, :func:`measured_board`). Each board the
lab prints (:func:`printed_name`) is one physical board in every scene that uses it: its draws are keyed by its name.
"""

from __future__ import annotations

from dataclasses import replace

from poseintegrity.boards import Board
from poseintegrity.params.generate import GenerateParams
from poseintegrity.seeding import keyed_rng


def measured_board(params: "GenerateParams", drawing: Board | None = None) -> Board:
    """A ground-truth board as the lab knows it: its drawing (default: ``generate.board``'s) scaled by the printed
    size the lab measured (:func:`measured_scale`)."""
    drawing = params.board.drawing() if drawing is None else drawing
    scale = measured_scale(params, printed_name(params, drawing), drawing)
    return replace(drawing, scale=scale)


def printed_name(params: "GenerateParams", drawing: Board) -> str:
    """The key of a printed ground-truth board's draws (:func:`print_errors`, :func:`measured_scale`): "aruco" for
    the params' own drawing (the board of the facing_camera and flat placements), else one of its size and first id: each
    board the lab prints is one physical board in every scene that uses it."""
    if drawing == params.board.drawing():
        return "aruco"
    return f"aruco_{drawing.size_mm[0]:g}x{drawing.size_mm[1]:g}_{getattr(drawing, 'first_id', 0)}"


def measured_scale(params: "GenerateParams", board: str, drawing: Board) -> tuple[float, float]:
    """The printed size over the drawn size of ``board`` ("aruco": the ground truth's, "charuco": the calibration
    board) as the lab measured it with calipers along x and y (``printed_boards.caliper_std_mm`` on the drawing's
    width and height), drawn from ``keyed_rng(seed, "caliper", board)`` around the printer's true scale
    (:func:`print_errors`); (1, 1), the drawing, when the lab does not measure (null)."""
    if params.printed_boards.caliper_std_mm is None:
        return 1.0, 1.0
    scale, _ = print_errors(params, board, 0.0)
    error = params.printed_boards.caliper_std_mm * keyed_rng(params.seed, "caliper", board).standard_normal(2)
    return float(scale[0] + error[0] / drawing.size_mm[0]), float(scale[1] + error[1] / drawing.size_mm[1])


def print_errors(params: "GenerateParams", board: str, sag_std_mm: float) -> tuple[tuple[float, float], float]:
    """(scale (x, y), sag mm) of one printed board of the world, drawn from ``keyed_rng(seed, "print", board)``:
    the same physical board in every scene (``generate.printed_boards``)."""
    rng = keyed_rng(params.seed, "print", board)
    scale = 1.0 + params.printed_boards.scale_std * rng.standard_normal(2)
    return (float(scale[0]), float(scale[1])), float(sag_std_mm * rng.standard_normal())
