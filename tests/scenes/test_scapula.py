"""The anatomical phantom: the STL read by trimesh, scaled, drilled; every bad mesh or hole named before rendering."""

from pathlib import Path

import numpy as np
import pytest
import trimesh

from poseintegrity.config import ParamsError, load_params, parse_params, read_raw
from poseintegrity.mesh_file import MeshError, check_mesh, read_mesh
from poseintegrity.scenes.scapula import scapula_mesh
from poseintegrity.scenes.world_checks import WorldError, check_world

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def generate():
    return load_params(ROOT / "params.yaml").generate


def test_phantom_is_an_adult_scapula_in_the_glenoid_frame(generate):
    bone = scapula_mesh(generate.scapula, drilled=False)
    raw = trimesh.load(generate.scapula.mesh)
    assert bone.is_watertight and bone.is_volume
    # scaled so that the file's longest extent is length_mm (volume scales with the cube), then only rotated
    scale = generate.scapula.length_mm / max(raw.extents)
    assert bone.volume == pytest.approx(raw.volume * scale**3, rel=1e-9)
    # the glenoid centre is the origin and its normal +z: the surface near the origin faces +z, bone lies below
    near = np.linalg.norm(bone.vertices, axis=1) < 8.0
    assert near.sum() > 5 and bone.vertex_normals[near, 2].mean() > 0.7
    assert np.median(bone.vertices[:, 2]) < -10.0  # the blade lies behind the glenoid (medial)
    # +x points to the inferior angle: the far tip of the blade
    assert bone.vertices[:, 0].max() > 100.0 and bone.vertices[:, 0].min() > -60.0


def test_drilled_phantom_has_the_hole_of_its_parameters(generate):
    plain, drilled = (scapula_mesh(generate.scapula, drilled=d) for d in (False, True))
    drill = generate.scapula.drill
    expected = np.pi * (drill.diameter_mm / 2) ** 2 * drill.depth_mm
    assert drilled.is_watertight
    assert plain.volume - drilled.volume == pytest.approx(expected, rel=0.3)
    # the hole runs along -z from the glenoid centre: its flat bottom at -depth, nothing inside it above that
    radial, z = np.hypot(drilled.vertices[:, 0], drilled.vertices[:, 1]), drilled.vertices[:, 2]
    inside = radial < drill.diameter_mm / 2 - 0.2
    assert (inside & (np.abs(z + drill.depth_mm) < 0.01)).any()
    assert not (inside & (z > -drill.depth_mm + 0.1) & (z < -4.0)).any()  # the cup itself is < 4 mm deep


def test_a_hole_outside_the_bone_is_named(generate):
    away = generate.scapula.model_copy(update={"glenoid_centre": (5.0, 5.0, 5.0)})  # far outside the mesh
    with pytest.raises(MeshError, match="generate.scapula.drill.*outside the mesh"):
        scapula_mesh(away, drilled=True)


def test_unreadable_or_open_mesh_files_are_named(tmp_path):
    text = tmp_path / "notes.stl"
    text.write_text("this is not a mesh")
    with pytest.raises(MeshError, match="generate.scapula.mesh.*notes.stl"):
        read_mesh(text, "generate.scapula.mesh")
    box = trimesh.creation.box((10.0, 10.0, 10.0))
    open_box = trimesh.Trimesh(box.vertices, box.faces[:-2])  # one face of the box removed: not closed
    path = tmp_path / "open.stl"
    open_box.export(path)
    with pytest.raises(MeshError, match="open.stl is not a closed manifold"):
        read_mesh(path, "generate.scapula.mesh")


def test_a_mesh_checked_once_is_checked_again_when_the_file_changes(tmp_path):
    """check_mesh remembers a closed mesh by path, size and modification time: the same file is not read again, but
    an open mesh written in its place is refused, and a refusal is never remembered."""
    path = tmp_path / "target.stl"
    box = trimesh.creation.box((10.0, 10.0, 10.0))
    box.export(path)
    check_mesh(path, "generate.scapula.mesh")
    check_mesh(path, "generate.scapula.mesh")  # from memory
    trimesh.Trimesh(box.vertices, box.faces[:-2]).export(path)  # one face removed: not closed, another size
    for _ in range(2):
        with pytest.raises(MeshError, match="generate.scapula.mesh: .*target.stl is not a closed manifold"):
            check_mesh(path, "generate.scapula.mesh")
    box.export(path)
    check_mesh(path, "generate.scapula.mesh")  # closed again
    with pytest.raises(MeshError, match="generate.scapula.mesh: cannot read mesh file .*gone.stl"):
        check_mesh(tmp_path / "gone.stl", "generate.scapula.mesh")


def test_params_validation_names_a_bad_mesh_before_any_work(tmp_path):
    raw, base = read_raw(ROOT / "tests" / "params_tiny.yaml")
    raw["generate"]["scapula"]["mesh"] = str(tmp_path / "missing.stl")
    with pytest.raises(ParamsError, match="generate.scapula.mesh.*missing.stl"):
        parse_params(raw, base_dir=base)


# 2 m: the target fills the view, leaving the board no place beside it (named before the target's own check). The
# boards planned at one size, the smallest: the plan over params.yaml's four took 1.1 s more a case.
@pytest.mark.parametrize("length_mm, message", [(2000.0, "no place beside the target"), (4.0, "too small")])
def test_a_scale_that_loses_the_target_stops_before_rendering(generate, length_mm, message):
    scaled = generate.model_copy(update={
        "scapula": generate.scapula.model_copy(update={"length_mm": length_mm}),
        "board": generate.board.model_copy(update={"sizes_mm": [min(generate.board.sizes_mm)]}),
        "scenes": [generate.scenes[0]], "lines": None})  # scene_1: the plain scapula (no hole to drill)
    with pytest.raises(WorldError, match=f"generate.scenes.0.*: .*{message}.*generate.scapula.length_mm"):
        check_world(scaled, load_params(ROOT / "params.yaml").protocol)
