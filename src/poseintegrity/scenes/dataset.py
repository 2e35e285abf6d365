"""Stage 01: write the robot datasets of Windsor et al. IV-D to disk, for every world of ``generate``.

Layout of ``<root>/<dataset>/``: ``meta.json`` (world, scene, targets, trajectory, board, model pair),
``camera.yaml`` (the camera as the world's calibration estimated it: the pipeline's only intrinsics),
``frames.parquet`` (one row per image: stop, image, theta_deg and x_mm as the robot recorded them, file, and the
exact T_cam_board / T_cam_target of the image as row-major 16-float lists, a diagnostic), ``model/`` (the two model
images and their target masks) and ``images/``. A dataset is written into a hidden temporary folder and renamed when
complete, so an interrupted run leaves nothing that looks finished; ``<root>/index.parquet`` is written last.

How an image comes about:

1. The robot (:mod:`.robot`) is commanded to the protocol's poses (:mod:`.trajectories`) and lands slightly off them:
   each visit of a pose has its own actual pose. The model pair is visited once per scene and trajectory kind and
   serves all its datasets; the robot returns to the first model view to start each arc (a new visit).
2. Once the robot reports a stop, the camera takes a burst of ``images_per_stop`` exposures (``capture``) while
   the arm rings down (:mod:`.ringdown`): each image sees the stop's view turned by a small rotation, and blurred
   along its path during the exposure. A model image is taken once the arm has settled (``model_settle_ms``).
3. The view is rendered once per visit on the lens' ideal canvas (:mod:`.renderer`), blurred by the lens and the
   depth of field (:mod:`.optics`), warped per image by its ring-down rotation and distorted by the lens onto the
   sensor, then exposed (sensor noise).

Every world is planned first (:mod:`.world_plan`: its scenes checked, :mod:`.world_checks`; its datasets' trips,
:mod:`.trips`; its robot driven, its camera calibrated), then its images are taken (:mod:`.shots`), split into
:class:`~.shots.Shot` tasks, one per visit, run by :class:`poseintegrity.workers.Workers` (each worker builds a
session's scene once, :mod:`.world_cache`), and each dataset's files are written (:mod:`.dataset_files`). Every random
draw comes from a generator keyed by the world's seed and what it is for, so the files do not depend on the backend,
the worker count or the order the shots run in.
"""

from __future__ import annotations

import shutil
from functools import partial
from pathlib import Path

import pandas as pd

from poseintegrity.atomic_write import full_disk_named
from poseintegrity.params.generate import GenerateParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.scenes.calibration_views import write_calibration
from poseintegrity.scenes.dataset_files import CAMERA_NAME, finish_dataset
from poseintegrity.scenes.shots import IMAGE_PNG_FLAGS, partial_dataset, plan_shots, take_shot
from poseintegrity.scenes.world_plan import WorldPlan, plan_worlds
from poseintegrity.workers import Workers


def generate(params: GenerateParams, protocol: ProtocolParams, root: Path, workers: Workers, *,
             calibration_dir: Path, progress: bool = True) -> tuple[pd.DataFrame, dict[str, WorldPlan]]:
    """Render every world's datasets under ``root`` and its calibration session under ``calibration_dir / world``
    (every world planned, calibrated and checked first), the shots on ``workers``; returns the index (also written)
    and each world's plan (its calibration and robot accuracy)."""
    worlds = plan_worlds(params, protocol, workers, progress)
    root = Path(root)
    with full_disk_named(root):  # a full disk, in a worker or here: one line naming the datasets' folder
        root.mkdir(parents=True, exist_ok=True)
        (root / "index.parquet").unlink(missing_ok=True)
        rows = []
        for w in worlds.values():
            write_calibration(Path(calibration_dir) / w.name, w.calibration, w.params, CAMERA_NAME, IMAGE_PNG_FLAGS)
            for plan in w.plans:
                tmp = partial_dataset(root, plan.dataset)
                shutil.rmtree(tmp, ignore_errors=True)
                (tmp / "model").mkdir(parents=True)
                (tmp / "images").mkdir()
            shots = plan_shots(w.params, w.plans, w.trips, w.routes, {key: s.plan for key, s in w.scenes.items()})
            workers.map(partial(take_shot, w.params, protocol, root), shots,
                        desc=f"camera poses of {len(w.plans)} datasets ({w.name} world)", progress=progress)
            rows += [finish_dataset(w.params, root, plan, trip, route, w.scenes[plan.scene_index, plan.trajectory],
                                    w.calibration.calibration.camera)
                     for plan, trip, route in zip(w.plans, w.trips, w.routes)]
        index = pd.DataFrame(rows)
        index.to_parquet(root / "index.parquet", index=False)
    return index, worlds
