"""Mesh primitives: closed, outward-facing, unit normals (invariants any renderer relies on)."""

import numpy as np
import pytest

from poseintegrity.scenes import mesh


def signed_volume(m: mesh.Mesh) -> float:
    v0, v1, v2 = (m.vertices[m.faces[:, i]] for i in range(3))
    return float(np.einsum("ij,ij->i", v0, np.cross(v1, v2)).sum() / 6)


def edge_counts(m: mesh.Mesh) -> np.ndarray:
    edges = np.sort(np.concatenate([m.faces[:, [0, 1]], m.faces[:, [1, 2]], m.faces[:, [2, 0]]]), axis=1)
    return np.unique(edges, axis=0, return_counts=True)[1]


def test_box_volume_is_exact_and_outward():
    box = mesh.box((30.0, 40.0, 50.0), "t")
    assert signed_volume(box) == pytest.approx(60000.0, rel=1e-9)  # positive: faces wound outwards


def test_a_trimesh_becomes_an_untextured_mesh_with_outward_normals_split_at_creases():
    import trimesh

    box = trimesh.creation.box((20.0, 30.0, 40.0))
    m = mesh.from_trimesh(box, mesh.Material(foam_albedo=0.8))
    assert m.texture is None and m.material.foam_albedo is not None
    assert signed_volume(m) == pytest.approx(24000.0)
    # every corner is a crease: its normals follow the faces (a box keeps flat faces), all unit and outward
    v0, v1, v2 = (m.vertices[m.faces[:, i]] for i in range(3))
    face_n = np.cross(v1 - v0, v2 - v0)
    face_n /= np.linalg.norm(face_n, axis=1, keepdims=True)
    np.testing.assert_allclose(m.normals[m.faces[:, 0]], face_n, atol=1e-9)


def test_transformed_composes_the_object_frame():
    T1, T2 = np.eye(4), np.eye(4)
    T1[:3, 3] = [1.0, 2.0, 3.0]
    T2[:3, :3] = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]])
    moved = mesh.box((1.0, 1.0, 1.0), None).transformed(T1).transformed(T2)
    np.testing.assert_allclose(moved.T_world_obj, T2 @ T1)


def test_cylinder_side_faces_point_away_from_axis():
    cyl = mesh.cylinder(20.0, 50.0, "t")
    v0, v1, v2 = (cyl.vertices[cyl.faces[:, i]] for i in range(3))
    n = np.cross(v1 - v0, v2 - v0)
    centre = (v0 + v1 + v2) / 3
    side = centre[:, 2] < 49.9
    assert (np.einsum("ij,ij->i", n[side, :2], centre[side, :2]) > 0).all()
    assert (n[~side, 2] > 0).all()


def test_transformed_keeps_shape():
    box = mesh.box((10.0, 20.0, 30.0), "t")
    T = np.eye(4)
    T[:3, :3] = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]])
    T[:3, 3] = [5, 6, 7]
    moved = box.transformed(T)
    assert signed_volume(moved) == pytest.approx(signed_volume(box))
    assert np.allclose(moved.vertices.mean(axis=0), [5, 6, 7])


def test_a_printed_sheet_is_scaled_about_its_centre_and_bowed_with_normals_that_follow():
    """printed_sheet: x' = c + s (x - c), z = -sag (1 - u^2) with u the drawn x from the centre over the half width;
    the normals are unit, face the viewer (-z) and stand perpendicular to the bowed surface (finite differences)."""
    from poseintegrity.scenes.mesh import plane, printed_sheet
    from poseintegrity.poses import pose_matrix

    flat = plane(100.0, 60.0, 20, 12, "paper").transformed(pose_matrix(np.diag([1.0, -1.0, -1.0]), [50.0, 30.0, 0.0]))
    centre, scale, sag = np.array([50.0, 30.0]), (1.003, 0.998), 0.8
    sheet = printed_sheet(flat, centre, 50.0, scale, sag)
    u = (flat.vertices[:, 0] - 50.0) / 50.0
    np.testing.assert_allclose(sheet.vertices[:, 0], 50.0 + 1.003 * (flat.vertices[:, 0] - 50.0))
    np.testing.assert_allclose(sheet.vertices[:, 1], 30.0 + 0.998 * (flat.vertices[:, 1] - 30.0))
    np.testing.assert_allclose(sheet.vertices[:, 2], -sag * (1 - u**2), atol=1e-12)
    assert sheet.vertices[:, 2].min() == pytest.approx(-sag)  # the centre bows towards the viewer
    np.testing.assert_allclose(np.linalg.norm(sheet.normals, axis=1), 1.0)
    assert (sheet.normals[:, 2] < 0).all()
    x = sheet.vertices[:, 0]
    h = 1e-4  # tangent of z(x') along x' by central differences of the bow's formula
    z_of = lambda xp: -sag * (1 - ((xp - 50.0) / 1.003 / 50.0) ** 2)  # noqa: E731
    tangent = np.column_stack([np.ones_like(x), np.zeros_like(x), (z_of(x + h) - z_of(x - h)) / (2 * h)])
    np.testing.assert_allclose(np.einsum("ij,ij->i", tangent, sheet.normals), 0.0, atol=1e-9)
