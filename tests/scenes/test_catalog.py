"""Scene layout invariants that the localization experiments rely on (catalog.build_scene)."""

import numpy as np
import pytest

from poseintegrity.scenes import catalog, mesh
from poseintegrity.scenes.params import SceneSpec


@pytest.mark.parametrize("targets", [["scapula"], ["block_print"], ["scapula", "block_mosaic"]])
def test_board_origin_is_on_the_board_edge_nearest_the_target(targets):
    """E_t is measured at the board origin (the model origin): it is a corner of the edge facing the target."""
    scene = catalog.build_scene(SceneSpec(name="s", targets=targets, distance_mm=350, elevation_deg=50), 3)
    bw, bh = scene.board.size_mm
    corners = np.array([[x, y, 0.0, 1.0] for x in (0, bw) for y in (0, bh)]) @ scene.T_world_board.T
    distances = np.linalg.norm(corners[:, :2] - scene.T_world_target[:2, 3], axis=1)
    assert 0 in np.argsort(distances)[:2] and distances[0] < 90.0


def test_boxes_show_two_printed_sides_to_the_model_camera():
    """Corner-on: the model view sees two side faces at 45 +- 15 deg each (a 3D point set, not one plane)."""
    scene = catalog.build_scene(SceneSpec(name="s", targets=["block_mosaic"], distance_mm=350, elevation_deg=50), 0)
    view = scene.view_dir[:2] / np.linalg.norm(scene.view_dir[:2])
    R = scene.T_world_target[:3, :3]
    angles = np.degrees(np.arccos(np.clip([abs(view @ R[:2, 0]), abs(view @ R[:2, 1])], -1, 1)))
    assert np.all(np.abs(angles - 45.0) <= 15.0)


def test_scapula_is_not_a_plane():
    """The spine stands proud of the blade: the phantom's depth range is many times its blade thickness."""
    plate = catalog.target_mesh("scapula")
    centred = plate.vertices - plate.vertices.mean(axis=0)
    smallest_extent = np.ptp(centred @ np.linalg.svd(centred, full_matrices=False)[2][2])
    assert smallest_extent > 30.0  # mm; thickness alone is 14


def test_box_lid_is_printed_faintly():
    """The +z sixth of a box texture has a fraction of the sides' contrast (see mesh.box's 3 x 2 layout)."""
    albedo = catalog.procedural_texture("block_print").astype(float)
    h, w = albedo.shape
    lid, side = albedo[h // 2:, w // 3: 2 * w // 3], albedo[: h // 2, : w // 3]
    assert 0.15 < lid.std() / side.std() < 0.5
    box = mesh.box((10, 10, 10), "t")
    top = box.vertices[box.faces].mean(axis=1)[:, 2] > 4.99  # faces of the lid (z = +5)
    uv = box.uv[box.faces[top]].reshape(-1, 2)
    assert np.all((uv[:, 0] >= 1 / 3 - 1e-9) & (uv[:, 0] <= 2 / 3 + 1e-9) & (uv[:, 1] >= 0.5 - 1e-9))
