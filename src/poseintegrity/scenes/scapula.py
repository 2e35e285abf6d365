"""The anatomical scapula phantom (Windsor et al. IV-B, Fig. 3-4): a left human scapula mesh, scaled to an adult,
and the prepared phantom "pre-drilled for implant placement" with an oversized hole in the glenoid.

The mesh is ``poseintegrity/assets/scapula_left.stl`` ("Upper Limb Bones (Left)" by HandOT, CC BY-SA 3.0; see
``poseintegrity/assets/README.md``), read with trimesh; the hole is a boolean difference computed by manifold3d (through trimesh).
Everything that can be wrong with the mesh or the hole is found here, before any rendering, and raised as a
:class:`MeshError` naming the params key and the file.

The phantom's own frame (the frame its relief and placement refer to): origin at the glenoid centre, +z the
glenoid's outward normal (the face shown to the model camera), +x towards the inferior angle, millimetres.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import trimesh

from poseintegrity.mesh_file import MeshError, read_mesh

if TYPE_CHECKING:
    from poseintegrity.params.generate import ScapulaParams

HOLE_VOLUME_TOLERANCE = 0.3  # the hole must remove at least 70 % of its cylinder's volume from the bone


def glenoid_frame(centre_mm: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """T_stl_phantom (4, 4): the phantom frame (module docstring) in the scaled STL frame.

    centre_mm : (3,) glenoid centre (scaled STL frame, mm); normal : (3,) its outward normal (any length). +x is the STL's +z axis (towards
    the inferior angle) made orthogonal to the normal.
    """
    z = normal / np.linalg.norm(normal)
    x = np.array([0.0, 0.0, 1.0]) - z[2] * z
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = centre_mm
    return T


def drill(bone: trimesh.Trimesh, T_stl_phantom: np.ndarray, diameter_mm: float, depth_mm: float) -> trimesh.Trimesh:
    """The bone with a cylindrical hole of ``diameter_mm`` drilled ``depth_mm`` deep along the glenoid's inward
    normal from its centre (the cylinder starts 10 mm outside, so it opens the surface).

    MeshError when the hole misses the bone (it removes less than 70 % of its own volume below the surface).
    """
    length = depth_mm + 10.0
    centre = T_stl_phantom @ np.array([0.0, 0.0, 10.0 - length / 2, 1.0])
    transform = T_stl_phantom.copy()
    transform[:3, 3] = centre[:3]
    cylinder = trimesh.creation.cylinder(radius=diameter_mm / 2, height=length, sections=48, transform=transform)
    drilled = trimesh.boolean.difference([bone, cylinder], engine="manifold")
    removed = bone.volume - drilled.volume
    expected = np.pi * (diameter_mm / 2) ** 2 * depth_mm
    if removed < (1 - HOLE_VOLUME_TOLERANCE) * expected:
        raise MeshError(
            f"generate.scapula.drill: the hole at the glenoid centre removes {removed:.0f} mm^3 of bone instead of "
            f"~{expected:.0f}: it lies (partly) outside the mesh; check generate.scapula.glenoid_centre / "
            "glenoid_normal")
    return drilled


@lru_cache(maxsize=4)
def _scapula(path: str, mtime: float, length_mm: float, centre: tuple, normal: tuple, diameter_mm: float | None,
             depth_mm: float | None) -> trimesh.Trimesh:
    bone = read_mesh(Path(path), "generate.scapula.mesh")
    scale = length_mm / bone.extents.max()
    bone.apply_scale(scale)
    T_stl_phantom = glenoid_frame(scale * np.array(centre), np.array(normal))
    if diameter_mm is not None:
        bone = drill(bone, T_stl_phantom, diameter_mm, depth_mm)
    bone.apply_transform(np.linalg.inv(T_stl_phantom))
    return bone


def scapula_mesh(params: "ScapulaParams", drilled: bool) -> trimesh.Trimesh:
    """The phantom in its own frame (module docstring), mm: scaled so that its longest extent is
    ``params.length_mm``, drilled when ``drilled``. Cached per process (the boolean takes ~0.1 s)."""
    path = Path(params.mesh)
    hole = (params.drill.diameter_mm, params.drill.depth_mm) if drilled else (None, None)
    return _scapula(str(path.resolve()), path.stat().st_mtime, params.length_mm, tuple(params.glenoid_centre),
                    tuple(params.glenoid_normal), *hole).copy()
