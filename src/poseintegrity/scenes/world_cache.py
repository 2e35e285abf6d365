"""The scene of one session and its renderable geometry (:class:`World`), built once per process and kept while its
shots run (:func:`world`), and the heap memory its build freed given back to the kernel.
"""

from __future__ import annotations

import ctypes
from collections import OrderedDict
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from poseintegrity.params.generate import BoneFoamParams, GenerateParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.scenes import catalog, renderer
from poseintegrity.scenes.board_plan import BoardPlan
from poseintegrity.scenes.foam import ReliefVolume, bone_foam_relief
from poseintegrity.scenes.textures import build_atlas

@dataclass(frozen=True)
class World:
    """A scene and its renderable geometry; ``target_ids`` index its targets in ``geometry.object_names``."""

    scene: catalog.Scene
    geometry: renderer.SceneGeometry
    target_ids: np.ndarray


_WORLDS: OrderedDict[tuple[str, int], World] = OrderedDict()
WORLDS_KEPT = 2  # per process: the shots of one session run together, a worker seldom goes back to an earlier one


def world(params: GenerateParams, protocol: ProtocolParams, scene_index: int, session: str,
          plan: BoardPlan | None = None) -> World:
    """The scene of one session and its renderable geometry, built once per process (the last WORLDS_KEPT kept);
    ``plan``: its boards' plan, found when the world was planned (:func:`~.catalog.build_scene`)."""
    key = (params.model_dump_json(), protocol.model_dump_json(), scene_index, session,
           None if plan is None else tuple(b.placement.T_world_board.tobytes() for b in plan.boards))
    if key not in _WORLDS:
        _WORLDS[key] = _build_world(params, protocol, scene_index, session, plan)
        while len(_WORLDS) > WORLDS_KEPT:
            _WORLDS.popitem(last=False)
        give_back_freed_memory()
    _WORLDS.move_to_end(key)
    return _WORLDS[key]


def give_back_freed_memory() -> None:
    """Return the heap memory freed so far to the kernel (glibc's ``malloc_trim``; nothing where there is none).

    The Makefile keeps freed memory for reuse (``MALLOC_TRIM_THRESHOLD_`` 1 GB: SIFT's per-frame buffers), so the
    temporaries of building a world stayed resident in the render worker: at paper scale 130 MB for a world whose foam
    relief is drawn (its 128^3 FFTs), 66 MB for one that reuses it. loky restarts a worker whose memory grew by
    300 MB past what it held after its first task (a robot drive, ~350 MB); by the validation world's first shot a
    render worker held 310-330 MB more and was restarted, in every stage-01 run, with "A worker stopped while some
    jobs were given to the executor" (and built its worlds again). Given back, they peak ~210 MB above it."""
    trim = getattr(ctypes.CDLL(None), "malloc_trim", None)  # the C library this process runs on
    if trim is not None:
        trim(0)


@lru_cache(maxsize=2)
def _relief(bone_foam: BoneFoamParams, seed: int) -> ReliefVolume:
    """The foam's relief: one material, the same in every scene of a world, drawn once per process."""
    return bone_foam_relief(bone_foam, seed)


def _build_world(params: GenerateParams, protocol: ProtocolParams, scene_index: int, session: str,
                 plan: BoardPlan | None) -> World:
    scene = catalog.build_scene(params.scenes[scene_index], scene_index, params, protocol, session, plan)
    atlas = build_atlas(catalog.scene_textures(scene, params))
    geometry = renderer.SceneGeometry.from_meshes(scene.placed, atlas, scene.light_dir, params.lights.intensities(),
                                                  _relief(params.bone_foam, params.seed))
    target_ids = np.array([i for i, name in enumerate(geometry.object_names) if name in scene.target_objects])
    return World(scene, geometry, target_ids)
