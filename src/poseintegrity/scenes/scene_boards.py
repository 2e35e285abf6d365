"""The ground-truth boards of a laid-out scene (``generate.board.placement``): one lying flat beside the target
(``flat``, :func:`flat_board`) or boards standing on posts (:func:`standing_boards`: ``facing_camera``,
:mod:`.board_placement`; ``planned``, :mod:`.board_plan`), as printed sheets (:func:`~.printed_boards.print_errors`)
with their posts, and what clutter must keep clear of. World frame: table top z = 0, z up, mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from poseintegrity.boards import Board
from poseintegrity.params.generate import GenerateParams, SceneSpec
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.poses import pose_matrix
from poseintegrity.scenes import board_placement, board_plan, board_stand
from poseintegrity.scenes import mesh as meshes
from poseintegrity.scenes import textures as tex
from poseintegrity.scenes.board_criteria import Obstacle
from poseintegrity.scenes.camera import Intrinsics
from poseintegrity.scenes.printed_boards import print_errors, printed_name
from poseintegrity.scenes.trajectories import arc_trajectories, line_trajectories

BOARD_BELOW_AIM_MM = 60.0  # the board's pedestal brings it this far below the aim point (never below the table)


@dataclass(frozen=True)
class SceneBoard:
    """One ground-truth board of a scene: as printed from its drawing (``drawing``, :mod:`poseintegrity.boards`) and
    as the lab measured it (``board``, :func:`~.printed_boards.measured_board`), its frame T_world_board (4, 4, mm),
    where it stands (``placement``; None when it lies flat) and its worst predicted sigma_t (mm) over the stops it
    serves (planned boards; NaN otherwise)."""

    drawing: Board
    board: Board
    T_world_board: np.ndarray
    placement: board_stand.BoardPlacement | None = None
    sigma_t_mm: float = float("nan")


def drawings(params: "GenerateParams", plan: board_plan.BoardPlan) -> list[Board]:
    """The drawing of each board of a plan: the params' board printed at its square size, ids from its first."""
    return [params.board.drawing(square_mm=b.square_mm, first_id=b.first_id) for b in plan.boards]


def board_texture_name(k: int) -> str:
    """The texture of a scene's k-th board (the first: ``board``)."""
    return "board" if k == 0 else f"board_{k + 1}"


def _board_sheet(params: "GenerateParams", board: Board, k: int = 0) -> meshes.Mesh:
    """The printed board (its drawing) in its own frame (x right, y down, facing -z, origin at the pattern's top-left
    corner), as printed: scaled and bowed (:func:`~.printed_boards.print_errors`), textured with the scene's k-th
    board texture (:func:`board_texture_name`). The plane spans the texture's texel centres (the renderer maps texture
    coordinates 0 and 1 onto its edges): a plane of the print's full size would stretch the board by n / (n - 1)
    texels (calibration_views.py)."""
    bw, bh = board.size_mm
    n_x, n_y = tex.board_texture(board, params.board.px_per_mm, params.board.margin_mm).shape[::-1]
    sheet = meshes.plane((n_x - 1) / params.board.px_per_mm, (n_y - 1) / params.board.px_per_mm, 12, 9,
                         board_texture_name(k), material=meshes.Material(0.02, 10.0))
    # plane() faces +z with texture v along -y; flip about x so it faces -z (the printed side) with v along +y
    sheet = sheet.transformed(pose_matrix(np.diag([1.0, -1.0, -1.0]), [bw / 2, bh / 2, 0.0]))
    return meshes.printed_sheet(sheet, np.array([bw / 2, bh / 2]), (n_x - 1) / params.board.px_per_mm / 2,
                                *print_errors(params, printed_name(params, board),
                                              params.printed_boards.board_sag_std_mm))


def flat_board(params: "GenerateParams", board: Board, board_yaw: float, T_world_target: np.ndarray, yaw: float,
               aim: np.ndarray, view_dir: np.ndarray) -> tuple[np.ndarray, list[tuple[str, meshes.Mesh]], np.ndarray]:
    """Placement ``flat``: the board lies beside the target, printed side up (board z
    points down), on the table or, beside a held phantom, on a pedestal BOARD_BELOW_AIM_MM below the aim point; board x
    points away from the target, so that its origin (the model origin, where E_t is measured) is a corner of the edge
    facing the target. Returns T_world_board, the meshes, the board's centre on the table (2,)."""
    bw, bh = board.size_mm
    m = params.board.margin_mm
    x_b = np.array([np.cos(board_yaw), np.sin(board_yaw), 0.0])
    R_world_board = np.column_stack([x_b, np.cross([0.0, 0.0, -1.0], x_b), [0.0, 0.0, -1.0]])
    toward_cam = view_dir[:2] / np.linalg.norm(view_dir[:2])
    board_centre = T_world_target[:2, 3] - 92.0 * np.array([np.cos(yaw), np.sin(yaw)]) + 20.0 * toward_cam
    height = max(aim[2] - BOARD_BELOW_AIM_MM, 0.0)
    objects = []
    if height > 0:
        pedestal = meshes.box((bw + 2 * m, bh + 2 * m, height), "clutter_b", n_sub=4)
        objects.append(("board_pedestal", pedestal.transformed(pose_matrix(R_world_board @ np.diag([1.0, -1.0, -1.0]),
                                                                             [*board_centre, height / 2]))))
    origin = np.append(board_centre, height + 0.4) - R_world_board @ np.array([bw / 2, bh / 2, 0.0])
    T_world_board = pose_matrix(R_world_board, origin)
    objects.append(("board", _board_sheet(params, board).transformed(T_world_board)))
    return T_world_board, objects, board_centre


