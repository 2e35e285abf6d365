"""How the lab plans a scene's ground-truth boards (scenes/board_plan.py, issue 39), checked against geometry and
detection of our own: the board issue 30's rule stands leaves the image late in an arc, the plan's board keeps at
least MIN_PLAN_CORNERS inner corners in view at every stop of the trajectories it serves, and rendered where the other
left the view it is found whole and trusted; where one board cannot serve every trajectory the plan adds a second
with marker ids of its own, apart from the first."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from poseintegrity.config import load_params
from poseintegrity.lens import Camera
from poseintegrity.localization.ground_truth import board_pose
from poseintegrity.poses import inverse
from poseintegrity.scenes import board_criteria, optics, renderer, world_cache
from poseintegrity.scenes.camera import true_camera
from poseintegrity.scenes.scene_boards import SceneBoard
from poseintegrity.scenes.trajectories import arc_trajectories
from poseintegrity.seeding import keyed_rng
from repository import ROOT

AZIMUTHS = [0.0]  # the camera moves along the image's x axis


@pytest.fixture(scope="module")
def params():
    return load_params(ROOT / "params.yaml")


def world(params, scene_index: int, placement: str, azimuths: list[float], plan_sigma_t_mm: float | None = None):
    """The main world's params with one board placement and these arcs (and, planned, this plan_sigma_t_mm, by
    default params.yaml's), and the laid-out arcs session."""
    generate = params.generate.world("main")
    board = generate.board.model_dump()
    if placement == "facing_camera":
        board |= dict(placement=placement, sizes_mm=None, max_boards=None, plan_sigma_t_mm=None)
    else:  # the rule on every size a lab may print, 12 mm too (params.yaml prints from 15 mm: R11, docs/references.md)
        board |= dict(sizes_mm=[12.0, 15.0, 18.0, 21.0, 24.0],
                      plan_sigma_t_mm=plan_sigma_t_mm or board["plan_sigma_t_mm"])
    generate = generate.model_copy(update={"board": type(generate.board).model_validate(board),
                                           "arcs": generate.arcs.model_copy(update={"azimuths_deg": azimuths})})
    return generate, world_cache.world(generate, params.protocol, scene_index, "arc")


def stops(generate, protocol, scene, index):
    """Per arc of scene ``index`` its commanded T_world_cam: model image 0 and every stop."""
    pair, arcs = arc_trajectories(scene.aim, scene.view_dir, generate.scenes[index].distance_mm,
                                  generate.model_baseline_mm, generate.arcs.azimuths_deg, protocol.arc_span_deg,
                                  generate.arcs.n_stops)
    return [[pair[0], *arc] for arc in arcs]


def paper(board: SceneBoard, margin: float) -> np.ndarray:
    """The board's paper corners (4, 3), world mm (``margin`` 0: its printed pattern's)."""
    w, h = board.drawing.size_mm
    local = np.array([[-margin, -margin, 0], [w + margin, -margin, 0], [w + margin, h + margin, 0],
                      [-margin, h + margin, 0]], float)
    return local @ board.T_world_board[:3, :3].T + board.T_world_board[:3, 3]


def share_in_view(points: np.ndarray, T_world_cam: np.ndarray, generate) -> float:
    """The share of the quad ``points`` (4, 3) inside the image of the pinhole of the true intrinsics, by OpenCV's
    polygon clipping."""
    camera = true_camera(generate.camera)
    pixels, _ = cv2.projectPoints(points, *_rvec_tvec(inverse(T_world_cam)), camera.K, None)
    quad = pixels.reshape(-1, 2).astype(np.float32)
    image = np.array([[0, 0], [camera.width - 1, 0], [camera.width - 1, camera.height - 1],
                      [0, camera.height - 1]], np.float32)
    return cv2.intersectConvexConvex(quad, image)[0] / cv2.contourArea(quad)


def _rvec_tvec(T: np.ndarray):
    return cv2.Rodrigues(T[:3, :3])[0], T[:3, 3]


