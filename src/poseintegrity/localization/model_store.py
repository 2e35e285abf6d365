"""The target model M_t of each dataset (Windsor et al. III-B), built once per dataset on a worker and stored beside
the SIFT cache, so that a frame task carries its path, not its 1-2 MB of descriptors, and loads it once per worker
process; the board poses in model image 0 that placed it in the board frame (IV-C) travel with it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path

import numpy as np

from poseintegrity.cache_entry import Miss, read_entry, read_whole, write_entry
from poseintegrity.dataset_meta import DatasetError
from poseintegrity.localization.dataset import Dataset
from poseintegrity.localization.evidence import model_digest
from poseintegrity.localization.features import cached_features, read_gray
from poseintegrity.localization.ground_truth import BoardPose, board_from_dict, board_pose, no_pose
from poseintegrity.localization.target_model import TargetModel, build_target_model
from poseintegrity.params.extract import ExtractParams


@dataclass(frozen=True)
class ModelTask:
    """Build M_t of one dataset and store it at ``path``."""

    dataset: Dataset
    cache_dir: Path
    params: ExtractParams

    @property
    def path(self) -> Path:
        return self.cache_dir / "model" / "M_t.npz"


@dataclass(frozen=True)
class StoredModel:
    """Where a dataset's M_t is stored, its digest (part of every evidence key), size and the model pair's measured
    pixel noise; ``anchor``: the board's checked pose in model image 0 that placed M_t in the board frame (status
    ``no_board`` with recorded poses); ``handover_anchors``: the handover boards' checked poses there."""

    path: Path
    digest: str
    size: int
    anchor: BoardPose
    pixel_noise_px: float
    handover_anchors: tuple[BoardPose, ...] = ()


def dataset_model(dataset: Dataset, params: ExtractParams, cache_dir: Path) -> tuple[TargetModel, BoardPose]:
    """M_t of a dataset from its two model images (features cached like frames), and the board pose in model image
    0 that placed it. Each image and mask must be the 8-bit gray image of camera.yaml's size:
    :class:`~poseintegrity.localization.features.ImageReadError` naming the dataset and the file otherwise. A board
    that gives no pose in model image 0 stops the stage naming the dataset; one whose pose fails its checks
    (``bad_ground_truth``) still places M_t, and the anchor's status says so (artifacts.json)."""
    model = dataset.meta["model"]
    try:
        images = [read_gray(dataset.path(image), dataset.image_size) for image in model["images"]]
        masks = tuple(read_gray(dataset.path(mask), dataset.image_size) for mask in model["masks"])
    except DatasetError as error:
        raise type(error)(f"dataset {dataset.name}, model pair: {error}") from None
    features = tuple(
        cached_features(dataset.path(name), cache_dir / "model" / f"{index}.npz", params.clahe, params.sift, image=image)
        for index, (name, image) in enumerate(zip(model["images"], images))
    )
    if dataset.meta.get("ground_truth", "board") == "poses":  # recorded: M_t in the external system's frame
        T_cam0_ref = np.asarray(dataset.meta["model"]["T_cam0_ref"], dtype=np.float64)
        return build_target_model(features, masks, dataset.model_baseline(), T_cam0_ref, dataset.camera,
                                  params.ratio_test, params.model_max_reprojection_px), no_pose("no_board", "")
    anchor = board_pose(images[0], board_from_dict(dataset.meta["board"], f"dataset {dataset.name}: meta.json board"),
                        dataset.camera, params.ground_truth)  # IV-C: M_t in the board frame
    if anchor.status not in ("ok", "bad_ground_truth"):
        raise DatasetError(f"dataset {dataset.name}: the ArUco board is not found in model image "
                           f"{model['images'][0]} ({anchor.status}: {anchor.reason}), so the target model cannot be "
                           f"placed in the board frame (IV-C)")
    return build_target_model(features, masks, dataset.model_baseline(), anchor.T_cam_board, dataset.camera,
                              params.ratio_test, params.model_max_reprojection_px), anchor


def handover_anchors(dataset: Dataset, params: ExtractParams) -> tuple[BoardPose, ...]:
    """The checked poses of meta.json's handover boards in model image 0 (``board`` 1, 2, ...; ground_truth.py)."""
    others = dataset.meta.get("handover_boards") or []
    if not others:
        return ()
    image = read_gray(dataset.path(dataset.meta["model"]["images"][0]), dataset.image_size)
    return tuple(replace(board_pose(image, board_from_dict(other, f"dataset {dataset.name}: meta.json handover_boards["
                                                                  f"{n}]"), dataset.camera, params.ground_truth),
                         board=n + 1) for n, other in enumerate(others))


def store_model(task: ModelTask) -> StoredModel:
    """Build M_t of a dataset (a worker task) and store it for the frame tasks (unless stored already)."""
    model, anchor = dataset_model(task.dataset, task.params, task.cache_dir)
    digest = model_digest(model)
    stored = read_entry(task.path, digest)  # the covariances do not enter the digest (no evidence depends on them)
    if isinstance(stored, Miss) or not np.array_equal(stored["covariances"], model.covariances):
        write_entry(task.path, digest, dict(points=model.points, descriptors=model.descriptors,
                                            covariances=model.covariances, pixel_noise_px=model.pixel_noise_px))
    return StoredModel(task.path, digest, model.size, anchor, model.pixel_noise_px,
                       handover_anchors(task.dataset, task.params))


@lru_cache(maxsize=4)
def load_model(path: Path, digest: str) -> TargetModel:
    """M_t stored by :func:`store_model`, loaded once per worker process (``digest``: the one expected)."""
    stored = read_whole(path, digest)  # checked (and counted) by store_model
    if isinstance(stored, Miss):
        raise DatasetError(f"target model {path} is {stored.reason} since this stage stored it (another run on the "
                           f"same data?): re-run the stage")
    return TargetModel(stored["points"], stored["descriptors"], stored["covariances"], float(stored["pixel_noise_px"]))
