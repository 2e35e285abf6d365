"""A closed triangle mesh read from a file (STL, OBJ, PLY: anything trimesh reads), and its check.

Both the ``generate`` schema (the scapula's mesh is refused before any work when it is unreadable or open) and the
renderer (:mod:`poseintegrity.scenes.scapula`) read meshes through here, so that both say the same.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import TYPE_CHECKING

from poseintegrity.errors import PoseIntegrityError

if TYPE_CHECKING:
    import trimesh


class MeshError(PoseIntegrityError):
    """A mesh file or a mesh parameter cannot give a renderable, closed target."""


def read_mesh(path: Path, key: str) -> "trimesh.Trimesh":
    """A closed, consistently wound triangle mesh from ``path``; MeshError naming ``key`` and the file otherwise."""
    import trimesh  # ~0.3 s: only when a mesh file is read

    try:
        mesh = trimesh.load(str(path), force="mesh")
    except Exception as error:  # trimesh raises many types for a corrupt or unknown file
        raise MeshError(f"{key}: cannot read mesh file {path}: {error}") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise MeshError(f"{key}: {path} holds no triangles")
    if not (mesh.is_watertight and mesh.is_winding_consistent and mesh.is_volume):
        raise MeshError(
            f"{key}: {path} is not a closed manifold (watertight {mesh.is_watertight}, consistent winding "
            f"{mesh.is_winding_consistent}, encloses a volume {mesh.is_volume}); the renderer culls back faces and "
            "the drill hole needs a solid")
    return mesh


def check_mesh(path: Path, key: str) -> None:
    """:func:`read_mesh`'s checks without keeping the mesh (MeshError naming ``key`` and the file). A file already
    found closed is not read again while its size and modification time stay the same: every validation of
    ``params.yaml`` checks the scapula's mesh, and reading it was 90 % of one (0.05 s each)."""
    try:
        stat = path.stat()
    except OSError:
        read_mesh(path, key)  # the same message as any other unreadable file
        return
    _checked(str(path.resolve()), stat.st_mtime_ns, stat.st_size, key)


@functools.lru_cache(maxsize=64)  # only a successful check is remembered: a failure raises again every time
def _checked(path: str, mtime_ns: int, size: int, key: str) -> None:
    read_mesh(Path(path), key)
