"""The images of a world's datasets, taken shot by shot: one :class:`Shot` per visit of the camera (the model pair once
for all datasets sharing it, each stop of each dataset), rendered once on the lens' ideal canvas and exposed for every
image taken there (:func:`take_shot`), the PNG files written into the datasets' partial folders.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np

from poseintegrity.atomic_write import partial_folder
from poseintegrity.params.generate import GenerateParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.poses import inverse
from poseintegrity.scenes import optics, renderer
from poseintegrity.scenes.acquisition import Route, image_motion, model_motion, rotation_maps
from poseintegrity.scenes.board_plan import BoardPlan
from poseintegrity.scenes.camera import Intrinsics, true_camera
from poseintegrity.scenes.trips import DatasetPlan, Trip
from poseintegrity.scenes.world_cache import world
from poseintegrity.seeding import keyed_rng

# Camera images are noisy: deflate's string matching finds almost nothing in them, so they are Huffman-coded only,
# after PNG's "average" filter (the prediction residuals are what is compressible): ~3 x faster to encode and ~12 %
# smaller than zlib level 3 with adaptive filters. Masks are flat: there string matching is what compresses.
IMAGE_PNG_FLAGS = [cv2.IMWRITE_PNG_STRATEGY, cv2.IMWRITE_PNG_STRATEGY_HUFFMAN_ONLY,
                   cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_AVG]
MASK_PNG_FLAGS = [cv2.IMWRITE_PNG_COMPRESSION, 3]


@dataclass(frozen=True)
class Exposure:
    """An image taken at a shot: its noise drawn from ``keyed_rng(generate.seed, "image", *rng_key)`` after turning the view by the
    ring-down path ``rotations`` (k, 3), written as ``file`` into the folder of every dataset in ``datasets``;
    ``mask``: the file of the target mask, written beside it (model images)."""

    datasets: tuple[str, ...]
    file: str
    rng_key: tuple
    rotations: np.ndarray
    mask: str | None = None


@dataclass(frozen=True)
class Shot:
    """One visit of the camera (T_world_cam at the reported stop) in scene ``scene_index``'s ``session`` ("arc" or
    "line"), the lens focused at ``focus_mm``: rendered once, then exposed for every image taken there."""

    scene_index: int
    session: str
    T_world_cam: np.ndarray
    focus_mm: float
    exposures: tuple[Exposure, ...]
    plan: BoardPlan | None = None  # the session's boards (found when the world was planned)


def plan_shots(params: GenerateParams, plans: list[DatasetPlan], trips: list[Trip], routes: list[Route],
               boards: dict[tuple[int, str], BoardPlan | None]) -> list[Shot]:
    """Every image of every dataset, one shot per visit (a scene's model pair once for all datasets sharing it), the
    shots of a scene together (a worker then builds each scene once); ``boards``: each session's boards' plan."""
    f_px = Intrinsics.from_params(params.camera).K[0, 0]
    shots: dict[tuple, Shot] = {}
    for plan, trip, route in zip(plans, trips, routes):
        for k, visit in enumerate(route.model):
            key = (plan.scene_index, "model", plan.trajectory, k)
            if key in shots:  # the scene's other datasets of this kind share the images
                shot = shots[key]
                shots[key] = replace(shot, exposures=tuple(
                    Exposure((*e.datasets, plan.dataset), e.file, e.rng_key, e.rotations, e.mask)
                    for e in shot.exposures))
                continue
            motion = model_motion(visit, params.capture, f_px)
            shots[key] = Shot(plan.scene_index, plan.trajectory, visit.T_world_cam, trip.focus_mm, (Exposure(
                (plan.dataset,), f"model/model_{k}.png", ("model", plan.scene_index, plan.trajectory, k),
                motion.path, f"model/mask_{k}.png"),), boards[plan.scene_index, plan.trajectory])
        for s, visit in enumerate(route.stops):
            exposures = tuple(Exposure((plan.dataset,), file, (plan.dataset, s, i),
                                       image_motion(visit, params.capture, i, f_px).path)
                              for i, file in enumerate(image_files(s, params.images_per_stop)))
            shots[(plan.dataset, s)] = Shot(plan.scene_index, plan.trajectory, visit.T_world_cam, trip.focus_mm,
                                            exposures, boards[plan.scene_index, plan.trajectory])
    # stable: the datasets' order within a session; a worker then builds each session's scene once
    return sorted(shots.values(), key=lambda shot: (shot.scene_index, shot.session))


def image_files(stop: int, images_per_stop: int) -> tuple[str, ...]:
    """The files of the images taken at stop ``stop``, relative to the dataset's folder."""
    return tuple(f"images/s{stop:02d}_i{i:02d}.png" for i in range(images_per_stop))


def partial_dataset(root: Path, dataset: str) -> Path:
    """The hidden folder a dataset is written into (its shots by the workers), renamed to ``root / dataset`` when
    complete (:func:`poseintegrity.atomic_write.partial_folder`)."""
    return partial_folder(root / dataset)


def take_shot(params: GenerateParams, protocol: ProtocolParams, root: Path, shot: Shot) -> None:
    """Render ``shot`` on the lens' ideal canvas, blur it by the lens and the depth of field, and for every image
    turn it by the image's ring-down path, distort it onto the sensor and expose it; write the images (and masks)
    into the datasets' partial folders under ``root``."""
    scene_world = world(params, protocol, shot.scene_index, shot.session, shot.plan)
    lens = true_camera(params.camera)  # its canvas and sensor maps are computed once per process
    K_canvas, width, height = lens.canvas
    frame = renderer.render(scene_world.geometry, K_canvas, width, height, inverse(shot.T_world_cam))
    irradiance = optics.lens(frame.radiance, frame.depth_mm, shot.focus_mm, params.sensor.blur_sigma_px, params.camera)
    map_x, map_y = lens.sensor_maps
    for exposure in shot.exposures:
        sensor = np.zeros(map_x.shape, np.float32)
        for rotation in exposure.rotations:  # the exposure integrates the view along the ring-down's path
            sensor += cv2.remap(irradiance, *rotation_maps(K_canvas, rotation, map_x, map_y), cv2.INTER_LINEAR,
                                borderMode=cv2.BORDER_REPLICATE)
        sensor /= len(exposure.rotations)
        image = renderer.expose(sensor, params.sensor, keyed_rng(params.seed, "image", *exposure.rng_key))
        _write_png(root, exposure.datasets, exposure.file, image, IMAGE_PNG_FLAGS)
        if exposure.mask is not None:
            middle = exposure.rotations[len(exposure.rotations) // 2]
            target = np.isin(frame.object_index, scene_world.target_ids).astype(np.uint8) * 255
            mask = cv2.remap(target, *rotation_maps(K_canvas, middle, map_x, map_y), cv2.INTER_NEAREST)
            _write_png(root, exposure.datasets, exposure.mask, mask, MASK_PNG_FLAGS)


def _write_png(root: Path, datasets: tuple[str, ...], file: str, image: np.ndarray, flags: list[int]) -> None:
    """Encode once (OpenCV ``flags``), write into every dataset's partial folder."""
    ok, encoded = cv2.imencode(".png", image, flags)
    if not ok:
        raise OSError(f"cannot encode {file} as PNG")
    for dataset in datasets:
        (partial_dataset(root, dataset) / file).write_bytes(encoded.tobytes())
