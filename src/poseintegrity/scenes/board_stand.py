"""A ground-truth board standing on a post beside the target, as both placements stand it (:mod:`.board_placement`,
facing_camera; :mod:`.board_plan`, planned): where it stands (:class:`BoardPlacement`), the error when no place fits
(:class:`PlacementError`), its post, the grid of board centres both look for a place on about the aim point (right
and up in the model camera's image) and whether clutter on the table would cover it (:func:`covers`). World frame:
table top z = 0, z up, mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.poses import inverse
from poseintegrity.scenes.image_polygons import hull, project

GRID_RIGHT_MM = np.arange(-200.0, 201.0, 20.0)
GRID_UP_MM = np.arange(-120.0, 121.0, 20.0)
TABLE_CLEARANCE_MM = 5.0  # the board's lowest corner above the table
POST_RADIUS_MM = 8.0
POST_BEHIND_MM = 3.0  # the post's top behind the paper beyond its own radius (at 3 mm its top poked through the board)
BOUNDING = 1.3  # a clutter box of 2 r x up to 1.5 r lies within a cylinder of 1.25 r about its centre


class PlacementError(PoseIntegrityError):
    """No candidate place keeps the board in view and clear of the targets along every trajectory."""


@dataclass(frozen=True)
class BoardPlacement:
    """T_world_board (4, 4, mm: board x right and y down as printed, z into the board) and the post holding it: from
    ``post_foot`` (3,) on the table up to ``post_top`` (3,) behind the board's centre. ``in_view``: the share of the
    board inside the image at its worst pose."""

    T_world_board: np.ndarray
    post_foot: np.ndarray
    post_top: np.ndarray
    in_view: float


def covers(xy: np.ndarray, radius: float, height: float, paper: np.ndarray, poses: list[np.ndarray],
           K: np.ndarray) -> bool:
    """Whether an object standing on the table within a cylinder (centre ``xy`` (2,), ``radius`` x BOUNDING, up to
    ``height``, mm) would cover part of the board's paper (4, 3) seen from any of ``poses`` (T_world_cam): their
    images overlap and the object's centre is nearer the camera than the board's."""
    angles = np.linspace(0.0, 2 * np.pi, 8, endpoint=False)
    ring = np.column_stack([xy[0] + BOUNDING * radius * np.cos(angles), xy[1] + BOUNDING * radius * np.sin(angles)])
    solid = np.vstack([np.column_stack([ring, np.zeros(8)]), np.column_stack([ring, np.full(8, height)])])
    centre = np.array([*xy, height / 2])
    for T in poses:
        view = inverse(T)
        if (view[2, :3] @ centre + view[2, 3]) >= (view[2, :3] @ paper.mean(axis=0) + view[2, 3]):
            continue  # behind the board
        seen = project(solid, view, K)
        if len(seen) < 3:
            continue  # behind the camera
        area, _ = cv2.intersectConvexConvex(project(paper, view, K).astype(np.float32), hull(seen))
        if area > 0:
            return True
    return False
