"""The candidate ground-truth boards of the board plan (:mod:`.board_plan`, placement planned), where a lab could
stand them.

Every size of ``generate.board.sizes_mm`` (squares_x x squares_y squares, the markers scaled alike), at board centres
on a grid in the model camera's frame about the aim point (GRID_RIGHT_MM, GRID_UP_MM in the image, PLAN_TOWARDS_MM
towards the camera), long side across the image or upright, facing the model camera or turned from it by
PLAN_TILTS_DEG (a planar target seen face on is its worst-conditioned pose: its tilt trades for its distance), the
origin at the corner nearest the first target; each on a post behind its centre (:mod:`.board_stand`). Points on a
candidate's plane are given as fractions of its pattern or paper about its centre (:data:`PAPER`, :func:`lattice`,
:func:`inner_corners`), computed in numba kernels in numpy's order of operations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from poseintegrity.poses import pose_matrix
from poseintegrity.scenes.board_stand import GRID_RIGHT_MM, GRID_UP_MM, POST_BEHIND_MM, POST_RADIUS_MM, BoardPlacement

PLAN_TOWARDS_MM = (-60.0, -30.0, 0.0, 30.0, 60.0)  # board centres from the aim point towards the camera
# the board turned from facing the model camera by (about the image's x axis: 0, about its y axis: 1, deg): a board
# seen face on is the worst-conditioned planar pose (its tilt trades for its distance, Schweighofer and Pinz 2006); a
# lab tilts it
PLAN_TILTS_DEG = ((0, 0.0), (0, 25.0), (0, -25.0), (0, 40.0), (0, -40.0), (1, 25.0), (1, -25.0), (1, 40.0), (1, -40.0))
PAPER = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])  # a paper's (or pattern's) corners


@dataclass
class Candidates:
    """Board candidates (n of them): centre (n, 3), board axes x_b, y_b, z_b (n, 3; z_b into the board, away from
    the printed side), pattern size (n, 2), square (n,), paper size with its margin (n, 2); derived: ``origin`` (n, 3),
    the pattern's corner x = y = 0, and ``post_top`` (n, 3), behind the centre."""

    centre: np.ndarray
    x_b: np.ndarray
    y_b: np.ndarray
    z_b: np.ndarray
    pattern: np.ndarray
    square: np.ndarray
    paper: np.ndarray

    def subset(self, keep: np.ndarray) -> Candidates:
        """The candidates ``keep`` (a mask or indices) alone."""
        return Candidates(self.centre[keep], self.x_b[keep], self.y_b[keep], self.z_b[keep], self.pattern[keep],
                          self.square[keep], self.paper[keep])

    def __post_init__(self) -> None:
        self.origin = self.centre - self.pattern[:, :1] / 2 * self.x_b - self.pattern[:, 1:] / 2 * self.y_b
        self.post_top = self.centre + (POST_RADIUS_MM + POST_BEHIND_MM) * self.z_b

    def on_board(self, fractions: np.ndarray, of: np.ndarray, keep: np.ndarray) -> np.ndarray:
        """World points (k, m, 3) of board-plane points given as fractions (m, 2) of the size ``of`` (n, 2) about
        the centre, of the candidates ``keep`` (k of n: a mask or their indices)."""
        keep = np.flatnonzero(keep) if keep.dtype == bool else keep
        points = np.empty((len(keep), len(fractions), 3))
        _on_board_at(self.centre, self.x_b, self.y_b, of, keep, fractions, points)
        return points

    def post(self, keep: np.ndarray, n: int = 24) -> np.ndarray:
        """(k, n, 3): points along the post's axis from the table to its top."""
        top = self.post_top[keep]
        foot = top * np.array([1.0, 1.0, 0.0])
        return foot[:, None, :] + np.linspace(0.0, 1.0, n)[None, :, None] * (top - foot)[:, None, :]


