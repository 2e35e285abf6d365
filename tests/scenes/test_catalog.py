"""Scene layout invariants that the localization experiments rely on (catalog.build_scene)."""

from pathlib import Path

import numpy as np
import pytest

from poseintegrity.config import load_params
from poseintegrity.scenes import catalog, mesh
from poseintegrity.scenes.params import SceneSpec

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def generate():
    return load_params(ROOT / "params.yaml").generate


def spec(targets, **extra):
    if any(name.startswith("scapula") for name in targets):
        extra.setdefault("glenoid_tilt_deg", (0.0, 0.0))
    return SceneSpec(name="s", targets=targets, distance_mm=350, elevation_deg=50, n_clutter=6, **extra)


@pytest.mark.parametrize("targets", [["scapula"], ["block_print"], ["scapula", "block_mosaic"]])
def test_board_origin_is_on_the_board_edge_nearest_the_target(generate, targets):
    """E_t is measured at the board origin (the model origin): it is a corner of the edge facing the target."""
    scene = catalog.build_scene(spec(targets), 3, generate)
    bw, bh = scene.board.size_mm
    corners = np.array([[x, y, 0.0, 1.0] for x in (0, bw) for y in (0, bh)]) @ scene.T_world_board.T
    distances = np.linalg.norm(corners[:, :2] - scene.T_world_target[:2, 3], axis=1)
    assert 0 in np.argsort(distances)[:2] and distances[0] < 90.0
    # beside a held phantom the board stands on a pedestal, never far below the aim point
    assert scene.aim[2] - corners[0, 2] <= catalog.BOARD_BELOW_AIM_MM + 1.0


def test_boxes_show_two_printed_sides_to_the_model_camera(generate):
    """Corner-on: the model view sees two side faces at 45 +- 15 deg each (a 3D point set, not one plane)."""
    scene = catalog.build_scene(spec(["block_mosaic"]), 0, generate)
    view = scene.view_dir[:2] / np.linalg.norm(scene.view_dir[:2])
    R = scene.T_world_target[:3, :3]
    angles = np.degrees(np.arccos(np.clip([abs(view @ R[:2, 0]), abs(view @ R[:2, 1])], -1, 1)))
    assert np.all(np.abs(angles - 45.0) <= 15.0)


@pytest.mark.parametrize("tilt", [(0.0, 0.0), (-15.0, 20.0)])
def test_the_glenoid_faces_the_model_camera_turned_by_the_scene_tilt(generate, tilt):
    scene = catalog.build_scene(spec(["scapula_drilled"], glenoid_tilt_deg=tilt), 1, generate)
    normal = scene.T_world_target[:3, 2]
    angle = np.degrees(np.arccos(normal @ scene.view_dir))
    assert angle == pytest.approx(np.degrees(np.arccos(np.cos(np.radians(tilt[0])) * np.cos(np.radians(tilt[1])))),
                                  abs=1e-6)
    np.testing.assert_allclose(scene.aim, scene.T_world_target[:3, 3])  # the arcs turn about the drill hole
    phantom = dict(scene.placed)["scapula_drilled"]
    assert phantom.vertices[:, 2].min() == pytest.approx(catalog.PHANTOM_CLEARANCE_MM)  # held above the table
    assert phantom.texture is None and phantom.material.foam_albedo == generate.bone_foam.albedo


def test_clutter_holds_bone_foam_and_printed_look_alikes(generate):
    materials = [(m.texture, m.material.foam_albedo) for name, m in catalog.build_scene(
        spec(["scapula"]).model_copy(update={"n_clutter": 12}), 2, generate).placed if name.startswith("clutter")]
    assert len(materials) == 12
    assert any(albedo is not None for _, albedo in materials)  # foam offcuts
    assert any(texture in catalog.PRINTED_CLUTTER for texture, _ in materials)


def test_the_layout_follows_generate_seed(generate):
    first = catalog.build_scene(spec(["block_print"]), 0, generate)
    again = catalog.build_scene(spec(["block_print"]), 0, generate)
    other = catalog.build_scene(spec(["block_print"]), 0, generate.model_copy(update={"seed": generate.seed + 1}))
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
