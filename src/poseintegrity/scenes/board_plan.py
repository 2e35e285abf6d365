"""How a lab places and sizes the ground-truth boards of a scene (``generate.board.placement: planned``; issue 39).

The lab looks at its camera's live image at every commanded pose of the scene's session (the robot's program is
known before any data is taken) and stands ChArUco boards on posts beside the target. A board *serves* a trajectory
when at model image 0 (whose board pose places M_t, IV-C) and at every stop of it (arcs to their last stop, lines to
their far stop):

1. **at least MIN_PLAN_CORNERS of its inner corners are found**: a ChArUco corner is interpolated from the markers of
   the four squares about it, so a corner counts when those squares' corners (its 3 x 3 neighbourhood of the board's
   lattice) all lie inside the image, in front of the camera, and off every nearer obstacle (criterion 2). The white
   margin around the pattern may leave the image: the detector never reads it (tests/scenes/test_board_plan.py: a
   board cut by the image's edge two squares in gives the 12 corners counted here, OpenCV's detector finds them). The
   plan first asked for the whole pattern in view: on the main world at one image per stop that left 93.5 % of frames
   trusted and every arc whose board stood near the image's edge late unserved, where this rule reaches 97.5 % (R11
   p99 0.354 mm against 0.419 mm), and stage 02 judges a frame by the corners it finds (issue 39);
2. **no target covers it**: where the board and a target (or a target's stand, or another board) overlap in the
   image (its outline, sampled at most OUTLINE_STEP_PX apart, on the other's silhouette hull grown by CLEARANCE_PX,
   or a hull vertex inside it), the nearer of the two covers the other; and the board **never covers a target** or
   another board, at any pose of the session, served or not (a candidate that would is dropped);
3. **it is in focus**: the lens is focused once per session (:mod:`.optics`), so the blur of the
   board's nearest or farthest corner, hypot(the lens' own blur, the defocus), must stay within FOCUS_BLUR_PER_CELL of
   a marker's bit cell where the pattern is smallest in the image (far, foreshortened), and a bit cell must span at
   least MIN_CELL_PX, or its markers are not read (the lines' far stops of issue 30);
4. **its pose is predicted within ``plan_sigma_t_mm``**: the covariance s^2 (J^T J)^-1 of the board pose from the
   inner corners found (the same prediction as stage 02's trust rule, :mod:`poseintegrity.localization.ground_truth`), J
   the Jacobian of the corners' projections at the commanded pose, s the corner noise CORNER_NOISE_PX grown by the
   blur; sigma_t is its RMS at the board origin, where E_t is measured (IV-C). Stage 02 trusts a pose by its own
   estimate of that sigma_t, from the residual scale s^2 = SSR / (2n - 6) of the n corners it fits; with Gaussian
   corner noise (2n - 6) s^2 / sigma^2 is chi-square with 2n - 6 degrees of freedom (docs/references.md), so the
   estimate exceeds the prediction by sqrt(chi2_q(2n - 6) / (2n - 6)) in a share 1 - q of frames (1.18 for 24
   corners at q = TRUSTED_SHARE). A stop is served where even that estimate stays within ``plan_sigma_t_mm``
   (without this margin, the frames of stops predicted within 0.128-0.15 mm were trusted in 90 % of both worlds'
   frames at one image per stop, those below in 92-96 %; stage 02's estimate over the plan's: median 0.76-0.81, 95th
   percentile 1.15-1.21, as sqrt(chi2_0.95(42) / 42) = 1.18).

The candidates: every size of ``generate.board.sizes_mm`` (squares_x x squares_y squares, the markers scaled alike),
at board centres on a grid in the model camera's frame about the aim point (GRID_RIGHT_MM, GRID_UP_MM in the image,
PLAN_TOWARDS_MM towards the camera), long side across the image or upright, facing the model camera or turned from it
by PLAN_TILTS_DEG (a planar target seen face on is its worst-conditioned pose: its tilt trades for its distance), the
origin at the corner nearest the first target. A candidate that fails 1-3 in model image 0 is dropped. Chosen, by the
trajectories served, then the fewest poses not served, then the worst predicted sigma_t over what it serves (to
SIGMA_STEP_MM), then the shortest lever arm from its origin to the target:

- the best single board; and, where it does not serve every trajectory and ``max_boards`` is 2,
- the best pair of boards that stand apart in the image at every pose (neither paper overlaps the other's paper or
  post): each of the PAIR_POOL best single boards with the PAIR_POOL boards apart from it that leave the fewest poses
  served by neither, when the pair is better. Within a pair a trajectory takes the board that serves it best, the
  other taking over at the poses where its own fails (a handover, :func:`~poseintegrity.localization.ground_truth.
  handed_over`: the camera's motion read from the other board, carried to the own board's origin, with the other's
  rotation error times the lever arm between them added). The second board's marker ids follow the first's: the
  detector never mixes them.

Each trajectory (dataset) takes one board, the one that serves it best (the first on a tie): its origin is the
dataset's model origin, M_t is placed by that board's pose in model image 0, and E_t and R11 are measured at that
origin, as with one board; the scene's other board is written beside it (meta.json ``handover_boards``), for the
frames where only that one is found. A trajectory no board serves wholly takes the one that fails the fewest of its
poses (``BoardPlan.unserved`` counts them); stage 02 then says which frames are not judged. Deterministic: no random
draw.

Issue 49 made the plan 20 x faster and left every plan as it was, to the bit (tests/scenes/
test_board_plans_unchanged.py, benchmarks/bench_board_plan.py): the candidates that stay are found first and only
they are judged at every pose, an image test runs only where a board's image can reach what it tests, the pairs
are looked for down each board's order until PAIR_POOL stand apart, and the per-point work runs in numba kernels
that round as numpy and OpenBLAS did (their comments say how; they read CLEARANCE_PX and NEAR_MM when compiled).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import cv2
import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic
from scipy.spatial import ConvexHull
from scipy.stats import chi2

from poseintegrity.poses import inverse, pose_matrix
from poseintegrity.scenes.board_placement import (
    CLEARANCE_PX, GRID_RIGHT_MM, GRID_UP_MM, NEAR_MM, POST_BEHIND_MM, POST_RADIUS_MM, TABLE_CLEARANCE_MM,
    BoardPlacement, PlacementError, near_targets, project, vertices_inside,
)
from poseintegrity.scenes.optics import defocus_sigma_px

# Measured on the renders of studies/board_options.py (ChArUco boards, 960 frames of issue 30's and this plan's
# boards): the corner noise the trust rule sees, s = sqrt(SSR / (2n - 6)), is 0.055-0.065 px (median) on sharp boards
# and grows with the blur to 0.10-0.13 px at a blur sigma of 2-2.7 px, as hypot(a, b x blur sigma). With
# (0.068, 0.038) px the predicted sigma_t is at least the measured one in 95 % of the 506 frames whose board was
# wholly in view, in focus and found with 20 or more corners (the measured one is 0.51-1.21 x, median 0.76 x, the
# predicted one). Boards whose bit cells are 3 px or more and blurred by at most 0.35 of a cell were found with 20 or
# more corners in 92-100 % of frames; beyond 0.5 of a cell in none.
CORNER_NOISE_PX = (0.068, 0.038)
PLAN_TOWARDS_MM = (-60.0, -30.0, 0.0, 30.0, 60.0)  # board centres from the aim point towards the camera
# the board turned from facing the model camera by (about the image's x axis: 0, about its y axis: 1, deg): a board
# seen face on is the worst-conditioned planar pose (its tilt trades for its distance, Schweighofer and Pinz 2006); a
# lab tilts it
PLAN_TILTS_DEG = ((0, 0.0), (0, 25.0), (0, -25.0), (0, 40.0), (0, -40.0), (1, 25.0), (1, -25.0), (1, 40.0), (1, -40.0))
FOCUS_BLUR_PER_CELL = 0.35
MIN_CELL_PX = 3.0  # below 3 px bit cells a quarter to a half of the boards lost their markers
MIN_PLAN_CORNERS = 12  # a board serves a pose only with half its 24 inner corners found or more
SIGMA_STEP_MM = 0.01  # predicted sigma_t closer than this count as equal: the lever arm decides
PAIR_POOL = 25  # pairs: each of the 25 best single boards with the 25 boards apart from it that best complete it
OUTLINE_STEP_PX = 10.0  # outline samples at most this far apart: less than 2 CLEARANCE_PX, so a crossing is caught
TRUSTED_SHARE = 0.95  # of a served stop's frames stage 02 should trust (issue 39's target share of trusted frames)
SINGULAR_COND = 1e12  # an information matrix this ill-conditioned predicts nothing: sigma_t inf


@dataclass(frozen=True)
class PlannedBoard:
    """One board of a scene's plan: squares of ``square_mm``, marker ids from ``first_id``, where it stands, and its
    worst predicted sigma_t (mm, at the board origin) over the stops of the trajectories it serves."""

    square_mm: float
    first_id: int
    placement: BoardPlacement
    sigma_t_mm: float


@dataclass(frozen=True)
class BoardPlan:
    """The boards of one scene and session, per trajectory (in the order given) the index of its board, and how many
    of the trajectory's poses (model image 0 and its stops) that board does not serve (0: every one)."""

    boards: tuple[PlannedBoard, ...]
    board_of: tuple[int, ...]
    unserved: tuple[int, ...]


