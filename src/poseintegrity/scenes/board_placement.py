"""Where a lab stood the ground-truth board before issue 39's plan (``generate.board.placement: facing_camera``,
:mod:`.board_plan` for ``planned``). Issue 30's rule: the board stands on a post beside the target
(:mod:`.board_stand`), facing the model camera, where along every trajectory of its scene no target covers the board,
the board and its post cover no target, and most of the board stays in the image. A target's edge over a marker is what
put the ArUco ground truth millimetres off (a partly hidden marker is still decoded, one corner pixels off); a board
seen face-on keeps its corners sharp where a board lying flat was seen at 50-79 deg at the arcs' far ends. Part of a
ChArUco board is enough for a pose: where the scene leaves no room for all of it along every trajectory (the lines'
model view, 220 mm from the target, sees 208 x 131 mm), the place keeping most of it in view at its worst pose wins.

The candidates are board centres on a grid in the frame of the model camera about the aim point (GRID_*: right, up in
the image, towards the camera), the board's plane facing the model camera, turned by a multiple of 90 deg so that its
origin (board x = y = 0, where E_t is measured, IV-C) is the corner nearest the first target. Each candidate is
projected by the pinhole of the true intrinsics (a lab looks at its camera's live image) at every commanded pose of the
scene's trajectories, beside the convex hulls of the targets' projected vertices, which contain their silhouettes
(:mod:`.image_polygons`). Kept: candidates whose board and post overlap no hull (with CLEARANCE_PX to spare) at any
pose, whose corners stay above the table, and which keep at least MIN_IN_VIEW of the board in the image at every pose.
Chosen: the one with the most of the board in view at its worst pose (to 1 %), then the shortest lever arm from the
board origin to the target. (Preferring the whole board at the model pair instead, whose board pose places M_t, left
less of it in view late in the arcs: R11's p99 0.78 mm against 0.61 mm, studies/board_options.py.) Deterministic: no
random draw.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import ConvexHull

from poseintegrity.poses import inverse, pose_matrix
from poseintegrity.scenes.board_stand import (
    GRID_RIGHT_MM, GRID_UP_MM, POST_BEHIND_MM, POST_RADIUS_MM, TABLE_CLEARANCE_MM, BoardPlacement, PlacementError,
)
from poseintegrity.scenes.image_polygons import (
    CLEARANCE_PX, NEAR_MM, hits, hull, near_targets, pixels, project, vertices_inside,
)

GRID_TOWARDS_MM = (-60.0, -30.0, 0.0, 30.0)
MIN_IN_VIEW = 0.25  # share of the board's area inside the image at every pose, at least


def place_board(size_mm: tuple[float, float], margin_mm: float, targets: list[np.ndarray], aim: np.ndarray,
                T_world_model: np.ndarray, poses: list[np.ndarray], K: np.ndarray, width: int, height: int,
                where: str) -> BoardPlacement:
    """The board's place (module docstring). size_mm : the pattern's (width, height); margin_mm : white paper around
    it (part of what must stay clear); targets : each target's vertices (n, 3), world mm; T_world_model : the model
    camera (its axes orient the grid and the board); poses : every commanded T_world_cam of the scene; K (3, 3),
    width, height : the camera. :class:`PlacementError` naming ``where`` when no candidate fits.

    Vectorized over the candidates, pose by pose, the views where candidates fail most first (the model view, then
    the poses furthest from it); a candidate is dropped at its first failing pose. The board's outline is sampled
    less than CLEARANCE_PX apart in the nearest view and tested against the targets' hulls grown by CLEARANCE_PX, and
    a hull vertex inside the board's outline is caught directly: no overlap is missed between the samples."""
    right, down, forward = T_world_model[:3, 0], T_world_model[:3, 1], T_world_model[:3, 2]
    target_centre = targets[0].mean(axis=0)
    targets = [v[ConvexHull(v).vertices] for v in targets]  # their projections have the same hulls
    w, h = size_mm[0] + 2 * margin_mm, size_mm[1] + 2 * margin_mm
    R_, U_, T_ = np.meshgrid(GRID_RIGHT_MM, GRID_UP_MM, GRID_TOWARDS_MM, indexing="ij")
    centres = aim + R_.reshape(-1, 1) * right - U_.reshape(-1, 1) * down - T_.reshape(-1, 1) * forward  # (n, 3)
    # printed side towards the camera (board z = camera forward), turned by a multiple of 90 deg about it so that its
    # origin (pattern corner x = y = 0) is the corner nearest the target
    turns = np.radians([0.0, 90.0, 180.0, 270.0])
    x_turn = np.cos(turns)[:, None] * right + np.sin(turns)[:, None] * down  # (4, 3)
    y_turn = -np.sin(turns)[:, None] * right + np.cos(turns)[:, None] * down
    origins = centres[:, None, :] - size_mm[0] / 2 * x_turn - size_mm[1] / 2 * y_turn  # (n, 4, 3)
    turn = np.argmin(np.linalg.norm(origins - target_centre, axis=2), axis=1)
    x_b, y_b = x_turn[turn], y_turn[turn]  # (n, 3)
    # the paper: its outline, sampled < CLEARANCE_PX apart in the nearest view, and an interior grid (share in view)
    nearest = min(np.linalg.norm(T[:3, 3] - aim) for T in poses) - max(w, h)
    step_mm = 0.9 * CLEARANCE_PX * max(nearest, NEAR_MM) / K[0, 0]
    s = np.linspace(-0.5, 0.5, int(np.ceil(max(w, h) / step_mm)) + 1)
    outline = np.vstack([np.column_stack([s * w, np.full_like(s, e * h / 2)]) for e in (-1, 1)]
                        + [np.column_stack([np.full_like(s, e * w / 2), s * h]) for e in (-1, 1)])
    gx, gy = np.meshgrid(np.linspace(-0.45, 0.45, 10) * w, np.linspace(-0.45, 0.45, 8) * h)
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    corners = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])

    def on_paper(local: np.ndarray, keep: np.ndarray) -> np.ndarray:  # (k, 2) board-plane offsets -> (n, k, 3)
        return (centres[keep, None, :] + local[None, :, 0, None] * x_b[keep, None, :]
                + local[None, :, 1, None] * y_b[keep, None, :])

    tops = centres + (POST_RADIUS_MM + POST_BEHIND_MM) * forward  # the post holds the board from behind
    feet = tops * np.array([1.0, 1.0, 0.0])
    post = feet[:, None, :] + np.linspace(0.0, 1.0, 12)[None, :, None] * (tops - feet)[:, None, :]  # (n, 12, 3)
    keep = on_paper(corners, np.ones(len(centres), bool))[..., 2].min(axis=1) >= TABLE_CLEARANCE_MM
    worst = np.ones(len(centres))
    order = np.argsort([-np.linalg.norm(T[:3, 3] - poses[0][:3, 3]) for T in poses], kind="stable")
    for k in np.concatenate([[0], order[order != 0]]):
        if not keep.any():
            break
        view = inverse(poses[k])
        hulls = [hull(project(v, view, K)) for v in targets]
        distance = np.linalg.norm(poses[k][:3, 3] - aim)
        near_board = near_targets(hulls, width, height, CLEARANCE_PX)
        near_post = near_targets(hulls, width, height, CLEARANCE_PX + POST_RADIUS_MM * K[0, 0] / distance)
        idx = np.flatnonzero(keep)
        quad, front = pixels(on_paper(corners, keep), view, K)
        grid_px, _ = pixels(on_paper(grid, keep), view, K)
        in_view = ((grid_px[..., 0] >= 0) & (grid_px[..., 0] <= width - 1) & (grid_px[..., 1] >= 0)
                   & (grid_px[..., 1] <= height - 1)).mean(axis=1)
        bad = ~front.all(axis=1) | (in_view < MIN_IN_VIEW)
        bad |= hits(*pixels(on_paper(outline, keep), view, K), near_board)
        bad |= hits(*pixels(post[keep], view, K), near_post)
        bad |= vertices_inside(quad, np.vstack(hulls))
        worst[idx] = np.minimum(worst[idx], in_view)
        keep[idx[bad]] = False
    if not keep.any():
        raise PlacementError(f"{where}: no place beside the target keeps a {w:g} x {h:g} mm board (with its margin) "
                             f"{MIN_IN_VIEW:.0%} in view and clear of the targets along every trajectory; a smaller "
                             f"generate.board, a larger distance_mm, fewer or smaller targets (generate.scapula.length_mm) would "
                             f"leave room")
    origins = centres - (size_mm[0] / 2) * x_b - (size_mm[1] / 2) * y_b
    lever = np.linalg.norm(origins - target_centre, axis=1)
    best = min(np.flatnonzero(keep), key=lambda i: (-round(worst[i], 2), lever[i], i))
    R = np.column_stack([x_b[best], y_b[best], forward])
    return BoardPlacement(pose_matrix(R, origins[best]), feet[best], tops[best], float(worst[best]))
