"""Scene layout invariants that the localization experiments rely on (catalog.build_scene)."""

from pathlib import Path

import numpy as np
import pytest

from poseintegrity.config import load_params
from poseintegrity.params.generate import SceneSpec
from poseintegrity.scenes import board_criteria, board_stand, catalog, mesh, printed_boards

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def params():
    return load_params(ROOT / "params.yaml")


def planned(generate, sizes_mm: list[float], n_stops: int):
    """params.yaml's world ``generate``, its boards planned (scenes/board_plan.py) among these square sizes, for arcs
    and lines of ``n_stops`` stops. Every candidate is turned, tilted and given its post alike, whatever its size or
    the stops it is judged at; the plan over params.yaml's 4 sizes and 20 stops (98 280 candidates at 61 poses) took
    7.5 s of this module's 12."""
    return generate.model_copy(update={"board": generate.board.model_copy(update={"sizes_mm": sizes_mm}),
                                       "arcs": generate.arcs.model_copy(update={"n_stops": n_stops}),
                                       "lines": generate.lines.model_copy(update={"n_stops": n_stops})})


@pytest.fixture(scope="module")
def generate(params):
    """params.yaml's world with issue 30's board placement (fast): the layout tests that are not about the boards."""
    board = params.generate.board.model_dump() | dict(placement="facing_camera", sizes_mm=None, max_boards=None,
                                                      plan_sigma_t_mm=None)
    return params.generate.model_copy(update={"board": type(params.generate.board).model_validate(board)})


@pytest.fixture(scope="module")
def protocol(params):
    return params.protocol


def spec(targets, **extra):
    if any(name.startswith("scapula") for name in targets):
        extra.setdefault("glenoid_tilt_deg", (0.0, 0.0))
    return SceneSpec(name="s", targets=targets, distance_mm=350, elevation_deg=50, n_clutter=6, **extra)


# Asked for every corner of a board in view (stricter than the plan's MIN_PLAN_CORNERS), the scapula's plan places one
# board of 18 mm squares, the pair's two (the second on a post of its own) of 15 mm tilted 25 and 40 deg (the most a
# candidate is).
@pytest.mark.parametrize(("targets", "sizes_mm", "n_boards"), [(["scapula"], [15.0, 18.0], 1),
                                                               (["scapula", "block_mosaic"], [15.0, 24.0], 2)])
def test_the_boards_face_the_model_camera_their_origin_the_corner_nearest_the_target(params, protocol, targets, sizes_mm,
                                                                                   n_boards, monkeypatch):
    """E_t is measured at the board origin (the model origin, IV-C): each board is turned so that its origin is nearer
    the target than the corner a half turn would put there (and than its centre); its printed side faces the model
    camera, tilted from facing it by at most 40 deg (board z against the camera's forward axis), and it stands on its
    post, whose top is behind its centre (never through the paper)."""
    monkeypatch.setattr(board_criteria, "MIN_PLAN_CORNERS", 24)
    scene = catalog.build_scene(spec(targets), 3, planned(params.generate, sizes_mm, n_stops=10), protocol)
    assert len(scene.boards) == n_boards
    target = dict(scene.placed)[targets[0]].vertices.mean(axis=0)
    for k, board in enumerate(scene.boards):
        bw, bh = board.drawing.size_mm
        T = board.T_world_board
        corners = np.array([[x, y, 0.0, 1.0] for x in (0, bw) for y in (0, bh)]) @ T.T
        distances = np.linalg.norm(corners[:, :3] - target, axis=1)
        centre = T @ [bw / 2, bh / 2, 0.0, 1.0]
        assert distances[0] <= distances[3] and distances[0] < np.linalg.norm(centre[:3] - target)
        assert np.degrees(np.arccos(np.clip(T[:3, 2] @ -scene.view_dir, -1.0, 1.0))) <= 40.0 + 1e-6
        post = dict(scene.placed)["board_post" + ("" if k == 0 else f"_{k + 1}")].vertices
        axis = post[:, :2].mean(axis=0)
        top = np.append(axis, post[:, 2].max())
        assert post[:, 2].min() == pytest.approx(0.0)
        # its top behind the board's centre by more than its radius: it holds the board and never pierces the paper
        behind = top - centre[:3]
        assert np.linalg.norm(np.cross(behind, T[:3, 2])) == pytest.approx(0.0, abs=0.5)  # the mesh's facets
        assert behind @ T[:3, 2] > board_stand.POST_RADIUS_MM


def test_the_flat_placement_lays_the_board_beside_the_target_on_its_pedestal(generate, protocol):
    flat = generate.model_copy(update={"board": generate.board.model_copy(update={"placement": "flat"})})
    scene = catalog.build_scene(spec(["scapula"]), 3, flat, protocol)
    np.testing.assert_allclose(scene.boards[0].T_world_board[:3, 2], [0.0, 0.0, -1.0])  # printed side up
    assert "board_pedestal" in dict(scene.placed)