def candidate_grid(sizes_mm: list[float], squares: tuple[int, int], margin_mm: float, aim: np.ndarray,
                   T_world_model: np.ndarray, target_centre: np.ndarray) -> Candidates:
    """Every candidate of the module docstring: boards of ``squares`` (squares_x, squares_y) squares of each size of
    ``sizes_mm``, with ``margin_mm`` of white paper about the pattern, centred on the grid about ``aim`` (3,) in the
    frame of the model camera T_world_model (4, 4), the origin at the corner nearest ``target_centre`` (3,), world
    mm."""
    right, down, forward = T_world_model[:3, 0], T_world_model[:3, 1], T_world_model[:3, 2]
    S, R_, U_, T_, L_, A_ = np.meshgrid(sizes_mm, GRID_RIGHT_MM, GRID_UP_MM, PLAN_TOWARDS_MM, (0, 1),
                                        np.arange(len(PLAN_TILTS_DEG)), indexing="ij")
    square = S.ravel()
    centre = aim + R_.reshape(-1, 1) * right - U_.reshape(-1, 1) * down - T_.reshape(-1, 1) * forward
    pattern = square[:, None] * np.array(squares, float)
    # printed side towards the camera (board z = camera forward), its long side across the image (L_ 0) or upright
    # (1), turned by 180 deg or not so that the origin is the corner nearest the target
    turns = np.radians([0.0, 180.0, 90.0, 270.0]).reshape(2, 2)[L_.ravel()]  # (n, 2)
    x_turn = np.cos(turns)[..., None] * right + np.sin(turns)[..., None] * down  # (n, 2, 3)
    y_turn = -np.sin(turns)[..., None] * right + np.cos(turns)[..., None] * down
    origins = centre[:, None, :] - pattern[:, None, :1] / 2 * x_turn - pattern[:, None, 1:] / 2 * y_turn  # (n, 2, 3)
    turn = np.argmin(np.linalg.norm(origins - target_centre, axis=2), axis=1)
    pick = np.arange(len(square))
    x_b, y_b = x_turn[pick, turn], y_turn[pick, turn]
    # then tilted from facing the model camera about the image's horizontal or vertical axis (Rodrigues' formula)
    tilts = np.array(PLAN_TILTS_DEG)[A_.ravel()]
    axis = np.where((tilts[:, :1] == 0), right, down)  # about "down": turns left-right; about "right": up-down
    angle = np.radians(tilts[:, 1])[:, None]

    def tilted(v: np.ndarray) -> np.ndarray:
        return (v * np.cos(angle) + np.cross(axis, v) * np.sin(angle)
                + axis * np.sum(axis * v, axis=1, keepdims=True) * (1 - np.cos(angle)))

    x_b, y_b = tilted(x_b), tilted(y_b)
    return Candidates(centre, x_b, y_b, np.cross(x_b, y_b), pattern, square, pattern + 2 * margin_mm)


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA
def board_point(centre, x_b, y_b, of, i, fraction):
    """World point (3 floats) of the board-plane point ``fraction`` (2,) of the size of[i] about candidate i's centre,
    in numpy's order of operations (:meth:`Candidates.on_board`): the centre, plus the offset along x_b, plus the
    offset along y_b."""
    u, v = fraction[0] * of[i, 0], fraction[1] * of[i, 1]
    return (centre[i, 0] + u * x_b[i, 0] + v * y_b[i, 0], centre[i, 1] + u * x_b[i, 1] + v * y_b[i, 1],
            centre[i, 2] + u * x_b[i, 2] + v * y_b[i, 2])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _on_board_at(centre, x_b, y_b, of, keep, fractions, points):
    """points (k, m, 3) of :meth:`Candidates.on_board` (``keep``: indices)."""
    for a in range(len(keep)):
        for j in range(len(fractions)):
            points[a, j, 0], points[a, j, 1], points[a, j, 2] = board_point(centre, x_b, y_b, of, keep[a],
                                                                            fractions[j])


def lattice(squares: tuple[int, int]) -> np.ndarray:
    """((squares_y + 1) (squares_x + 1), 2) the corners of a board's squares, its outline's included, as fractions of
    its pattern about the centre, row by row."""
    sx, sy = squares
    return np.array([[i / sx - 0.5, j / sy - 0.5] for j in range(sy + 1) for i in range(sx + 1)])


def inner_corners(squares: tuple[int, int]) -> np.ndarray:
    """(m, 2) a board's inner (chessboard) corners as fractions of its pattern about the centre."""
    sx, sy = squares
    return np.array([[(i + 1) / sx - 0.5, (j + 1) / sy - 0.5] for j in range(sy - 1) for i in range(sx - 1)])


def placement_of(c: Candidates, i: int, in_view: float) -> BoardPlacement:
    """Where candidate ``i`` stands (its post from the table up to its top), ``in_view`` of it at its worst pose."""
    top = c.post_top[i]
    return BoardPlacement(pose_matrix(np.column_stack([c.x_b[i], c.y_b[i], c.z_b[i]]), c.origin[i]),
                          top * np.array([1.0, 1.0, 0.0]), top, in_view)
