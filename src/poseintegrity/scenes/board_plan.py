"""How a lab places and sizes the ground-truth boards of a scene (``generate.board.placement: planned``; issue 39).

The lab looks at its camera's live image at every commanded pose of the scene's session (the robot's program is
known before any data is taken) and stands ChArUco boards on posts beside the target. A board *serves* a trajectory
when at model image 0 (whose board pose places M_t, IV-C) and at every stop of it (arcs to their last stop, lines to
their far stop) at least MIN_PLAN_CORNERS of its inner corners are found, no target covers it and it is in focus
(criteria 1-3, :mod:`.board_criteria`), and its pose is predicted within ``plan_sigma_t_mm`` by even stage 02's own
estimate of it (criterion 4, :mod:`.board_sigma`); the board never covers a target or another board, at any pose of
the session, served or not.

The candidates (:mod:`.board_candidates`): every size of ``generate.board.sizes_mm`` at board centres on a grid about
the aim point, turned and tilted; a candidate that fails 1-3 in model image 0 is dropped. Chosen, by the
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

from dataclasses import dataclass

import numba
import numpy as np
from scipy.spatial import ConvexHull

from poseintegrity.poses import inverse
from poseintegrity.scenes.board_candidates import PAPER, Candidates, candidate_grid, inner_corners, placement_of
from poseintegrity.scenes.board_criteria import Judged, Obstacle, judge
from poseintegrity.scenes.board_sigma import estimate_spread, handover_sigma_t
from poseintegrity.scenes.board_stand import BoardPlacement, PlacementError
from poseintegrity.scenes.image_polygons import overlap, pixels

SIGMA_STEP_MM = 0.01  # predicted sigma_t closer than this count as equal: the lever arm decides
PAIR_POOL = 25  # pairs: each of the 25 best single boards with the 25 boards apart from it that best complete it


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
    blur_sigma_px : the lens' own blur. Raises :class:`~.board_stand.PlacementError` naming ``where`` when no
    candidate stands clear of the targets and whole in model image 0."""
    obstacles = [Obstacle(o.vertices[ConvexHull(o.vertices).vertices], o.hidden_matters)  # the same image hulls
                 for o in obstacles]
    poses, index = _unique_poses([model_pair[:1], *[model_pair[:1] + t for t in trajectories], model_pair[1:]])
    index = index[1:-1]  # a trajectory's: model image 0 (its board pose places M_t) and its stops
    criteria = (obstacles, squares, marker_cells, marker_share, K, width, height, focus_mm, camera, blur_sigma_px)
    c = candidate_grid(sizes_mm, squares, margin_mm, aim, model_pair[0], target_centre)
    c = c.subset(judge(c, poses[:1], *criteria).alive)  # model image 0 drops most, cheaply: the rest judged alone
    judged = judge(c, poses, *criteria)
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
        planned.append(PlannedBoard(float(c.square[i]), b * (squares[0] * squares[1] // 2),
                                    placement_of(c, i, in_view), float(sigma)))
    return BoardPlan(tuple(planned), board_of, unserved)


def _first_apart(c: Candidates, alive: np.ndarray, a: int, order: np.ndarray, views: np.ndarray, K: np.ndarray
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
    share 1 - TRUSTED_SHARE of frames by the corners found (:func:`~.board_sigma.estimate_spread`), and ``ok``, served
    within ``limit_mm`` by the board alone; per alive candidate and trajectory: ``failing``, the poses it does not serve
    so, and ``worst``, its worst predicted sigma_t; ``lever``: from its origin to the target (mm)."""

    def __init__(self, c: Candidates, judged: Judged, poses: list[np.ndarray], index: list[np.ndarray],
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
        """(p,) :func:`~.board_sigma.handover_sigma_t` at board ``own``'s origin from board ``other``'s corners
        (indices into alive) where ``own`` alone does not serve and ``other`` does, computed once per ordered pair (a
        pool board and one of those it is tried with may meet again the other way round)."""
        if (own, other) not in self.handovers:
            c, judged, b = self.c, self.judged, self.alive[other]
            corners = c.on_board(inner_corners(self.squares), c.pattern, np.array([b]))[0]
            self.handovers[own, other] = handover_sigma_t(
                corners, c.origin[self.alive[own]], self.views, self.K, ~self.ok[own] & judged.served[b],
                judged.noise[b], judged.visible[b], self.spread)
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


def _worst_in_view(c: Candidates, i: int, poses: list[np.ndarray], K: np.ndarray, width: int, height: int) -> float:
    """The share of board ``i``'s paper inside the image at the worst of ``poses`` (a 10 x 8 grid on it)."""
    gx, gy = np.meshgrid(np.linspace(-0.45, 0.45, 10), np.linspace(-0.45, 0.45, 8))
    keep = np.arange(len(c.centre)) == i
    grid = c.on_board(np.column_stack([gx.ravel(), gy.ravel()]), c.paper, keep)
    shares = []
    for T in poses:
        uv, front = pixels(grid, inverse(T), K)
        shares.append(float((front & (uv[..., 0] >= 0) & (uv[..., 0] <= width - 1) & (uv[..., 1] >= 0)
                             & (uv[..., 1] <= height - 1)).mean()))
    return min(shares, default=1.0)


def _apart(c: Candidates, first: np.ndarray, second: np.ndarray, views: np.ndarray, K: np.ndarray
           ) -> np.ndarray:
    """(m, n) whether each board of ``first`` (m,) and each of ``second`` (n,) stay apart in the image at every
    pose (``views`` (p, 4, 4): T_cam_world): neither paper overlaps the other's paper, nor the other's post (a segment
    from its foot to its top), with CLEARANCE_PX to spare, so that neither covers the other wherever it serves."""
    apart = np.empty((len(first), len(second)), bool)
    _apart_at(*_outlines(c, first, views, K), *_outlines(c, second, views, K), apart)
    return apart


def _outlines(c: Candidates, boards: np.ndarray, views: np.ndarray, K: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per pose (``views`` (p, 4, 4): T_cam_world) the images of the boards' papers (p, k, 4, 2) and posts (p, k, 2,
    2: foot, top), and whether each board is in the image (p, k): a board partly behind the camera is not."""
    (papers, paper_front), (posts, post_front) = (pixels(points, views, K) for points in (
        c.on_board(PAPER, c.paper, boards), c.post(boards, 2)))
    return papers, posts, paper_front.all(axis=-1) & post_front.all(axis=-1)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _apart_at(papers_1, posts_1, seen_1, papers_2, posts_2, seen_2, apart):
    """apart (m, n) of :func:`_apart` from the boards' :func:`_outlines` (m and n boards), a pair's poses looked at
    until its boards overlap."""
    for i in range(apart.shape[0]):
        for j in range(apart.shape[1]):
            apart[i, j] = True
            for p in range(len(papers_1)):
                if seen_1[p, i] and seen_2[p, j] and (overlap(papers_1[p, i], papers_2[p, j])
                                                      or overlap(papers_1[p, i], posts_2[p, j])
                                                      or overlap(posts_1[p, i], papers_2[p, j])):
                    apart[i, j] = False
                    break
