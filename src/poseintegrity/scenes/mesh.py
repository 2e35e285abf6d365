"""Triangle meshes: the primitives our scenes are built from, and meshes read from files
(:mod:`poseintegrity.mesh_file`, via trimesh).

A mesh is wound counter-clockwise seen from outside (so the right-hand normal of a face points outwards), carries
smooth per-vertex normals and either per-vertex texture coordinates in [0, 1]^2 of one named texture (printed
surfaces) or no texture: its albedo and relief then come from its material's solid texture (bone foam,
:mod:`poseintegrity.scenes.foam`), evaluated in its own object frame (millimetres) wherever it is placed.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from poseintegrity.poses import pose_matrix

if TYPE_CHECKING:
    import trimesh


@dataclass(frozen=True)
class Material:
    """Reflectance of a surface: Lambertian albedo, Blinn-Phong specular lobe, optional bone-foam relief.

    specular, shininess : Blinn-Phong k_s and exponent
    foam_albedo : None for a textured surface; else the mean albedo of a bone-foam surface, whose albedo and relief
        are the solid texture of :mod:`poseintegrity.scenes.foam` (the mesh then needs no texture)
    """

    specular: float = 0.05
    shininess: float = 20.0
    foam_albedo: float | None = None



@dataclass(frozen=True)
class Mesh:
    """vertices : (n, 3) float mm; faces : (m, 3) int; uv : (n, 2) float in [0, 1]; normals : (n, 3) unit;
    texture : name of its albedo map, None for a bone-foam material; T_world_obj : (4, 4) where its own frame
    (the frame of its solid texture) has been placed."""

    vertices: np.ndarray
    faces: np.ndarray
    uv: np.ndarray
    normals: np.ndarray
    texture: str | None
    material: Material = Material()
    T_world_obj: np.ndarray = field(default_factory=lambda: np.eye(4))

    def transformed(self, T_new_old: np.ndarray) -> "Mesh":
        """The same mesh with vertices and normals mapped by the rigid transform ``T_new_old``."""
        R, t = T_new_old[:3, :3], T_new_old[:3, 3]
        return replace(self, vertices=self.vertices @ R.T + t, normals=self.normals @ R.T,
                       T_world_obj=T_new_old @ self.T_world_obj)


def printed_sheet(sheet: Mesh, centre: np.ndarray, half_width_mm: float, scale: tuple[float, float],
                  sag_mm: float) -> Mesh:
    """A flat printed sheet (a plane in its z = 0, facing -z: a board's printed side) as it really is: printed at
    ``scale`` (x, y) of its drawing about ``centre`` (2,), mm, and bowed like a card bent about its y axis, by
    ``sag_mm`` at the centre towards the viewer (-z; negative: away), z = -sag (1 - ((x - cx) / half_width)^2).
    Normals follow the bow."""
    x, y = sheet.vertices[:, 0] - centre[0], sheet.vertices[:, 1] - centre[1]
    u = x / half_width_mm
    vertices = np.column_stack([centre[0] + scale[0] * x, centre[1] + scale[1] * y,
                                sheet.vertices[:, 2] - sag_mm * (1.0 - u * u)])
    slope = 2.0 * sag_mm * u / (half_width_mm * scale[0])  # dz/dx' of the bowed sheet
    normals = np.column_stack([slope, np.zeros_like(slope), -np.ones_like(slope)])
    return replace(sheet, vertices=vertices, normals=normals / np.linalg.norm(normals, axis=1, keepdims=True))


def from_trimesh(mesh: "trimesh.Trimesh", material: Material, crease_deg: float = 40.0) -> Mesh:
    """A bone-foam (untextured) mesh from a trimesh mesh: normals smooth except across edges sharper than
    ``crease_deg`` (e.g. a drill hole's rim), where vertices are split (trimesh.graph.smooth_shade)."""
    import trimesh

    smooth = trimesh.graph.smooth_shade(mesh, angle=np.radians(crease_deg))
    vertices = np.asarray(smooth.vertices, dtype=np.float64)
    return Mesh(vertices, np.asarray(smooth.faces, dtype=np.int32), np.zeros((len(vertices), 2)),
                np.asarray(smooth.vertex_normals, dtype=np.float64), None, material)


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted average of the normals of the faces around each vertex; (n, 3) unit vectors."""
    v0, v1, v2 = (vertices[faces[:, i]] for i in range(3))
    face_n = np.cross(v1 - v0, v2 - v0)  # length = 2 x area: area weighting for free
    normals = np.zeros_like(vertices)
    for i in range(3):
        np.add.at(normals, faces[:, i], face_n)
    return normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)


def grid_faces(n_rows: int, n_cols: int, offset: int = 0) -> np.ndarray:
    """Faces of a regular (n_rows x n_cols) vertex grid indexed row-major, two triangles per cell.

    Counter-clockwise when rows run along +y and columns along +x seen from +z.
    """
    r, c = np.meshgrid(np.arange(n_rows - 1), np.arange(n_cols - 1), indexing="ij")
    a = (r * n_cols + c).ravel() + offset
    b, d, e = a + 1, a + n_cols, a + n_cols + 1
    return np.concatenate([np.column_stack([a, b, e]), np.column_stack([a, e, d])]).astype(np.int32)


def plane(size_x: float, size_y: float, n_x: int, n_y: int, texture: str, uv_rect=(0.0, 0.0, 1.0, 1.0),
          material: Material = Material()) -> Mesh:
    """A flat rectangle in z = 0 centred on the origin, facing +z, subdivided n_x x n_y cells.

    uv_rect : (u0, v0, u1, v1), the part of the texture mapped onto it; texture v grows with -y so that the
    image appears upright seen from +z with +y up.
    """
    xs = np.linspace(-size_x / 2, size_x / 2, n_x + 1)
    ys = np.linspace(-size_y / 2, size_y / 2, n_y + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")  # rows along x
    vertices = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    u0, v0, u1, v1 = uv_rect
    uv = np.column_stack([u0 + (X.ravel() / size_x + 0.5) * (u1 - u0), v0 + (0.5 - Y.ravel() / size_y) * (v1 - v0)])
    # rows run along +x and columns along +y: swap the winding of grid_faces to face +z
    faces = grid_faces(n_x + 1, n_y + 1)[:, [0, 2, 1]]
    normals = np.tile([0.0, 0.0, 1.0], (len(vertices), 1))
    return Mesh(vertices, faces, uv, normals, texture, material)


def merge(meshes: list[Mesh]) -> Mesh:
    """One mesh from several that share a texture and material (faces re-indexed)."""
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    return Mesh(
        np.concatenate([m.vertices for m in meshes]),
        np.concatenate([m.faces + o for m, o in zip(meshes, offsets)]).astype(np.int32),
        np.concatenate([m.uv for m in meshes]),
        np.concatenate([m.normals for m in meshes]),
        meshes[0].texture,
        meshes[0].material,
    )


def box(size: tuple[float, float, float], texture: str | None, n_sub: int = 6, material: Material = Material()) -> Mesh:
    """A box centred on the origin with flat-shaded faces; each face shows its own sixth of the texture.

    The texture is cut in a 3 x 2 layout: faces +x, -x, +y / -y, +z, -z.
    """
    sx, sy, sz = size
    rot = {  # rotation taking the plane's +z normal to the face normal, and the face's extent (along x, y)
        "+z": (np.eye(3), (sx, sy), sz / 2),
        "-z": (np.diag([1.0, -1.0, -1.0]), (sx, sy), sz / 2),
        "+x": (np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0]], float), (sy, sz), sx / 2),
        "-x": (np.array([[0, 0, -1], [-1, 0, 0], [0, 1, 0]], float), (sy, sz), sx / 2),
        "+y": (np.array([[-1, 0, 0], [0, 0, 1], [0, 1, 0]], float), (sx, sz), sy / 2),
        "-y": (np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], float), (sx, sz), sy / 2),
    }
    layout = ["+x", "-x", "+y", "-y", "+z", "-z"]
    faces = []
    for k, name in enumerate(layout):
        R, (a, b), d = rot[name]
        u0, v0 = (k % 3) / 3, (k // 3) / 2
        face = plane(a, b, n_sub, n_sub, texture, (u0, v0, u0 + 1 / 3, v0 + 1 / 2), material)
        faces.append(face.transformed(pose_matrix(R, R @ [0, 0, d])))
    return merge(faces)


def cylinder(radius: float, height: float, texture: str | None, n_seg: int = 48, n_rings: int = 8,
             material: Material = Material()) -> Mesh:
    """An upright cylinder standing on z = 0 with a top cap; the side takes the texture's top 3/4, the cap the rest."""
    phi = np.linspace(0, 2 * np.pi, n_seg + 1)  # the seam vertex is repeated for the texture
    z = np.linspace(0, height, n_rings + 1)
    P, Z = np.meshgrid(phi, z, indexing="ij")
    side_v = np.column_stack([radius * np.cos(P.ravel()), radius * np.sin(P.ravel()), Z.ravel()])
    side_uv = np.column_stack([P.ravel() / (2 * np.pi), 0.75 * (1 - Z.ravel() / height)])
    side_n = np.column_stack([np.cos(P.ravel()), np.sin(P.ravel()), np.zeros(P.size)])
    side = Mesh(side_v, grid_faces(n_seg + 1, n_rings + 1)[:, [0, 2, 1]], side_uv, side_n, texture, material)
    # cap: a fan around the centre
    ring = np.column_stack([radius * np.cos(phi[:-1]), radius * np.sin(phi[:-1]), np.full(n_seg, height)])
    cap_v = np.vstack([[0, 0, height], ring])
    idx = np.arange(n_seg)
    cap_f = np.column_stack([np.zeros(n_seg, int), 1 + idx, 1 + (idx + 1) % n_seg]).astype(np.int32)
    cap_uv = np.column_stack([0.5 + 0.125 * cap_v[:, 0] / radius * 2, 0.875 + 0.125 * cap_v[:, 1] / radius])
    cap = Mesh(cap_v, cap_f, np.clip(cap_uv, 0, 1), np.tile([0.0, 0.0, 1.0], (n_seg + 1, 1)), texture, material)
    return merge([side, cap])
