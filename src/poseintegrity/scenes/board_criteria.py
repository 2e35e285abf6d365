"""Which candidate boards serve which poses: criteria 1-3 of the board plan (:mod:`.board_plan`, placement planned), and the sigma_t
each predicts (criterion 4, :mod:`.board_sigma`).

A board serves a pose (model image 0, a stop) where

1. **at least MIN_PLAN_CORNERS of its inner corners are found**: a ChArUco corner is interpolated from the markers of
   the four squares about it, so a corner counts when those squares' corners (its 3 x 3 neighbourhood of the board's
   lattice) all lie inside the image, in front of the camera, and off every nearer obstacle (criterion 2). The white
   margin around the pattern may leave the image: the detector never reads it (tests/scenes/test_board_criteria.py: a
   board cut by the image's edge two squares in gives the 12 corners counted here, OpenCV's detector finds them). The
   plan first asked for the whole pattern in view: on the main world at one image per stop that left 93.5 % of frames
   trusted and every arc whose board stood near the image's edge late unserved, where this rule reaches 97.5 % (R11
   p99 0.354 mm against 0.419 mm), and stage 02 judges a frame by the corners it finds;
2. **no target covers it**: where the board and a target (or a target's stand, or another board) overlap in the
   image (its outline, sampled at most OUTLINE_STEP_PX apart, on the other's silhouette hull grown by CLEARANCE_PX,
   or a hull vertex inside it), the nearer of the two covers the other; and the board **never covers a target** or
   another board, at any pose of the session, served or not (a candidate that would is dropped);
3. **it is in focus**: the lens is focused once per session (:mod:`.optics`), so the blur of the
   board's nearest or farthest corner, hypot(the lens' own blur, the defocus), must stay within FOCUS_BLUR_PER_CELL of
   a marker's bit cell where the pattern is smallest in the image (far, foreshortened), and a bit cell must span at
   least MIN_CELL_PX, or its markers are not read (the lines' far stops of the facing_camera placement).

A candidate that fails 1-3 in model image 0 is dropped. The candidates that stay are found first and only they are
judged at every pose, and an image test runs only where a board's image can reach what it tests.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numba
import numpy as np

from poseintegrity.poses import inverse
from poseintegrity.scenes.board_candidates import PAPER, Candidates, board_point, inner_corners, lattice
from poseintegrity.scenes.board_sigma import corner_noise_px, unit_sigma_t
from poseintegrity.scenes.board_stand import POST_RADIUS_MM, TABLE_CLEARANCE_MM
from poseintegrity.scenes.image_polygons import (
    CLEARANCE_PX, NEAR_MM, Mask, hull, on_pixel, pixels, project, project_point, vertices_inside,
)
from poseintegrity.scenes.optics import defocus_sigma_px

# Measured on the renders of studies/board_options.py (ChArUco boards, 960 frames of the facing_camera placement's and this plan's
# boards): boards whose bit cells are 3 px or more and blurred by at most 0.35 of a cell were found with 20 or more
# corners in 92-100 % of frames; beyond 0.5 of a cell in none.
FOCUS_BLUR_PER_CELL = 0.35
MIN_CELL_PX = 3.0  # below 3 px bit cells a quarter to a half of the boards lost their markers
MIN_PLAN_CORNERS = 12  # a board serves a pose only with half its 24 inner corners found or more
OUTLINE_STEP_PX = 10.0  # outline samples at most this far apart: less than 2 CLEARANCE_PX, so a crossing is caught


@dataclass(frozen=True)
class Obstacle:
    """An object near the board: its vertices (k, 3, world mm), and whether the board may never stand in front of
    it (a target) or only must not stand behind it where it serves (a target's stand)."""

    vertices: np.ndarray
    hidden_matters: bool


@dataclass
class Judged:
    """Per candidate (n) and pose (p): ``alive`` (n,): whole, in focus and uncovered in model image 0 and covering
    nothing at any pose; for the candidates alive (the others are left False, inf, NaN): ``served`` (n, p): criteria
    1-3 hold; ``sigma_t`` (n, p) predicted (inf where not served); ``noise`` (n, p): the corner noise (px) at that
    pose's blur (NaN where not served); ``visible`` (n, p, m): which of its m inner corners are found there."""

    alive: np.ndarray
    served: np.ndarray
    sigma_t: np.ndarray
    noise: np.ndarray
    visible: np.ndarray


@dataclass(frozen=True)
class _Sighted:
    """An obstacle in one pose's image: its hull (h, 2 px), its depth (its vertices' mean, mm), the pixels within
    CLEARANCE_PX of it (``near``) and, for a target, those a post in front of it must keep off (``post``: CLEARANCE_PX
    and the post's radius at the target's depth)."""

    obstacle: Obstacle
    hull: np.ndarray
    distance: float
    near: Mask
    post: Mask | None


def _sighted(obstacles: list[Obstacle], view: np.ndarray, K: np.ndarray, width: int, height: int
             ) -> list[_Sighted]:
    """The obstacles some vertex of which is in front of the camera at ``view`` (T_cam_world), as it sees them."""
    out = []
    for obstacle in obstacles:
        silhouette = hull(project(obstacle.vertices, view, K))
        if len(silhouette) == 0:
            continue
        distance = obstacle.vertices.mean(axis=0) @ view[2, :3] + view[2, 3]
        post = (Mask.near(silhouette, width, height, CLEARANCE_PX + POST_RADIUS_MM * K[0, 0] / max(distance, NEAR_MM))
                if obstacle.hidden_matters else None)
        out.append(_Sighted(obstacle, silhouette, distance, Mask.near(silhouette, width, height, CLEARANCE_PX), post))
    return out


@dataclass(frozen=True)
class _Camera:
    """What the criteria ask of the camera and the boards: the pinhole (K (3, 3), width, height px), its lens
    (focused at ``focus_mm``, ``camera``'s depth of field, its own blur ``blur_sigma_px``) and the boards' squares
    (squares_x, squares_y) and markers (``marker_cells`` bit cells across, ``marker_share`` of a square)."""

    K: np.ndarray
    width: int
    height: int
    focus_mm: float
    camera: object
    blur_sigma_px: float
    squares: tuple[int, int]
    marker_cells: float
    marker_share: float


class _View:
    """The candidates ``idx`` (k,) of ``c`` at one pose (``view``: T_cam_world), beside the obstacles ``sighted`` there.

    The image tests of the criteria (on the image, on an obstacle's grown hull) run only on the candidates whose
    image can reach what they test: where the paper's corners are all in front of the camera (``bounded``), every
    point of the board in front of it projects inside their hull, within its bounding box ``low``-``high`` (k, 2 px)
    (and a post's inside its ends'); the other candidates pass those tests, as they would pixel by pixel."""

    def __init__(self, c: Candidates, idx: np.ndarray, view: np.ndarray, sighted: list[_Sighted], cam: _Camera,
                 board_depth: np.ndarray | None = None):
        self.c, self.idx, self.view, self.sighted, self.cam = c, idx, view, sighted, cam
        self.corners = c.on_board(PAPER, c.paper, idx)  # (k, 4, 3) the paper's
        self.quad, self.front = pixels(self.corners, view, cam.K)
        self.low, self.high = _least(self.quad), _most(self.quad)
        edges = np.roll(self.quad, -1, axis=1) - self.quad
        area = np.abs(np.sum(self.quad[..., 0] * edges[..., 1] - self.quad[..., 1] * edges[..., 0], axis=1)) / 2
        # a board seen edge on (no area) is tested point by point: a point on its line is "inside" the quad
        self.bounded = self.front.all(axis=1) & (area > 1.0)
        # the boards' centres' depths (k,), unless given
        self.board_depth = c.centre[idx] @ view[2, :3] + view[2, 3] if board_depth is None else board_depth

    def subset(self, keep: np.ndarray) -> _View:
        return _View(self.c, self.idx[keep], self.view, self.sighted, self.cam)

    def lattice(self, which: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pixels (j, l, 2) of the squares' corners (:func:`~.board_candidates.lattice`) of the candidates ``which``
        (a mask, j of them), and whether each is in front of the camera (j, l)."""
        return pixels(self.c.on_board(lattice(self.cam.squares), self.c.pattern, self.idx[which]), self.view,
                       self.cam.K)

    def shown(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Criteria 1 and 3 (not yet what obstacles hide): ok (k,), which squares' corners are in the image (k, l)
        and the blur (k, px) at the board's nearest or farthest corner."""
        c, cam, view = self.c, self.cam, self.view
        width, height = cam.width, cam.height
        pattern, pattern_front = pixels(c.on_board(PAPER, c.pattern, self.idx), view, cam.K)
        depth = self.corners @ view[2, :3] + view[2, 3]  # (k, 4)
        # the squares' corners lie in the pattern's image where its corners are in front of the camera: all in the
        # image where that is inside the image's edges by a pixel (and the paper in front by a millimetre), none
        # where it lies a pixel beyond one
        low, high, whole = _least(pattern), _most(pattern), pattern_front.all(axis=1)
        inside = (whole & (_least(depth) > NEAR_MM + 1.0) & (low >= 1.0).all(axis=1) & (high[:, 0] <= width - 2)
                  & (high[:, 1] <= height - 2))
        beyond = whole & ((high[:, 0] < -1.0) | (low[:, 0] > width) | (high[:, 1] < -1.0) | (low[:, 1] > height))
        in_image = np.repeat(inside[:, None], len(lattice(cam.squares)), axis=1)
        rest = ~inside & ~beyond
        points, points_front = self.lattice(rest)
        in_image[rest] = (points_front & (points[..., 0] >= 0) & (points[..., 0] <= width - 1)
                          & (points[..., 1] >= 0) & (points[..., 1] <= height - 1))
        # the blur at the board's nearest and farthest corners against a marker's bit cell where the pattern's
        # outline is shortest in the image (far and foreshortened)
        blur = _most(np.hypot(cam.blur_sigma_px, defocus_sigma_px(np.clip(depth, NEAR_MM, None), cam.focus_mm,
                                                                   cam.camera)))
        sides = _length(np.roll(pattern, -1, axis=1) - pattern) / np.array(cam.squares * 2, float)
        cell = _least(sides) * cam.marker_share / cam.marker_cells
        ok = (whole & (corners_found(in_image, cam.squares).sum(axis=1) >= MIN_PLAN_CORNERS)
              & (cell >= MIN_CELL_PX) & (blur <= FOCUS_BLUR_PER_CELL * cell))
        return ok, in_image, blur

    def found(self, in_image: np.ndarray) -> np.ndarray:
        """(k, m) which inner corners are found: their squares' corners in the image (``in_image`` (k, l)) and off
        every obstacle nearer than the board (on its grown hull: criterion 2)."""
        good = in_image.copy()
        for sighted in self.sighted:
            hides = ~(self.board_depth < sighted.distance) & (~self.bounded | sighted.near.reaches(self.low, self.high))
            if hides.any():
                good[hides] &= ~sighted.near.on(*self.lattice(hides))
        return corners_found(good, self.cam.squares)

    def covers(self) -> np.ndarray:
        """(k,) whether each board covers a target (criterion 2): where its outline, sampled at most OUTLINE_STEP_PX
        apart along the longest edge of all k papers in the image, falls on the target's grown hull, a vertex of
        the hull lies inside its paper, or its post falls on the hull grown by the post's radius, and the board is
        nearer (their centres' depths)."""
        c, K, view = self.c, self.cam.K, self.view
        quad, front = self.quad, self.front
        edge_px = np.nanmax(_length(np.roll(quad, -1, axis=1) - quad)[front.all(axis=1)], initial=0.0)
        s = np.linspace(-0.5, 0.5, int(np.ceil(min(edge_px, 4 * self.cam.width) / OUTLINE_STEP_PX)) + 2)
        outline = np.vstack([np.column_stack([s, np.full_like(s, e)]) for e in (-0.5, 0.5)]
                            + [np.column_stack([np.full_like(s, e), s]) for e in (-0.5, 0.5)])
        top = c.post_top[self.idx]
        post_ends, post_front = pixels(np.stack([top * np.array([1.0, 1.0, 0.0]), top], axis=1), view, K)
        post_low, post_high, post_bounded = _least(post_ends), _most(post_ends), post_front.all(axis=1)
        covers = np.zeros(len(self.idx), bool)
        for sighted in self.sighted:  # each test on the boards that do not cover a target yet
            if not sighted.obstacle.hidden_matters:
                continue
            nearer = self.board_depth < sighted.distance
            paper = np.flatnonzero(nearer & ~covers & (~self.bounded | sighted.near.reaches(self.low, self.high)))
            covers[paper] = _touched(sighted.near, c, outline, c.paper, self.idx[paper], view, K)
            paper = paper[~covers[paper]]
            covers[paper] = vertices_inside(quad[paper], sighted.hull)
            post = np.flatnonzero(nearer & ~covers & (~post_bounded | sighted.post.reaches(post_low, post_high)))
            covers[post] = sighted.post.on(*pixels(c.post(self.idx[post]), view, K)).any(axis=1)
        return covers


def judge(c: Candidates, poses: list[np.ndarray], obstacles: list[Obstacle], squares: tuple[int, int],
          marker_cells: float, marker_share: float, K: np.ndarray, width: int, height: int, focus_mm: float,
          camera, blur_sigma_px: float) -> Judged:
    """Criteria 1-3 of the module docstring, and the sigma_t of criterion 4 (:mod:`.board_sigma`), for every
    candidate at every pose (``poses``: T_world_cam (4, 4); the others as :func:`~.board_plan.plan_boards` takes
    them). Criterion 2 in two parts: where a
    board and an obstacle overlap in the image (the board's outline, sampled at most OUTLINE_STEP_PX apart, on the
    obstacle's hull grown by CLEARANCE_PX, or a hull vertex inside it; its post likewise), the nearer one
    covers the other (their centres' depths): a board covering a target is dropped, one covered does not serve that
    pose. A candidate failing 1-3 at pose 0 (model image 0) is dropped too (``alive`` False).

    In two passes: first which candidates stay, pose by pose in order (the outline's samples follow the longest
    edge among the candidates still alive), then, for those alone, what they serve at every pose."""
    n, p = len(c.centre), len(poses)
    m = (squares[0] - 1) * (squares[1] - 1)
    cam = _Camera(K, width, height, focus_mm, camera, blur_sigma_px, squares, marker_cells, marker_share)
    alive = c.on_board(PAPER, c.paper, np.ones(n, bool))[..., 2].min(axis=1) >= TABLE_CLEARANCE_MM
    # per pose: T_cam_world, the obstacles seen, the boards' depths (numpy's (k, 3) @ (3,) rounds a single row
    # otherwise than more: the second pass takes them from the first, which had the boards then alive)
    views, sighted, depths = [], [], np.full((p, n), np.nan)
    for k, T_world_cam in enumerate(poses):
        if not alive.any():
            break
        views.append(inverse(T_world_cam))
        sighted.append(_sighted(obstacles, views[k], K, width, height))
        at = _View(c, np.flatnonzero(alive), views[k], sighted[k], cam)
        if k == 0:  # 1 and 3 first, on the pattern's and the paper's corners: in model image 0 they drop most
            ok, in_image, _ = at.shown()
            alive[at.idx[~ok]] = False
            at, in_image = at.subset(ok), in_image[ok]
            alive[at.idx] = ~at.covers() & (at.found(in_image).sum(axis=1) >= MIN_PLAN_CORNERS)
        else:
            alive[at.idx] = ~at.covers()
        depths[k, at.idx] = at.board_depth
    served = np.zeros((n, p), bool)
    sigma_t = np.full((n, p), np.inf)
    noises = np.full((n, p), np.nan)
    visible = np.zeros((n, p, m), bool)
    idx = np.flatnonzero(alive)
    inner = inner_corners(squares)
    for k, (view, sight) in enumerate(zip(views, sighted)):
        at = _View(c, idx, view, sight, cam, depths[k, idx])
        ok, in_image, blur = at.shown()
        seen = at.found(in_image)
        ok &= seen.sum(axis=1) >= MIN_PLAN_CORNERS
        # 4: the board pose's predicted sigma_t at its origin from its inner corners found, at the corner noise of
        # this blur
        noise = corner_noise_px(blur[ok])
        served[idx, k] = ok
        noises[idx[ok], k] = noise
        visible[idx[ok], k] = seen[ok]
        sigma_t[idx[ok], k] = noise * unit_sigma_t(c.on_board(inner, c.pattern, idx[ok]), c.origin[idx[ok]], view, K,
                                                   seen[ok])
    return Judged(alive, served, sigma_t, noises, visible)


def corners_found(good: np.ndarray, squares: tuple[int, int]) -> np.ndarray:
    """(k, m) which inner corners of each board are found: those whose four squares (the 3 x 3 lattice points
    about them, ``good`` (k, lattice) of :func:`~.board_candidates.lattice`) are all in the image and uncovered: a
    ChArUco corner is interpolated from the markers of the squares about it."""
    sx, sy = squares
    grid = good.reshape(len(good), sy + 1, sx + 1)
    rows = grid[:, :-2] & grid[:, 1:-1] & grid[:, 2:]  # (k, sy - 1, sx + 1): three rows about each inner row
    return (rows[:, :, :-2] & rows[:, :, 1:-1] & rows[:, :, 2:]).reshape(len(good), (sy - 1) * (sx - 1))


def _least(a: np.ndarray) -> np.ndarray:
    """a.min(axis=1), the same values: numpy reduces along a short axis slowly, the minima of its slices fast."""
    return functools.reduce(np.minimum, np.moveaxis(a, 1, 0))


def _most(a: np.ndarray) -> np.ndarray:
    """a.max(axis=1), the same values (:func:`_least`)."""
    return functools.reduce(np.maximum, np.moveaxis(a, 1, 0))


def _length(v: np.ndarray) -> np.ndarray:
    """np.linalg.norm(v, axis=-1) of 2-vectors (..., 2), to the bit (sqrt(x x + y y)), without its reduction."""
    return np.sqrt(v[..., 0] * v[..., 0] + v[..., 1] * v[..., 1])


def _touched(mask: Mask, c: Candidates, fractions: np.ndarray, of: np.ndarray, keep: np.ndarray, view: np.ndarray,
             K: np.ndarray) -> np.ndarray:
    """(k,) whether any of the board-plane points of each candidate ``keep`` (k,) (fractions (m, 2) of the size ``of``
    (n, 2): :meth:`~.board_candidates.Candidates.on_board`) falls on ``mask`` at ``view`` (T_cam_world):
    :meth:`~.image_polygons.Mask.on` of their pixels, each board's looked at until one does."""
    out = np.empty(len(keep), bool)
    _touched_at(c.centre, c.x_b, c.y_b, of, keep, fractions, view, K, mask.pixels, mask.u0, mask.v0, out)
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _touched_at(centre, x_b, y_b, of, keep, fractions, view, K, pixels, u0, v0, touched):
    """touched (k,) of :func:`_touched`."""
    for a in range(len(keep)):
        touched[a] = False
        for j in range(len(fractions)):
            p0, p1, p2 = board_point(centre, x_b, y_b, of, keep[a], fractions[j])
            u, v, front = project_point(p0, p1, p2, view, K)
            if on_pixel(u, v, front, pixels, u0, v0):
                touched[a] = True
                break