@dataclass
class _Candidates:
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

    def subset(self, keep: np.ndarray) -> _Candidates:
        """The candidates ``keep`` (a mask or indices) alone."""
        return _Candidates(self.centre[keep], self.x_b[keep], self.y_b[keep], self.z_b[keep], self.pattern[keep],
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


def _candidates(sizes_mm: list[float], squares: tuple[int, int], margin_mm: float, aim: np.ndarray,
                T_world_model: np.ndarray, target_centre: np.ndarray) -> _Candidates:
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
    return _Candidates(centre, x_b, y_b, np.cross(x_b, y_b), pattern, square, pattern + 2 * margin_mm)


@dataclass
class _Judged:
    """Per candidate (n) and pose (p): ``alive`` (n,): whole, in focus and uncovered in model image 0 and covering
    nothing at any pose; for the candidates alive (the others are left False, inf, NaN): ``served`` (n, p): criteria
    1-3 hold; ``sigma_t`` (n, p) predicted (inf where not served); ``noise`` (n, p): the corner noise (px) at that
    pose's blur (NaN where not served); ``visible`` (n, p, m): which of its m inner corners are found there."""

    alive: np.ndarray
    served: np.ndarray
    sigma_t: np.ndarray
    noise: np.ndarray
    visible: np.ndarray


PAPER = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])


@dataclass(frozen=True)
class Obstacle:
    """An object near the board: its vertices (k, 3, world mm), and whether the board may never stand in front of
    it (a target) or only must not stand behind it where it serves (a target's stand)."""

    vertices: np.ndarray
    hidden_matters: bool


@dataclass(frozen=True)
class _Mask:
    """Image pixels near an obstacle (:func:`~.board_placement.near_targets`), kept as their bounding box: ``pixels``
    (rows, columns) from pixel column ``u0`` and row ``v0`` (outside it the whole image's mask is False)."""

    pixels: np.ndarray
    u0: int
    v0: int

    @classmethod
    def near(cls, hull: np.ndarray, width: int, height: int, clearance_px: float) -> _Mask:
        """The pixels within ``clearance_px`` of an image hull (h, 2)."""
        mask = near_targets([hull], width, height, clearance_px)
        rows, columns = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
        if len(rows) == 0:
            return cls(np.zeros((0, 0), bool), 0, 0)
        return cls(mask[rows[0]:rows[-1] + 1, columns[0]:columns[-1] + 1], int(columns[0]), int(rows[0]))

    def reaches(self, low: np.ndarray, high: np.ndarray) -> np.ndarray:
        """(k,) whether boxes from ``low`` to ``high`` (k, 2: u, v px) come within a pixel of the mask's: a point
        rounds onto a pixel of the mask only from within half a pixel of it."""
        rows, columns = self.pixels.shape
        return ((high[:, 0] >= self.u0 - 1) & (low[:, 0] <= self.u0 + columns) & (high[:, 1] >= self.v0 - 1)
                & (low[:, 1] <= self.v0 + rows))

    def on(self, points: np.ndarray, front: np.ndarray) -> np.ndarray:
        """(k, l) whether each point (k, l, 2 px) in front of the camera (``front`` (k, l)) falls on the mask, rounded
        to its pixel."""
        on = np.empty(front.shape, bool)
        _on_mask(points, front, self.pixels, self.u0, self.v0, on)
        return on

    def touched(self, c: _Candidates, fractions: np.ndarray, of: np.ndarray, keep: np.ndarray, view: np.ndarray,
                K: np.ndarray) -> np.ndarray:
        """(k,) whether any of the board-plane points of each candidate ``keep`` (k,) (:meth:`_Candidates.on_board`)
        falls on the mask at ``view`` (T_cam_world): :meth:`on` of their pixels, each board's looked at until one
        does."""
        touched = np.empty(len(keep), bool)
        _touched(c.centre, c.x_b, c.y_b, of, keep, fractions, view, K, self.pixels, self.u0, self.v0, touched)
        return touched