def rendered_board(generate, scene_world, T_world_cam: np.ndarray, focus_mm: float, board: SceneBoard):
    """The board's checked pose in the image taken at T_world_cam (no ring-down), with the true camera."""
    lens = true_camera(generate.camera)
    K_canvas, width, height = lens.canvas
    frame = renderer.render(scene_world.geometry, K_canvas, width, height, inverse(T_world_cam))
    irradiance = optics.lens(frame.radiance, frame.depth_mm, focus_mm, generate.sensor.blur_sigma_px, generate.camera)
    sensor = cv2.remap(irradiance, *lens.sensor_maps, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    image = renderer.expose(sensor, generate.sensor, keyed_rng(0, "test"))
    return board_pose(image, board.board, Camera(lens.K, lens.dist, lens.width, lens.height))


def corners_in_view(board: SceneBoard, T_world_cam: np.ndarray, generate) -> int:
    """How many of the board's inner corners have all four of their squares inside the image of the pinhole of the
    true intrinsics (OpenCV's projectPoints): the corners a ChArUco detector can interpolate from their markers."""
    drawing = board.drawing
    sx, sy, square = drawing.squares_x, drawing.squares_y, drawing.size_mm[0] / drawing.squares_x
    lattice = np.array([[i * square, j * square, 0.0] for j in range(sy + 1) for i in range(sx + 1)])
    camera = true_camera(generate.camera)
    T = inverse(T_world_cam) @ board.T_world_board
    pixels, _ = cv2.projectPoints(lattice, *_rvec_tvec(T), camera.K, None)
    depth = lattice @ T[:3, 2] + T[2, 3]
    u, v = pixels.reshape(-1, 2).T
    inside = ((depth > 0) & (u >= 0) & (u <= camera.width - 1) & (v >= 0) & (v <= camera.height - 1)).reshape(
        sy + 1, sx + 1)
    return sum(inside[j - 1:j + 2, i - 1:i + 2].all() for j in range(1, sy) for i in range(1, sx))


def test_a_board_that_would_leave_the_view_late_is_moved_and_judges_every_stop(params):
    """Issue 30's board leaves the image late in scene_4's arc; the plan serves every stop: at each, at least
    MIN_PLAN_CORNERS inner corners in view (counted by OpenCV's projection), and rendered at the stop where the old
    board left the view, the new one is found with every corner in view and its pose trusted."""
    index = 3  # the main world's scene_4: a printed block at 360 mm
    focus = params.generate.scenes[index].distance_mm
    before, old = world(params, index, "facing_camera", AZIMUTHS)
    after, new = world(params, index, "planned", AZIMUTHS)
    old_board = old.scene.boards[0]
    old_shares = np.array([[share_in_view(paper(old_board, 6.0), T, before) for T in arc]
                           for arc in stops(before, params.protocol, old.scene, index)])
    arc, stop = np.unravel_index(np.argmin(old_shares), old_shares.shape)
    assert old_shares[arc, stop] < 0.8 and stop > old_shares.shape[1] // 2  # issue 30's board leaves the view late
    assert new.scene.plan.unserved == (0,) * len(AZIMUTHS)  # every stop served
    new_stops = stops(after, params.protocol, new.scene, index)
    for poses, b in zip(new_stops, new.scene.board_of):
        assert min(corners_in_view(new.scene.boards[b], T, after) for T in poses) >= board_criteria.MIN_PLAN_CORNERS
    missed = rendered_board(before, old, stops(before, params.protocol, old.scene, index)[arc][stop], focus, old_board)
    board = new.scene.board_for(arc)
    found = rendered_board(after, new, new_stops[arc][stop], focus, board)
    assert missed.n_points + missed.n_dropped < 24
    assert found.status == "ok"
    assert found.n_points + found.n_dropped >= corners_in_view(board, new_stops[arc][stop], after)


def test_where_one_board_cannot_serve_every_arc_a_second_one_with_its_own_ids_stands_apart(params, monkeypatch):
    """Asked for every corner of a board in view (a stricter rule than the plan's), one board cannot serve scene_3's
    three arcs: the plan adds a second, with marker ids of its own, that never overlaps the first in the image."""
    monkeypatch.setattr(board_criteria, "MIN_PLAN_CORNERS", 24)
    index = 2  # the main world's scene_3: a printed block at 320 mm, three arcs; a limit on sigma_t loose enough
    generate, built = world(params, index, "planned", params.generate.arcs.azimuths_deg, 0.3)  # that the view decides
    scene, plan = built.scene, built.scene.plan
    assert len(scene.boards) == 2 and sorted(set(scene.board_of)) == [0, 1]
    first, second = (board.drawing for board in scene.boards)
    assert (first.first_id, second.first_id) == (0, first.n_markers)  # no marker id in both boards
    arcs = stops(generate, params.protocol, scene, index)
    for arc, b, unserved in zip(arcs, scene.board_of, plan.unserved):
        if b == 1:  # the second board serves an arc the first would not
            assert unserved == 0 and min(share_in_view(paper(scene.boards[1], 0.0), T, generate) for T in arc) == \
                pytest.approx(1.0)
    camera = true_camera(generate.camera)
    for T in [T for arc in arcs for T in arc]:  # the two boards never overlap in the image
        quads = [cv2.projectPoints(paper(board, 6.0), *_rvec_tvec(inverse(T)), camera.K, None)[0].reshape(-1, 2)
                 .astype(np.float32) for board in scene.boards]
        assert cv2.intersectConvexConvex(*quads)[0] == 0