def test_the_lab_measures_the_printed_board_with_calipers(generate, protocol):
    """meta.json's board is the drawing scaled by what the lab measured: within a caliper error of the printed
    scale; without calipers (null) the drawing itself."""
    scene = catalog.build_scene(spec(["block_print"]), 0, generate, protocol)
    caliper = generate.printed_boards.caliper_std_mm
    for board in scene.boards:  # each printed board its own print and measurement
        printed, _ = printed_boards.print_errors(generate, printed_boards.printed_name(generate, board.drawing),
                                                 generate.printed_boards.board_sag_std_mm)
        width, height = board.drawing.size_mm
        assert abs(board.board.scale[0] - printed[0]) * width < 5 * caliper
        assert abs(board.board.scale[1] - printed[1]) * height < 5 * caliper
        assert board.board.scale != (1.0, 1.0) and board.board.first_id == board.drawing.first_id
    unmeasured = generate.model_copy(update={"printed_boards": generate.printed_boards.model_copy(
        update={"caliper_std_mm": None})})
    assert printed_boards.measured_board(unmeasured).scale == (1.0, 1.0)


def test_boxes_show_two_printed_sides_to_the_model_camera(generate, protocol):
    """Corner-on: the model view sees two side faces at 45 +- 15 deg each (a 3D point set, not one plane)."""
    scene = catalog.build_scene(spec(["block_mosaic"]), 0, generate, protocol)
    view = scene.view_dir[:2] / np.linalg.norm(scene.view_dir[:2])
    R = scene.T_world_target[:3, :3]
    angles = np.degrees(np.arccos(np.clip([abs(view @ R[:2, 0]), abs(view @ R[:2, 1])], -1, 1)))
    assert np.all(np.abs(angles - 45.0) <= 15.0)


@pytest.mark.parametrize("tilt", [(0.0, 0.0), (-15.0, 20.0)])
def test_the_glenoid_faces_the_model_camera_turned_by_the_scene_tilt(generate, protocol, tilt):
    scene = catalog.build_scene(spec(["scapula_drilled"], glenoid_tilt_deg=tilt), 1, generate, protocol)
    normal = scene.T_world_target[:3, 2]
    angle = np.degrees(np.arccos(normal @ scene.view_dir))
    assert angle == pytest.approx(np.degrees(np.arccos(np.cos(np.radians(tilt[0])) * np.cos(np.radians(tilt[1])))),
                                  abs=1e-6)
    np.testing.assert_allclose(scene.aim, scene.T_world_target[:3, 3])  # the arcs turn about the drill hole
    phantom = dict(scene.placed)["scapula_drilled"]
    assert phantom.vertices[:, 2].min() == pytest.approx(catalog.PHANTOM_CLEARANCE_MM)  # held above the table
    assert phantom.texture is None and phantom.material.foam_albedo == generate.bone_foam.albedo


def test_clutter_holds_bone_foam_and_printed_look_alikes(generate, protocol):
    materials = [(m.texture, m.material.foam_albedo) for name, m in catalog.build_scene(
        spec(["scapula"]).model_copy(update={"n_clutter": 12}), 2, generate, protocol).placed if name.startswith("clutter")]
    assert len(materials) == 12
    assert any(albedo is not None for _, albedo in materials)  # foam offcuts
    assert any(texture in catalog.PRINTED_CLUTTER for texture, _ in materials)


def test_the_layout_follows_generate_seed(generate, protocol):
    first = catalog.build_scene(spec(["block_print"]), 0, generate, protocol)
    again = catalog.build_scene(spec(["block_print"]), 0, generate, protocol)
    other = catalog.build_scene(spec(["block_print"]), 0, generate.model_copy(update={"seed": generate.seed + 1}),
                                protocol)
    np.testing.assert_array_equal(first.view_dir, again.view_dir)
    assert not np.allclose(first.view_dir, other.view_dir)


def test_box_lid_is_printed_faintly(generate):
    """The +z sixth of a box texture has a fraction of the sides' contrast (see mesh.box's 3 x 2 layout)."""
    albedo = catalog.procedural_texture("block_print", generate.seed).astype(float)
    h, w = albedo.shape
    lid, side = albedo[h // 2:, w // 3: 2 * w // 3], albedo[: h // 2, : w // 3]
    assert 0.15 < lid.std() / side.std() < 0.5
    box = mesh.box((10, 10, 10), "t")
    top = box.vertices[box.faces].mean(axis=1)[:, 2] > 4.99  # faces of the lid (z = +5)
    uv = box.uv[box.faces[top]].reshape(-1, 2)
    assert np.all((uv[:, 0] >= 1 / 3 - 1e-9) & (uv[:, 0] <= 2 / 3 + 1e-9) & (uv[:, 1] >= 0.5 - 1e-9))
