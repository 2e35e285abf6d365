"""The physical world of the experiments: targets, clutter, the ArUco board and the table (Fig. 4).

Targets are the same physical objects in every scene they appear in (their meshes and textures are seeded by
name), arranged differently per scene. World frame: table top z = 0, z up, millimetres.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.scenes import mesh as meshes
from poseintegrity.scenes.camera import rigid
from poseintegrity.scenes import textures as tex

if TYPE_CHECKING:
    from poseintegrity.scenes.params import SceneSpec

# bone-like phantoms (smooth, curved, low texture; one pre-drilled) and highly textured blocks (Fig. 4)
TARGET_NAMES = ("scapula", "scapula_drilled", "block_print", "block_mosaic")
TEXTURE_NAMES = ("scapula", "scapula_drilled", "block_print", "block_mosaic", "table", "clutter_a", "clutter_b",
                 "clutter_c", "bone_offcut")
HOLE_UV = (0.62, 0.45)  # where the drill hole of the prepared phantom is, in its texture coordinates
BLOCK_SIZE_MM = (72.0, 64.0, 58.0)


def _rng(*key: int) -> np.random.Generator:
    return np.random.default_rng([20240501, *key])


@lru_cache(maxsize=None)
def procedural_texture(name: str) -> np.ndarray:
    """The albedo map of a texture name, the same in every scene and process."""
    rng = _rng(1, TEXTURE_NAMES.index(name))
    if name in ("scapula", "scapula_drilled"):
        return tex.bone_texture(rng, 1024, HOLE_UV if name == "scapula_drilled" else None)
    if name == "bone_offcut":
        return tex.bone_texture(rng, 512)
    if name == "block_print":
        return _faint_lid(tex.collage_texture(rng, (1024, 1536), density=3.0, contrast=0.45, text=True), rng)
    if name == "block_mosaic":
        return _faint_lid(tex.collage_texture(rng, (1024, 1536), density=5.0, contrast=0.35, text=False), rng)
    if name == "table":
        return tex.wood_texture(rng, 2048)
    return tex.collage_texture(rng, (512, 512), density=0.8, contrast=0.25, text=name == "clutter_a")


def _faint_lid(albedo: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A box printed on its sides, its lid (the +z face's sixth of the texture, see
    :func:`~poseintegrity.scenes.mesh.box`) printed faintly (30 % contrast) on grey board. A fully printed lid
    seen from above is one plane with many features: arcs over the top then keep 130 inliers while the error
    grows (a 20 mm-baseline model cannot pin the tilt of a small plane); a plain lid starves those arcs within
    10 deg, leaving n_i at its chance floor for the rest of the arc."""
    h, w = albedo.shape
    rows, cols = slice(h // 2, h), slice(w // 3, 2 * w // 3)
    printed = albedo[rows, cols].astype(np.float32) / 255
    lid = 0.62 + 0.3 * (printed - printed.mean()) + 0.02 * tex.fractal_noise(rng, printed.shape, 3, 3)
    out = albedo.copy()
    out[rows, cols] = tex.to_u8(lid)
    return out


def target_mesh(name: str) -> meshes.Mesh:
    """A target in its own frame: origin at its centre, +z the face shown to the model camera."""
    if name.startswith("scapula"):
        hole = HOLE_UV if name == "scapula_drilled" else None
        return meshes.bone_plate(_rng(2, TARGET_NAMES.index(name)), name, hole_uv=hole)
    return meshes.box(BLOCK_SIZE_MM, name, material=meshes.Material(specular=0.08, shininess=30.0))


@dataclass
class Scene:
    """A laid-out scene: placed meshes, which of them are targets, the board, the model-view direction.

    T_world_target is the frame of the first target (its centre); ``aim`` is the point the camera looks at.
    """

    name: str
    placed: list[tuple[str, meshes.Mesh]]
    target_objects: tuple[str, ...]
    T_world_target: np.ndarray
    T_world_board: np.ndarray
    board: tex.BoardSpec
    aim: np.ndarray
    view_dir: np.ndarray
    light_dir: np.ndarray
    textures: dict[str, np.ndarray] = field(repr=False, default_factory=dict)


def build_scene(spec: "SceneSpec", index: int, texture_overrides: dict | None = None) -> Scene:
    """Lay out scene ``spec`` (index = its position in params, seeds the arrangement)."""
    rng = _rng(3, index)
    yaw = np.deg2rad(rng.uniform(-20, 20))  # direction of the model camera around the target
    elev = np.deg2rad(spec.elevation_deg)
    view_dir = np.array([np.sin(yaw) * np.cos(elev), -np.cos(yaw) * np.cos(elev), np.sin(elev)])
    placed: list[tuple[str, meshes.Mesh]] = [
        ("table", meshes.plane(1400.0, 1400.0, 56, 56, "table", material=meshes.Material(0.03, 8.0)))]
    target_poses = []
    for k, name in enumerate(spec.targets):
        side = np.array([np.cos(yaw), np.sin(yaw), 0.0]) * 120.0 * k  # further targets stand beside the first
        if name.startswith("scapula"):
            # the plate faces the model camera, tilted a little at random, on a stand 95 mm high
            normal = Rotation.from_rotvec(rng.uniform(-0.25, 0.25, 3)).apply(view_dir)
            in_plane = Rotation.from_rotvec(normal * rng.uniform(0, 2 * np.pi))
            z = normal / np.linalg.norm(normal)
            x = np.cross([0.0, 0.0, 1.0], z)
            x = in_plane.apply(x / np.linalg.norm(x))
            R = np.column_stack([x, np.cross(z, x), z])
            centre = side + np.array([0.0, 0.0, 95.0])
            placed.append((f"{name}_stand", meshes.cylinder(9.0, 95.0 - 25.0, "clutter_c").transformed(
                rigid(np.eye(3), side))))
        else:
            # a corner towards the model camera, so that two printed sides are in view (a 3D point set)
            R = Rotation.from_euler("z", yaw + np.pi / 4 + rng.uniform(-0.25, 0.25)).as_matrix()
            centre = side + np.array([0.0, 0.0, BLOCK_SIZE_MM[2] / 2])
        T = rigid(R, centre)
        target_poses.append(T)
        placed.append((name, target_mesh(name).transformed(T)))
    aim = np.mean([T[:3, 3] for T in target_poses], axis=0)

    # the ArUco board lies flat on the table beside the target, printed side up (board z points into the table)
    board = tex.BoardSpec()
    bw, bh = board.size_mm
    # board x points away from the target, so its origin (the model origin, where E_t is measured) is a corner
    # of the edge facing the target
    board_yaw = yaw + np.pi + rng.uniform(-0.3, 0.3)
    x_b = np.array([np.cos(board_yaw), np.sin(board_yaw), 0.0])
    R_world_board = np.column_stack([x_b, np.cross([0.0, 0.0, -1.0], x_b), [0.0, 0.0, -1.0]])
    # beside the first target and in front of it, so that both stay in view along the arcs
    board_centre = target_poses[0][:2, 3] - 92.0 * np.array([np.cos(yaw), np.sin(yaw)]) + 20.0 * view_dir[
        :2] / np.linalg.norm(view_dir[:2])
    origin = np.append(board_centre, 0.4) - R_world_board @ np.array([bw / 2, bh / 2, 0.0])
    T_world_board = rigid(R_world_board, origin)
    m = board.margin_mm
    # plane() faces +z with texture v along -y; flip about x so it faces -z (the board's printed side) with v along +y
    board_mesh = meshes.plane(bw + 2 * m, bh + 2 * m, 12, 9, "aruco_board", material=meshes.Material(0.02, 10.0))
    board_mesh = board_mesh.transformed(rigid(np.diag([1.0, -1.0, -1.0]), [bw / 2, bh / 2, 0.0]))
    placed.append(("aruco_board", board_mesh.transformed(T_world_board)))

    # clutter: boxes and cylinders around, off the line of sight of the model view and off the board
    occupied = [(aim[:2], 110.0 + 120.0 * (len(spec.targets) - 1)), (board_centre, 80.0)]
    clutter_textures = ["clutter_a", "clutter_b", "clutter_c", "bone_offcut"]
    n_placed, attempts = 0, 0
    while n_placed < spec.n_clutter and attempts < 500:
        attempts += 1
        r, a = rng.uniform(150, 420), rng.uniform(0, 2 * np.pi)
        xy = aim[:2] + r * np.array([np.cos(a), np.sin(a)])
        radius = rng.uniform(20, 55)
        towards_cam = np.dot(xy - aim[:2], view_dir[:2] / np.linalg.norm(view_dir[:2]))
        if towards_cam > 0 and abs(np.cross(view_dir[:2] / np.linalg.norm(view_dir[:2]), xy - aim[:2])) < 130:
            continue
        if any(np.linalg.norm(xy - c) < radius + rc for c, rc in occupied):
            continue
        occupied.append((xy, radius))
        texture = clutter_textures[rng.integers(len(clutter_textures))]
        if rng.random() < 0.5:
            size = (2 * radius, rng.uniform(0.5, 1.5) * radius, rng.uniform(25, 140))
            obj = meshes.box(size, texture, n_sub=4)
            T = rigid(Rotation.from_euler("z", rng.uniform(0, np.pi)).as_matrix(), [*xy, size[2] / 2])
        else:
            obj = meshes.cylinder(0.8 * radius, rng.uniform(40, 160), texture, n_seg=40)
            T = rigid(np.eye(3), [*xy, 0.0])
        placed.append((f"clutter_{n_placed}", obj.transformed(T)))
        n_placed += 1

    light_dir = np.array([rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.3), 1.0])
    overrides = texture_overrides or {}
    used = {m.texture for _, m in placed}
    textures = {name: (tex.load_texture(overrides[name]) if name in overrides else procedural_texture(name))
                for name in used if name != "aruco_board"}
    textures["aruco_board"] = board.texture()
    return Scene(spec.name, placed, tuple(spec.targets), target_poses[0], T_world_board, board, aim, view_dir,
                 light_dir, textures)
