"""Triangle meshes: the primitives our scenes are built from.

A mesh lives in its own object frame (millimetres), is wound counter-clockwise seen from outside (so the
right-hand normal of a face points outwards), carries per-vertex texture coordinates in [0, 1]^2 of one
named texture and smooth per-vertex normals.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from poseintegrity.scenes.camera import rigid


@dataclass(frozen=True)
class Material:
    """Reflectance of a surface: Lambertian albedo from the texture, Blinn-Phong specular lobe."""

    specular: float = 0.05
    shininess: float = 20.0


@dataclass(frozen=True)
class Mesh:
    """vertices : (n, 3) float mm; faces : (m, 3) int; uv : (n, 2) float in [0, 1]; normals : (n, 3) unit."""

    vertices: np.ndarray
    faces: np.ndarray
    uv: np.ndarray
    normals: np.ndarray
    texture: str
    material: Material = Material()

    def transformed(self, T_world_obj: np.ndarray) -> "Mesh":
        """The same mesh with vertices and normals mapped by the rigid transform ``T_world_obj``."""
        R, t = T_world_obj[:3, :3], T_world_obj[:3, 3]
        return replace(self, vertices=self.vertices @ R.T + t, normals=self.normals @ R.T)


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


def box(size: tuple[float, float, float], texture: str, n_sub: int = 6, material: Material = Material()) -> Mesh:
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
        faces.append(face.transformed(rigid(R, R @ [0, 0, d])))
    return merge(faces)


def cylinder(radius: float, height: float, texture: str, n_seg: int = 48, n_rings: int = 8,
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


def bone_plate(rng: np.random.Generator, texture: str, size_mm: float = 150.0, thickness_mm: float = 14.0,
               hole_uv: tuple[float, float] | None = None, n_radial: int = 40, n_angular: int = 120,
               material: Material = Material(specular=0.12, shininess=12.0)) -> Mesh:
    """A scapula-like bone phantom: a thin, curved, roughly triangular plate with a ridge and a shallow cup.

    Star-shaped outline r(phi) with a dominant 3-fold harmonic (triangular blade); top and bottom surfaces
    z = +-t(rho)/2 + bend(x, y) meet at the rim, so the surface is closed and smooth. A spine-like ridge runs
    across the top, a glenoid-like cup sits near one corner, and ``hole_uv`` (texture coordinates) drills a
    narrow pit (the paper's pre-drilled phantom). Planar texture mapping over the outline's bounding box.
    """
    phi = np.linspace(0, 2 * np.pi, n_angular, endpoint=False)
    harmonics = 1 + 0.28 * np.cos(3 * phi + rng.uniform(0, 0.3)) + 0.06 * np.cos(5 * phi + rng.uniform(0, 6.28))
    r_outline = 0.5 * size_mm * harmonics / harmonics.max()
    rho = np.linspace(0, 1, n_radial + 1)[1:]
    RHO, PHI = np.meshgrid(rho, phi, indexing="ij")
    x = (RHO * r_outline[None, :] * np.cos(PHI)).ravel()
    y = (RHO * r_outline[None, :] * np.sin(PHI)).ravel()
    half_t = 0.5 * thickness_mm * np.sqrt(np.clip(1 - RHO.ravel() ** 4, 0, 1))
    bend = -(x**2) / (2 * 1.3 * size_mm) + 0.15 * y**2 / (2 * size_mm)  # saddle-like curvature of the blade
    # the scapular spine: a crest standing ~20 mm proud of the blade, so the phantom is not a plane
    ridge = 20.0 * np.exp(-(((y - 0.15 * x - 0.1 * size_mm) / (0.08 * size_mm)) ** 2)) * np.clip(
        (x + 0.4 * size_mm) / (0.15 * size_mm), 0, 1)
    cup_c = 0.36 * size_mm * np.array([np.cos(0.1), np.sin(0.1)])
    cup = -5.0 * np.exp(-((x - cup_c[0]) ** 2 + (y - cup_c[1]) ** 2) / (2 * (0.07 * size_mm) ** 2))
    u = (x - x.min()) / np.ptp(x)
    v = (y.max() - y) / np.ptp(y)
    top_z = bend + half_t + ridge + cup
    if hole_uv is not None:
        d2 = ((u - hole_uv[0]) * np.ptp(x)) ** 2 + ((v - hole_uv[1]) * np.ptp(y)) ** 2
        top_z = top_z - 0.8 * thickness_mm * np.exp(-d2 / (2 * 2.5**2))
    bottom_z = bend - half_t
    n_ring = n_radial * n_angular
    top = np.column_stack([x, y, top_z])
    bottom = np.column_stack([x, y, bottom_z])
    # rim ring (rho = 1) shared: use the top's last ring for both sides so the surface is watertight
    # centre vertices of the two fans sit at the mean height of the innermost ring
    vertices = np.vstack([[0, 0, top_z[:n_angular].mean()], top, [0, 0, bottom_z[:n_angular].mean()], bottom])
    uv = np.vstack([[(0 - x.min()) / np.ptp(x), y.max() / np.ptp(y)], np.column_stack([u, v])] * 2)

    def cap_faces(centre: int, first: int) -> np.ndarray:
        j = np.arange(n_angular)
        fan = np.column_stack([np.full(n_angular, centre), first + j, first + (j + 1) % n_angular])
        r, c = np.meshgrid(np.arange(n_radial - 1), j, indexing="ij")
        a = first + r * n_angular + c
        b = first + r * n_angular + (c + 1) % n_angular
        a2, b2 = a + n_angular, b + n_angular
        quads = np.concatenate([np.column_stack([a.ravel(), a2.ravel(), b2.ravel()]),
                                np.column_stack([a.ravel(), b2.ravel(), b.ravel()])])
        return np.concatenate([fan, quads])

    top_f = cap_faces(0, 1)
    bottom_f = cap_faces(n_ring + 1, n_ring + 2)[:, ::-1]
    # weld: the bottom's rim vertices are replaced by the top's rim vertices
    rim_bottom = n_ring + 2 + (n_radial - 1) * n_angular + np.arange(n_angular)
    rim_top = 1 + (n_radial - 1) * n_angular + np.arange(n_angular)
    remap = np.arange(len(vertices))
    remap[rim_bottom] = rim_top
    faces = remap[np.concatenate([top_f, bottom_f])].astype(np.int32)
    return Mesh(vertices, faces, uv, vertex_normals(vertices, faces), texture, material)