@dataclass(frozen=True)
class _Sighted:
    """An obstacle in one pose's image: its hull (h, 2 px), its depth (its vertices' mean, mm), the pixels within
    CLEARANCE_PX of it (``near``) and, for a target, those a post in front of it must keep off (``post``: CLEARANCE_PX
    and the post's radius at the target's depth)."""

    obstacle: Obstacle
    hull: np.ndarray
    distance: float
    near: _Mask
    post: _Mask | None


def _sighted(obstacles: list[Obstacle], view: np.ndarray, K: np.ndarray, width: int, height: int
             ) -> list[_Sighted]:
    """The obstacles some vertex of which is in front of the camera at ``view`` (T_cam_world), as it sees them."""
    out = []
    for obstacle in obstacles:
        hull = _hull(project(obstacle.vertices, view, K))
        if len(hull) == 0:
            continue
        distance = obstacle.vertices.mean(axis=0) @ view[2, :3] + view[2, 3]
        post = (_Mask.near(hull, width, height, CLEARANCE_PX + POST_RADIUS_MM * K[0, 0] / max(distance, NEAR_MM))
                if obstacle.hidden_matters else None)
        out.append(_Sighted(obstacle, hull, distance, _Mask.near(hull, width, height, CLEARANCE_PX), post))
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

    def __init__(self, c: _Candidates, idx: np.ndarray, view: np.ndarray, sighted: list[_Sighted], cam: _Camera,
                 board_depth: np.ndarray | None = None):
        self.c, self.idx, self.view, self.sighted, self.cam = c, idx, view, sighted, cam
        self.corners = c.on_board(PAPER, c.paper, idx)  # (k, 4, 3) the paper's
        self.quad, self.front = _pixels(self.corners, view, cam.K)
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
        """Pixels (j, l, 2) of the squares' corners (:func:`_lattice`) of the candidates ``which`` (a mask, j of
        them), and whether each is in front of the camera (j, l)."""
        return _pixels(self.c.on_board(_lattice(self.cam.squares), self.c.pattern, self.idx[which]), self.view,
                       self.cam.K)

    def shown(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Criteria 1 and 3 (not yet what obstacles hide): ok (k,), which squares' corners are in the image (k, l)
        and the blur (k, px) at the board's nearest or farthest corner."""
        c, cam, view = self.c, self.cam, self.view
        width, height = cam.width, cam.height
        pattern, pattern_front = _pixels(c.on_board(PAPER, c.pattern, self.idx), view, cam.K)
        depth = self.corners @ view[2, :3] + view[2, 3]  # (k, 4)
        # the squares' corners lie in the pattern's image where its corners are in front of the camera: all in the
        # image where that is inside the image's edges by a pixel (and the paper in front by a millimetre), none
        # where it lies a pixel beyond one
        low, high, whole = _least(pattern), _most(pattern), pattern_front.all(axis=1)
        inside = (whole & (_least(depth) > NEAR_MM + 1.0) & (low >= 1.0).all(axis=1) & (high[:, 0] <= width - 2)
                  & (high[:, 1] <= height - 2))
        beyond = whole & ((high[:, 0] < -1.0) | (low[:, 0] > width) | (high[:, 1] < -1.0) | (low[:, 1] > height))
        in_image = np.repeat(inside[:, None], len(_lattice(cam.squares)), axis=1)
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
        ok = (whole & (_seen(in_image, cam.squares).sum(axis=1) >= MIN_PLAN_CORNERS)
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
        return _seen(good, self.cam.squares)

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
        post_ends, post_front = _pixels(np.stack([top * np.array([1.0, 1.0, 0.0]), top], axis=1), view, K)
        post_low, post_high, post_bounded = _least(post_ends), _most(post_ends), post_front.all(axis=1)
        covers = np.zeros(len(self.idx), bool)
        for sighted in self.sighted:  # each test on the boards that do not cover a target yet
            if not sighted.obstacle.hidden_matters:
                continue
            nearer = self.board_depth < sighted.distance
            paper = np.flatnonzero(nearer & ~covers & (~self.bounded | sighted.near.reaches(self.low, self.high)))
            covers[paper] = sighted.near.touched(c, outline, c.paper, self.idx[paper], view, K)
            paper = paper[~covers[paper]]
            covers[paper] = vertices_inside(quad[paper], sighted.hull)
            post = np.flatnonzero(nearer & ~covers & (~post_bounded | sighted.post.reaches(post_low, post_high)))
            covers[post] = sighted.post.on(*_pixels(c.post(self.idx[post]), view, K)).any(axis=1)
        return covers


def _judge(c: _Candidates, poses: list[np.ndarray], obstacles: list[Obstacle], squares: tuple[int, int],
           marker_cells: float, marker_share: float, K: np.ndarray, width: int, height: int, focus_mm: float,
           camera, blur_sigma_px: float) -> _Judged:
    """Criteria 1-4 of the module docstring for every candidate at every pose. Criterion 2 in two parts: where a
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
    inner = _inner(squares)
    for k, (view, sight) in enumerate(zip(views, sighted)):
        at = _View(c, idx, view, sight, cam, depths[k, idx])
        ok, in_image, blur = at.shown()
        seen = at.found(in_image)
        ok &= seen.sum(axis=1) >= MIN_PLAN_CORNERS
        # 4: the board pose's predicted sigma_t at its origin from its inner corners found, at the corner noise of
        # this blur
        noise = np.hypot(CORNER_NOISE_PX[0], CORNER_NOISE_PX[1] * blur[ok])
        served[idx, k] = ok
        noises[idx[ok], k] = noise
        visible[idx[ok], k] = seen[ok]
        sigma_t[idx[ok], k] = noise * _unit_sigma_t(c.on_board(inner, c.pattern, idx[ok]), c.origin[idx[ok]], view, K,
                                                    seen[ok])
    return _Judged(alive, served, sigma_t, noises, visible)


def _least(a: np.ndarray) -> np.ndarray:
    """a.min(axis=1), the same values: numpy reduces along a short axis slowly, the minima of its slices fast."""
    return functools.reduce(np.minimum, np.moveaxis(a, 1, 0))


def _most(a: np.ndarray) -> np.ndarray:
    """a.max(axis=1), the same values (:func:`_least`)."""
    return functools.reduce(np.maximum, np.moveaxis(a, 1, 0))


def _length(v: np.ndarray) -> np.ndarray:
    """np.linalg.norm(v, axis=-1) of 2-vectors (..., 2), to the bit (sqrt(x x + y y)), without its reduction."""
    return np.sqrt(v[..., 0] * v[..., 0] + v[..., 1] * v[..., 1])


def _lattice(squares: tuple[int, int]) -> np.ndarray:
    """((squares_y + 1) (squares_x + 1), 2) the corners of a board's squares, its outline's included, as fractions of
    its pattern about the centre, row by row."""
    sx, sy = squares
    return np.array([[i / sx - 0.5, j / sy - 0.5] for j in range(sy + 1) for i in range(sx + 1)])


def _seen(good: np.ndarray, squares: tuple[int, int]) -> np.ndarray:
    """(k, m) which inner corners of each board are found: those whose four squares (the 3 x 3 lattice points
    about them, ``good`` (k, lattice) of :func:`_lattice`) are all in the image and uncovered: a ChArUco corner is
    interpolated from the markers of the squares about it."""
    sx, sy = squares
    grid = good.reshape(len(good), sy + 1, sx + 1)
    rows = grid[:, :-2] & grid[:, 1:-1] & grid[:, 2:]  # (k, sy - 1, sx + 1): three rows about each inner row
    return (rows[:, :, :-2] & rows[:, :, 1:-1] & rows[:, :, 2:]).reshape(len(good), (sy - 1) * (sx - 1))


def _inner(squares: tuple[int, int]) -> np.ndarray:
    """(m, 2) a board's inner (chessboard) corners as fractions of its pattern about the centre."""
    sx, sy = squares
    return np.array([[(i + 1) / sx - 0.5, (j + 1) / sy - 0.5] for j in range(sy - 1) for i in range(sx - 1)])


def _handover_sigma_t(c: _Candidates, judged: _Judged, a: int, b: int, views: np.ndarray,
                      squares: tuple[int, int], K: np.ndarray, need: np.ndarray, spread: np.ndarray) -> np.ndarray:
    """(p,) the sigma_t (mm) at board ``a``'s origin of a frame judged by board ``b`` (a handover: stage 02 carries
    the camera's motion since model image 0, read from b, to a's origin, :func:`~poseintegrity.localization.
    ground_truth.handed_over`): hypot of what b's corners found, at their corner noise, predict for a's origin at the
    pose (``views`` (p, 4, 4): T_cam_world) and at model image 0 (pose 0), times ``spread`` (by the corners found,
    :func:`estimate_spread`); inf where b does not serve the pose, or where ``need`` (p,) is False."""
    out = np.full(len(views), np.inf)
    at = np.flatnonzero(judged.served[b] & need)
    if len(at):
        poses = np.concatenate([[0], at])
        corners = c.on_board(_inner(squares), c.pattern, np.array([b]))
        unit = _unit_sigma_t(np.repeat(corners, len(poses), axis=0), np.repeat(c.origin[[a]], len(poses), axis=0),
                             views[poses], K, judged.visible[b, poses])
        sigma = judged.noise[b, poses] * unit
        out[at] = np.hypot(sigma[1:], sigma[0]) * spread[judged.visible[b, at].sum(axis=1)]
    return out


def _hull(points: np.ndarray) -> np.ndarray:
    """The convex hull (m, 2) of image points (k, 2) (those behind the camera already left out; a post seen end on
    is a line)."""
    return cv2.convexHull(points.astype(np.float32)).reshape(-1, 2) if len(points) else points



def _unit_sigma_t(corners: np.ndarray, origin: np.ndarray, view: np.ndarray, K: np.ndarray,
                  seen: np.ndarray | None = None) -> np.ndarray:
    """(k,) RMS error (mm) of the board origin predicted from the corners (k, m, 3, world) at unit pixel noise:
    sqrt(trace of the translation block of (J^T J)^-1), J (2m, 6) the Jacobian of the corners' pixels with respect to
    a small rotation about the camera origin and the translation of the board (the translation block does not
    depend on how the rotation is parametrized: OpenCV's rvec gives the same). ``view``: T_cam_world (4, 4), or one
    per board (k, 4, 4); ``seen`` (k, m): the corners found (default: all). J^T J compiled (:func:`_information`),
    inverted by numpy's LAPACK."""
    if len(corners) == 0:
        return np.empty(0)
    views = np.ascontiguousarray(np.broadcast_to(view, (len(corners), 4, 4)))
    seen = np.ones(corners.shape[:2], bool) if seen is None else seen
    information = np.zeros((len(corners), 6, 6))
    _information(corners, origin, views, K[0, 0], K[1, 1], seen, information)
    covariance = np.empty_like(information)
    try:
        covariance[...] = np.linalg.inv(information)
        # cond = |A|_2 |A^-1|_2 <= |A|_F |A^-1|_F: the SVD (np.linalg.cond) only where this bound does not rule it out
        with np.errstate(over="ignore"):
            doubt = ~(np.linalg.norm(information, axis=(1, 2)) * np.linalg.norm(covariance, axis=(1, 2))
                      <= SINGULAR_COND / 10)
    except np.linalg.LinAlgError:  # one is singular to the bit
        doubt = np.ones(len(corners), bool)
    singular = np.zeros(len(corners), bool)
    if doubt.any():
        singular[doubt] = np.linalg.cond(information[doubt]) > SINGULAR_COND
        information[singular] = np.eye(6)
        covariance[doubt] = np.linalg.inv(information[doubt])
    return np.where(singular, np.inf, np.sqrt(np.clip(np.trace(covariance[:, 3:, 3:], axis1=1, axis2=2), 0.0, None)))


@intrinsic
def _fma(typingctx, a, b, c):
    """a b + c rounded once (LLVM's fma): OpenBLAS's kernels multiply and add so."""
    def codegen(context, builder, signature, args):
        double = ir.DoubleType()
        return builder.call(builder.module.declare_intrinsic("llvm.fma", [double],
                                                             ir.FunctionType(double, [double] * 3)), args)

    return types.float64(types.float64, types.float64, types.float64), codegen


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA unasked
def _to_camera(p0, p1, p2, view):
    """The world point (p0, p1, p2) in the camera frame of ``view`` (T_cam_world), as numpy's ``points @ R.T + t``
    computes it: the product by the rotation as OpenBLAS's kernels do, fused multiply-adds from zero, term by term,
    then the translation added."""
    return (_fma(p2, view[0, 2], _fma(p1, view[0, 1], _fma(p0, view[0, 0], 0.0))) + view[0, 3],
            _fma(p2, view[1, 2], _fma(p1, view[1, 1], _fma(p0, view[1, 0], 0.0))) + view[1, 3],
            _fma(p2, view[2, 2], _fma(p1, view[2, 1], _fma(p0, view[2, 0], 0.0))) + view[2, 3])


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA unasked
def _project(p0, p1, p2, view, K):
    """(u, v, in front of the camera) of the world point (p0, p1, p2) at ``view`` (T_cam_world), as
    :func:`~.board_placement.pixels` computes them, to the bit."""
    x, y, z = _to_camera(p0, p1, p2, view)
    front = z > NEAR_MM
    z = z if front else 1.0
    return K[0, 0] * x / z + K[0, 2], K[1, 1] * y / z + K[1, 2], front


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA
def _board_point(centre, x_b, y_b, of, i, fraction):
    """World point (3 floats) of the board-plane point ``fraction`` (2,) of the size of[i] about candidate i's centre,
    in numpy's order of operations (:meth:`_Candidates.on_board`): the centre, plus the offset along x_b, plus the
    offset along y_b."""
    u, v = fraction[0] * of[i, 0], fraction[1] * of[i, 1]
    return (centre[i, 0] + u * x_b[i, 0] + v * y_b[i, 0], centre[i, 1] + u * x_b[i, 1] + v * y_b[i, 1],
            centre[i, 2] + u * x_b[i, 2] + v * y_b[i, 2])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _on_board_at(centre, x_b, y_b, of, keep, fractions, points):
    """points (k, m, 3) of :meth:`_Candidates.on_board` (``keep``: indices)."""
    for a in range(len(keep)):
        for j in range(len(fractions)):
            points[a, j, 0], points[a, j, 1], points[a, j, 2] = _board_point(centre, x_b, y_b, of, keep[a],
                                                                             fractions[j])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _on_pixel(u, v, front, pixels, u0, v0):
    """Whether the image point (u, v px), in front of the camera (``front``), rounds (half to even, as np.round) onto
    a True pixel of ``pixels`` (rows, columns), a mask's box from column u0 and row v0."""
    if not front:
        return False
    u, v = np.rint(u) - u0, np.rint(v) - v0
    return 0 <= u < pixels.shape[1] and 0 <= v < pixels.shape[0] and pixels[int(v), int(u)]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _on_mask(uv, front, pixels, u0, v0, on):
    """on (k, l) of :meth:`_Mask.on`."""
    for k in range(uv.shape[0]):
        for l in range(uv.shape[1]):
            on[k, l] = _on_pixel(uv[k, l, 0], uv[k, l, 1], front[k, l], pixels, u0, v0)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _touched(centre, x_b, y_b, of, keep, fractions, view, K, pixels, u0, v0, touched):
    """touched (k,) of :meth:`_Mask.touched`."""
    for a in range(len(keep)):
        touched[a] = False
        for j in range(len(fractions)):
            p0, p1, p2 = _board_point(centre, x_b, y_b, of, keep[a], fractions[j])
            u, v, front = _project(p0, p1, p2, view, K)
            if _on_pixel(u, v, front, pixels, u0, v0):
                touched[a] = True
                break


def _pixels(points: np.ndarray, view: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~.board_placement.pixels` (k, m, 2) of world points (k, m, 3) at ``view`` (T_cam_world (4, 4), or one
    per pose (p, 4, 4): then (p, k, m, 2)), to the bit, and whether each is in front of the camera (k, m or p, k, m)."""
    views = view.reshape(-1, 4, 4)
    uv, front = np.empty((len(views), *points.shape[:2], 2)), np.empty((len(views), *points.shape[:2]), bool)
    _pixels_at(points, views, K, uv, front)
    return (uv, front) if view.ndim == 3 else (uv[0], front[0])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _pixels_at(points, views, K, uv, front):
    """uv (p, k, m, 2), front (p, k, m) of :func:`_pixels`."""
    for p in range(len(views)):
        for k in range(points.shape[0]):
            for m in range(points.shape[1]):
                uv[p, k, m, 0], uv[p, k, m, 1], front[p, k, m] = _project(points[k, m, 0], points[k, m, 1],
                                                                          points[k, m, 2], views[p], K)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _apart_at(papers_1, posts_1, seen_1, papers_2, posts_2, seen_2, apart):
    """apart (m, n) of :func:`_apart` from the boards' :func:`_outlines` (m and n boards), a pair's poses looked at
    until its boards overlap."""
    for i in range(apart.shape[0]):
        for j in range(apart.shape[1]):
            apart[i, j] = True
            for p in range(len(papers_1)):
                if seen_1[p, i] and seen_2[p, j] and (_overlap(papers_1[p, i], papers_2[p, j])
                                                      or _overlap(papers_1[p, i], posts_2[p, j])
                                                      or _overlap(posts_1[p, i], papers_2[p, j])):
                    apart[i, j] = False
                    break


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA
def _overlap(a, b):
    """Whether the convex polygons a (p, 2) and b (q, 2) (a segment when 2 points) come within CLEARANCE_PX of each
    other: no separating axis among their edges' normals (the separating axis theorem)."""
    return not (_separates(a, b) or _separates(b, a))


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA
def _separates(a, b):
    """Whether along the normal of an edge of polygon a (p, 2) polygon b (q, 2) lies more than CLEARANCE_PX beyond
    it. The normal is the edge turned by 90 deg over its length (at least 1e-9), each projection the sum of two
    products, in this order."""
    for e in range(len(a)):
        nx, ny = -(a[(e + 1) % len(a), 1] - a[e, 1]), a[(e + 1) % len(a), 0] - a[e, 0]
        length = max(np.sqrt(nx * nx + ny * ny), 1e-9)
        nx, ny = nx / length, ny / length
        own_low, own_high, other_low, other_high = np.inf, -np.inf, np.inf, -np.inf
        for q in range(len(a)):
            d = nx * a[q, 0] + ny * a[q, 1]
            own_low, own_high = min(own_low, d), max(own_high, d)
        for q in range(len(b)):
            d = nx * b[q, 0] + ny * b[q, 1]
            other_low, other_high = min(other_low, d), max(other_high, d)
        if max(other_low - own_high, own_low - other_high) > CLEARANCE_PX:
            return True
    return False


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float64, no reassociation or FMA unasked
def _information(corners, origin, views, fx, fy, seen, out):
    """out (k, 6, 6, zeros) += J^T J of :func:`_unit_sigma_t` for corners (k, m, 3), origins (k, 3), views
    (k, 4, 4), focal lengths fx, fy px and the corners found (k, m), to the bit as numpy computed them with matrix
    products (the camera frame, :func:`_to_camera`; d(pixel)/d(point) times -[r]_x: OpenBLAS's fused multiply-adds
    from zero, term by term) and an einsum over the corners (the products summed in order from zero). A corner not
    found (its rows of J times 0) adds only zeros to a sum that is never -0: skipped."""
    J = np.empty((2, 6))
    for n in range(corners.shape[0]):
        t0, t1, t2 = _to_camera(origin[n, 0], origin[n, 1], origin[n, 2], views[n])
        for i in range(corners.shape[1]):
            if not seen[n, i]:
                continue
            X, Y, Z = _to_camera(corners[n, i, 0], corners[n, i, 1], corners[n, i, 2], views[n])
            r0, r1, r2 = X - t0, Y - t1, Z - t2  # before Z is clipped
            Z = max(Z, NEAR_MM)
            # d(pixel)/d(point) (2, 3): [[fx / Z, 0, -fx X / Z^2], [0, fy / Z, -fy Y / Z^2]]; times -[r]_x, whose
            # diagonal is -0.0 (the negated zeros of [r]_x)
            for row in range(2):
                if row == 0:
                    d0, d1, d2 = fx / Z, 0.0, -fx * X / (Z * Z)
                else:
                    d0, d1, d2 = 0.0, fy / Z, -fy * Y / (Z * Z)
                J[row, 0] = _fma(d2, r1, _fma(d1, -r2, _fma(d0, -0.0, 0.0)))
                J[row, 1] = _fma(d2, -r0, _fma(d1, -0.0, _fma(d0, r2, 0.0)))
                J[row, 2] = _fma(d2, -0.0, _fma(d1, r0, _fma(d0, -r1, 0.0)))
                J[row, 3], J[row, 4], J[row, 5] = d0, d1, d2
            for row in range(2):
                for a in range(6):
                    for b in range(a, 6):
                        out[n, a, b] = out[n, a, b] + J[row, a] * J[row, b]
        for a in range(6):
            for b in range(a):
                out[n, a, b] = out[n, b, a]


def _placement(c: _Candidates, i: int, in_view: float) -> BoardPlacement:
    top = c.post_top[i]
    return BoardPlacement(pose_matrix(np.column_stack([c.x_b[i], c.y_b[i], c.z_b[i]]), c.origin[i]),
                          top * np.array([1.0, 1.0, 0.0]), top, in_view)


def _apart(c: _Candidates, first: np.ndarray, second: np.ndarray, views: np.ndarray, K: np.ndarray
           ) -> np.ndarray:
    """(m, n) whether each board of ``first`` (m,) and each of ``second`` (n,) stay apart in the image at every
    pose (``views`` (p, 4, 4): T_cam_world): neither paper overlaps the other's paper, nor the other's post (a segment
    from its foot to its top), with CLEARANCE_PX to spare, so that neither covers the other wherever it serves."""
    apart = np.empty((len(first), len(second)), bool)
    _apart_at(*_outlines(c, first, views, K), *_outlines(c, second, views, K), apart)
    return apart


def _outlines(c: _Candidates, boards: np.ndarray, views: np.ndarray, K: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per pose (``views`` (p, 4, 4): T_cam_world) the images of the boards' papers (p, k, 4, 2) and posts (p, k, 2,
    2: foot, top), and whether each board is in the image (p, k): a board partly behind the camera is not."""
    (papers, paper_front), (posts, post_front) = (_pixels(points, views, K) for points in (
        c.on_board(PAPER, c.paper, boards), c.post(boards, 2)))
    return papers, posts, paper_front.all(axis=-1) & post_front.all(axis=-1)


def plan_boards(sizes_mm: list[float], squares: tuple[int, int], marker_share: float, marker_cells: float,
                margin_mm: float, max_boards: int, plan_sigma_t_mm: float, obstacles: list[Obstacle],
                target_centre: np.ndarray, aim: np.ndarray, model_pair: list[np.ndarray],
                trajectories: list[list[np.ndarray]], K: np.ndarray, width: int, height: int, focus_mm: float,
                camera, blur_sigma_px: float, where: str) -> BoardPlan:
    """The boards of one scene and session (module docstring).

    sizes_mm : square sizes to choose from; squares : (squares_x, squares_y); marker_share : marker / square;
    marker_cells : a marker's bit cells across (its bits and the black border); margin_mm : white paper around the
    pattern; obstacles : the targets and their stands, what the boards must not cover or be covered by;
    target_centre (3,) : where the lever arm is measured to; model_pair : the session's model images' T_world_cam
    (4, 4) (the first orients the boards; in the second a board only must cover no target); trajectories : per
    trajectory the commanded T_world_cam of its stops; K (3, 3), width, height : the camera (pinhole of its true
    intrinsics); focus_mm : where the lens is focused; camera : ``generate.camera`` (its depth of field);
    blur_sigma_px : the lens' own blur. Raises :class:`~.board_placement.PlacementError` naming ``where`` when no
    candidate stands clear of the targets and whole in model image 0."""
    obstacles = [Obstacle(o.vertices[ConvexHull(o.vertices).vertices], o.hidden_matters)  # the same image hulls
                 for o in obstacles]
    poses, index = _unique_poses([model_pair[:1], *[model_pair[:1] + t for t in trajectories], model_pair[1:]])
    index = index[1:-1]  # a trajectory's: model image 0 (its board pose places M_t) and its stops
    judge = (obstacles, squares, marker_cells, marker_share, K, width, height, focus_mm, camera, blur_sigma_px)
    c = _candidates(sizes_mm, squares, margin_mm, aim, model_pair[0], target_centre)
    c = c.subset(_judge(c, poses[:1], *judge).alive)  # model image 0 drops most, cheaply: the rest judged alone
    judged = _judge(c, poses, *judge)
    if not judged.alive.any():
        raise PlacementError(
            f"{where}: no place beside the target keeps a board of {min(sizes_mm):g}-{max(sizes_mm):g} mm squares "
            f"wholly in model image 0 and clear of the targets along every trajectory; smaller "
            f"generate.board.sizes_mm, a larger distance_mm, fewer or smaller targets (generate.scapula.length_mm) "
            f"would leave room")
    ranking = _Ranking(c, judged, poses, index, squares, K, plan_sigma_t_mm, target_centre)
    singles = ranking.singles()
    chosen = (int(singles[0]),)
    best = ranking.rank(chosen)
    service = _Service((0,) * len(index), tuple(int(f) for f in ranking.failing[chosen[0]]))
    if max_boards > 1 and ranking.failing[chosen[0]].any():
        # a pair: each of the best boards alone with the boards apart from it that leave the fewest poses unserved
        # by either (what a handover could at best reach), the best PAIR_POOL of them tried
        alive, ok, lever = ranking.alive, ranking.ok, ranking.lever
        for a in (int(k) for k in singles[:PAIR_POOL]):
            either = np.stack([(~(ok[a, i] | ok[:, i])).sum(axis=1) for i in index], axis=1)  # (alive, trajectories)
            order = np.lexsort((lever, either.sum(axis=1), -(either == 0).sum(axis=1)))
            for b in _first_apart(c, alive, a, order[order != a], ranking.views, K):
                ranked, served = ranking.pair(a, b)
                if ranked < best:
                    chosen, best, service = (a, b), ranked, served
    board_of, unserved = service
    planned = []
    for b, k in enumerate(chosen):
        served = [t for t in range(len(index)) if board_of[t] == b]
        sigma = max((ranking.worst[k, t] for t in served if not ranking.failing[k, t]), default=float("nan"))
        i = ranking.alive[k]
        in_view = _worst_in_view(c, i, [poses[p] for t in served for p in index[t]], K, width, height)
        planned.append(PlannedBoard(float(c.square[i]), b * (squares[0] * squares[1] // 2), _placement(c, i, in_view),
                                    float(sigma)))
    return BoardPlan(tuple(planned), board_of, unserved)


def _first_apart(c: _Candidates, alive: np.ndarray, a: int, order: np.ndarray, views: np.ndarray, K: np.ndarray
                 ) -> list[int]:
    """The first PAIR_POOL boards of ``order`` (indices into ``alive``, the candidates' indices) that stay apart from
    board ``a`` (:func:`_apart`), looked at in blocks twice as long each time (the boards best completing ``a`` are
    often beside it: hundreds may overlap it before PAIR_POOL stand apart)."""
    found, start, size = [], 0, PAIR_POOL
    while len(found) < PAIR_POOL and start < len(order):
        block = order[start:start + size]
        found += [int(b) for b in block[_apart(c, alive[[a]], alive[block], views, K)[0]]]
        start, size = start + size, 2 * size
    return found[:PAIR_POOL]


class _Ranking:
    """How well the candidates that stay alive (``alive``: their indices into ``c``) serve the trajectories (``index``:
    per trajectory its poses' indices into ``poses``), alone (:meth:`rank`) and in pairs (:meth:`pair`).

    Per alive candidate and pose: ``sigma``, the predicted sigma_t times what stage 02's estimate of it reaches in a
    share 1 - TRUSTED_SHARE of frames by the corners found (:func:`estimate_spread`), and ``ok``, served within
    ``limit_mm`` by the board alone; per alive candidate and trajectory: ``failing``, the poses it does not serve so,
    and ``worst``, its worst predicted sigma_t; ``lever``: from its origin to the target (mm)."""

    def __init__(self, c: _Candidates, judged: _Judged, poses: list[np.ndarray], index: list[np.ndarray],
                 squares: tuple[int, int], K: np.ndarray, limit_mm: float, target_centre: np.ndarray):
        self.c, self.judged, self.index, self.squares, self.K = c, judged, index, squares, K
        self.limit_mm = limit_mm
        self.views = np.array([inverse(T) for T in poses])  # T_cam_world (p, 4, 4)
        self.alive = alive = np.flatnonzero(judged.alive)
        self.spread = np.array([estimate_spread(n) if n > 3 else np.inf for n in range(judged.visible.shape[2] + 1)])
        self.sigma = judged.sigma_t[alive] * self.spread[judged.visible[alive].sum(axis=2)]
        self.ok = judged.served[alive] & (self.sigma <= limit_mm)  # (alive, poses)
        self.failing = np.stack([(~self.ok[:, i]).sum(axis=1) for i in index], axis=1)  # (alive, trajectories)
        self.worst = np.stack([judged.sigma_t[alive][:, i].max(axis=1) for i in index], axis=1)
        self.lever = np.linalg.norm(c.origin[alive] - target_centre, axis=1)
        self.handovers: dict[tuple[int, int], np.ndarray] = {}  # :meth:`handover`'s

    def singles(self) -> np.ndarray:
        """The alive candidates (indices into alive) ordered by :meth:`rank` of each alone, best first."""
        whole = self.failing == 0  # (alive, trajectories)
        worst = np.round(np.where(whole, self.worst, 0.0).max(axis=1) / SIGMA_STEP_MM)  # 0 where none is served
        return np.lexsort((np.arange(len(self.alive)), self.lever, worst, self.failing.sum(axis=1), -whole.sum(axis=1)))

    def rank(self, boards: tuple[int, ...]) -> tuple:
        """A single board (index into alive) is better the more trajectories it serves, the fewer poses it fails,
        the smaller its worst predicted sigma_t (to SIGMA_STEP_MM) and the shorter its lever arm."""
        fails = self.failing[list(boards)].min(axis=0)
        served = [self.worst[boards[0], t] for t in range(len(self.index)) if not fails[t]]
        return (-int((fails == 0).sum()), int(fails.sum()), np.round(max(served, default=0.0) / SIGMA_STEP_MM),
                float(self.lever[list(boards)].sum()), boards)

    def handover(self, own: int, other: int) -> np.ndarray:
        """(p,) :func:`_handover_sigma_t` of board ``own`` from board ``other`` (indices into alive) where ``own``
        alone does not serve, computed once per ordered pair (a pool board and one of those it is tried with may
        meet again the other way round)."""
        if (own, other) not in self.handovers:
            self.handovers[own, other] = _handover_sigma_t(
                self.c, self.judged, self.alive[own], self.alive[other], self.views, self.squares, self.K,
                ~self.ok[own] & self.judged.served[self.alive[other]], self.spread)
        return self.handovers[own, other]

    def pair(self, a: int, b: int) -> tuple[tuple, _Service]:
        """Per trajectory the board of the two (indices into alive) that, with the other taking over where it fails
        (the handover), fails the fewest of its poses (model image 0 by its own board: its pose places M_t); ranked
        as :meth:`rank` ranks a single board."""
        ok, sigma = self.ok, self.sigma
        via = {(own, other): self.handover(own, other) for own, other in ((a, b), (b, a))}
        primary, fails, sigmas = [], [], []
        for t, i in enumerate(self.index):
            options = []
            for k, (own, other) in enumerate(((a, b), (b, a))):
                effective = np.where(ok[own, i], sigma[own, i], via[own, other][i])
                effective[0] = sigma[own, i[0]] if ok[own, i[0]] else np.inf
                options.append((int((effective > self.limit_mm).sum()), int(self.failing[own, t]), k, effective))
            f, _, k, effective = min(options, key=lambda o: o[:3])
            primary.append(k)
            fails.append(f)
            sigmas.append(effective.max() if f == 0 else 0.0)
        fails_ = np.array(fails)
        return ((-int((fails_ == 0).sum()), int(fails_.sum()), np.round(max(sigmas, default=0.0) / SIGMA_STEP_MM),
                 float(self.lever[[a, b]].sum()), (a, b)), _Service(tuple(primary), tuple(fails)))


@dataclass(frozen=True)
class _Service:
    """Per trajectory the board whose origin it takes (index into the chosen boards) and the poses left unserved."""

    board_of: tuple[int, ...]
    unserved: tuple[int, ...]

    def __iter__(self):
        return iter((self.board_of, self.unserved))


def estimate_spread(n_corners: int, share: float = TRUSTED_SHARE) -> float:
    """How far stage 02's estimate of a pose's sigma_t exceeds the true one in a share 1 - ``share`` of frames: the
    quantile sqrt(chi2_share(2n - 6) / (2n - 6)) of s / sigma, s^2 = SSR / (2n - 6) the residual variance of a pose
    fitted to ``n_corners`` points with Gaussian noise (6 parameters; module docstring, criterion 4)."""
    dof = 2 * n_corners - 6
    return float(np.sqrt(chi2.ppf(share, dof) / dof))


def _unique_poses(trajectories: list[list[np.ndarray]]) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """The distinct poses of the trajectories (model image 0 first, then the poses furthest from it first: there
    candidates fail most) and per trajectory the indices (into them) of its poses."""
    keys, poses = {}, []
    for trajectory in trajectories:
        for T in trajectory:
            if T.tobytes() not in keys:
                keys[T.tobytes()] = len(poses)
                poses.append(T)
    far = np.argsort([-np.linalg.norm(T[:3, 3] - poses[0][:3, 3]) for T in poses], kind="stable")
    order = np.concatenate([[0], far[far != 0]])
    rank = np.empty(len(order), int)
    rank[order] = np.arange(len(order))
    return [poses[k] for k in order], [np.array([rank[keys[T.tobytes()]] for T in t]) for t in trajectories]


def _worst_in_view(c: _Candidates, i: int, poses: list[np.ndarray], K: np.ndarray, width: int, height: int) -> float:
    """The share of board ``i``'s paper inside the image at the worst of ``poses`` (a 10 x 8 grid on it)."""
    gx, gy = np.meshgrid(np.linspace(-0.45, 0.45, 10), np.linspace(-0.45, 0.45, 8))
    keep = np.arange(len(c.centre)) == i
    grid = c.on_board(np.column_stack([gx.ravel(), gy.ravel()]), c.paper, keep)
    shares = []
    for T in poses:
        uv, front = _pixels(grid, inverse(T), K)
        shares.append(float((front & (uv[..., 0] >= 0) & (uv[..., 0] <= width - 1) & (uv[..., 1] >= 0)
                             & (uv[..., 1] <= height - 1)).mean()))
    return min(shares, default=1.0)