def standing_boards(params: "GenerateParams", protocol: "ProtocolParams", spec: "SceneSpec", session: str,
                     placed: list[tuple[str, meshes.Mesh]], aim: np.ndarray, view_dir: np.ndarray,
                     plan: board_plan.BoardPlan | None):
    """Placements ``planned`` (:mod:`.board_plan`) and ``facing_camera`` (:mod:`.board_placement`): boards on posts,
    facing the session's model camera, clear of the targets along every trajectory of the session (``plan``, when
    given, is where they were found). Returns the plan, the meshes (boards, posts) and what clutter must keep clear
    of: each board's paper corners (4, 3) and the session's poses."""
    cam = Intrinsics.from_params(params.camera)
    if session == "line":
        lines = params.lines
        focus = lines.focus_mm(protocol.line_length_mm)
        pair, trajectories = line_trajectories(aim, view_dir, lines.distance_mm, params.model_baseline_mm,
                                               lines.offsets_deg, protocol.line_length_mm, lines.n_stops)
    else:
        focus = spec.distance_mm
        pair, trajectories = arc_trajectories(aim, view_dir, focus, params.model_baseline_mm, params.arcs.azimuths_deg,
                                              protocol.arc_span_deg, params.arcs.n_stops)
    if plan is None:
        plan = _plan(params, spec, placed, aim, pair, trajectories, cam, focus)
    objects, papers = [], []
    m = params.board.margin_mm
    for k, (planned, drawing) in enumerate(zip(plan.boards, drawings(params, plan))):
        T, where = planned.placement.T_world_board, planned.placement
        post = meshes.cylinder(board_stand.POST_RADIUS_MM, float(where.post_top[2]), "clutter_c")
        suffix = "" if k == 0 else f"_{k + 1}"
        objects += [(f"board{suffix}", _board_sheet(params, drawing, k).transformed(T)),
                    (f"board_post{suffix}", post.transformed(pose_matrix(np.eye(3), where.post_foot)))]
        bw, bh = drawing.size_mm
        papers.append((T[:3, :3] @ np.array([[-m, -m, 0], [bw + m, -m, 0], [bw + m, bh + m, 0], [-m, bh + m, 0]]).T
                       ).T + T[:3, 3])
    poses = [*pair] + [T for trajectory in trajectories for T in trajectory]
    return plan, objects, (papers, poses)


def _plan(params: "GenerateParams", spec: "SceneSpec", placed: list[tuple[str, meshes.Mesh]], aim: np.ndarray,
          pair: list[np.ndarray], trajectories: list[list[np.ndarray]], cam: Intrinsics,
          focus_mm: float) -> board_plan.BoardPlan:
    """Where the session's boards stand: :func:`.board_plan.plan_boards` (``planned``) or one board of the params'
    size where most of it stays in view (``facing_camera``, :func:`.board_placement.place_board`)."""
    targets = [mesh.vertices for name, mesh in placed if name in spec.targets]
    where = f"scene {spec.name}"
    board = params.board
    if board.placement == "facing_camera":
        poses = [*pair] + [T for trajectory in trajectories for T in trajectory]
        placement = board_placement.place_board(board.drawing().size_mm, board.margin_mm, targets, aim, poses[0],
                                                poses, cam.K, cam.width, cam.height, where)
        return board_plan.BoardPlan((board_plan.PlannedBoard(board.square_mm, 0, placement, float("nan")),),
                                    (0,) * len(trajectories), (0,) * len(trajectories))
    obstacles = [Obstacle(v, True) for v in targets] + [
        Obstacle(mesh.vertices, False) for name, mesh in placed
        if name.endswith("_stand") and name.removesuffix("_stand") in spec.targets]
    cells = board.drawing().cv_board().getDictionary().markerSize + 2  # its bits and the black border
    return board_plan.plan_boards(board.sizes_mm, (board.squares_x, board.squares_y), board.marker_mm / board.square_mm,
                                  cells, board.margin_mm, board.max_boards, board.plan_sigma_t_mm, obstacles,
                                  targets[0].mean(axis=0), aim, pair, trajectories, cam.K, cam.width, cam.height,
                                  focus_mm,
                                  params.camera, params.sensor.blur_sigma_px, where)
