"""Stage 02/05 driver: every frame of the datasets through the localization pipeline, one row per PnP method.

Before any work: the index, each dataset's meta.json and frames.parquet are checked (:mod:`dataset`), a
:class:`~poseintegrity.dataset_meta.DatasetError` naming the dataset and file otherwise. Then, on the
workers of the ``parallel`` section (:class:`~poseintegrity.workers.Workers`):

1. per dataset, M_t from the two model images (III-B); a model image or mask that is not the 8-bit gray image of
   camera.yaml's image size stops the stage naming it. M_t is stored beside the SIFT cache, and every frame task
   loads it from there once per worker process (a task carries its path, not its 1-2 MB of descriptors);
2. per frame (one task, results in frame order): its evidence (:mod:`evidence`: image check, CLAHE + SIFT, ratio-test
   matches to M_t, the board's checked pose; cached, so stage 05 reuses stage 02's), then PnP-RANSAC per method
   (:mod:`frame_pnp`: cached per frame, the classic RANSAC shared by EPnP, SQPnP and iterative) ->
   artifacts (III-C), the evidence that needs no ground truth (:mod:`consensus`: the inliers' bootstrap and RANSAC
   re-runs per frame and method, cached per frame; per stop the spread of its images' poses, once a dataset's rows
   are gathered) and E_t/E_r against the ground truth, the board pose of the frame (IV-C): ``E_t_mm``,
   ``E_r_deg`` (NaN without a pose, and without a trusted board pose: ``board_status`` other than "ok", e.g.
   ``bad_ground_truth`` with its ``board_reason``; such a frame keeps its localization status and n_i, it is only
   not judged); the same against a board pose refused by the trust rule's limits alone, which judges looser
   tolerances (``E_t_loose_mm``, ``E_r_loose_deg``, NaN where the board gave no consistent fit; ``truth_scale_t``,
   ``truth_scale_r``: its predicted uncertainty over the limits, :func:`.ground_truth.truth_scale`); against the
   exact renderer pose as a diagnostic: ``E_t_exact_mm``, ``E_r_exact_deg``. The board
   pose's own errors: ``E_*_board_exact`` (against the exact pose, absolute) and ``E_*_truth`` (what it adds to E_t
   and E_r: relative to model image 0's, :func:`~poseintegrity.localization.ground_truth.truth_error`; R11); the
   model placement's (``E_*_placement``: model image 0's board pose against its exact pose, ``anchor_status`` its
   check). A recorded dataset whose meta.json says ``ground_truth: poses``
   (:mod:`poseintegrity.recorded`) has no board: M_t is placed by model image 0's pose ``model.T_cam0_ref``, the
   frames' poses of frames.parquet are the ground truth of E_t/E_r (as well as of the ``_exact`` columns), and the
   board columns say ``no_board``.

Every cache file (SIFT features, evidence, PnP results, consensus columns, M_t) is used only when it proves it is
whole and current (:mod:`poseintegrity.cache_entry`), and computed again otherwise; the unfinished writes of a killed
run are removed first. The stage prints one line per dataset where it computed a file (how many, and why) and a total.

A frame whose image is unusable gives rows with status ``bad_image``, one whose exact pose in frames.parquet is not a
finite rigid transform rows with status ``bad_pose`` (a damaged file: no error is reported); a frame without a pose
gives its PnP status; a recorded frame whose pose is not known (None in frames.parquet, board ground truth) is not
flagged and its ``_exact`` errors are NaN. The ``reason`` column says why for every row whose status is not "ok"
(empty otherwise). Neither is evidence about localization: :func:`~.frame_rows.usable` drops them before
envelopes and summaries.
"""

from __future__ import annotations

from collections import Counter
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from poseintegrity.atomic_write import remove_staging_files
from poseintegrity.cache_entry import describe, tallied
from poseintegrity.dataset_meta import DatasetError
from poseintegrity.localization.consensus import stop_spread
from poseintegrity.localization.dataset import Dataset, load_dataset, load_index
from poseintegrity.localization.frame_rows import DATA_FLAGS, FrameTask, frame_rows, judged
from poseintegrity.localization.ground_truth import BoardPose, handed_over, handover
from poseintegrity.localization.model_store import ModelTask, StoredModel, store_model
from poseintegrity.params.extract import ExtractParams
from poseintegrity.workers import Workers


def handed_over_rows(tasks: list[FrameTask], results: list[tuple[list[dict[str, Any]], tuple[BoardPose, ...]]],
                     params: ExtractParams) -> list[dict[str, Any]]:
    """The rows of one dataset's frames (``tasks`` and their :func:`frame_rows` results, in order), each frame whose
    own board pose is not trusted judged by the first handover board that is (ground_truth.py, "Handover boards")."""
    rows = [list(frame_result[0]) for frame_result in results]
    if not tasks or not tasks[0].handover_boards:
        return [row for frame in rows for row in frame]
    model = tasks[0].model
    links = [handover(model.anchor, other) for other in model.handover_anchors]
    for task, frame, (_, boards) in zip(tasks, rows, results):
        if boards[0].trusted or not frame or frame[0]["status"] in DATA_FLAGS:
            continue
        for board, link in enumerate(links, start=1):
            if link is None or not boards[board].trusted:
                continue
            carried = handed_over(boards[board], link, params.ground_truth, board)
            if carried.trusted:
                frame[:] = [row | judged(row, carried, task) for row in frame]
                break
    return [row for frame in rows for row in frame]


def extract_datasets(
    datasets: list[Dataset], params: ExtractParams, methods: list[str], workers: Workers, progress: bool = True,
    consensus: bool = True,
) -> pd.DataFrame:
    """Artifact rows (one per frame and method, datasets in the given order, frames by stop and image) of checked
    datasets: M_t per dataset, then every frame, on ``workers``; then each stop's spread of poses
    (:func:`~poseintegrity.localization.consensus.stop_spread`).

    consensus : compute the consensus columns of every method (:mod:`consensus`; NaN otherwise). Stage 02 does, for
    ``protocol.pnp_method``, at ~2 ms (bootstrap) + ~15 ms (3 USAC re-runs) per frame; stage 05 does not: its five
    classic methods would cost ~50 ms more per frame, about three times its PnP, for columns no figure of it reads."""
    cache_dirs = [_cache_root(dataset.data_dir, params) / dataset.name for dataset in datasets]
    unfinished = {dataset.name: remove_staging_files(cache_dir) for dataset, cache_dir in zip(datasets, cache_dirs)}
    stored = workers.map(partial(tallied, store_model), [ModelTask(d, c, params) for d, c in zip(datasets, cache_dirs)],
                         desc="target models M_t", progress=progress)
    models = [model for model, _ in stored]
    tasks = [
        FrameTask(
            frame, dataset.path(frame["file"]), cache_dir / Path(frame["file"]).with_suffix(".npz"),
            cache_dir / Path(frame["file"]).with_suffix(".evidence.npz"), model, dataset.meta.get("board"),
            dataset.camera, tuple(methods), params, dataset.meta.get("ground_truth", "board"), exact_model_pose(dataset),
            robot_board_pose(dataset, model), tuple(dataset.meta.get("handover_boards") or ()), consensus,
        )
        for dataset, cache_dir, model in zip(datasets, cache_dirs, models)
        for frame in dataset.frames.assign(world=dataset.meta["world"], trajectory=dataset.meta["trajectory"])
            .to_dict("records")
    ]
    counted = workers.map(partial(tallied, frame_rows), tasks, desc=f"frames of {len(datasets)} dataset(s)",
                          progress=progress)
    results = [result for result, _ in counted]
    tallies = {dataset.name: tally for dataset, (_, tally) in zip(datasets, stored)}
    for task, (_, tally) in zip(tasks, counted):
        tallies[task.frame["dataset"]] += tally
    if progress:
        print(cache_report(tallies, unfinished), flush=True)
    rows = []
    for dataset in datasets:
        mine = [i for i, task in enumerate(tasks) if task.frame["dataset"] == dataset.name]
        rows += handed_over_rows([tasks[i] for i in mine], [results[i] for i in mine], params)
    table = pd.DataFrame(rows)
    return table.join(stop_spread(table)) if rows else table


def cache_report(tallies: dict[str, Counter], unfinished: dict[str, int]) -> str:
    """The lines a stage prints about its cache files (:mod:`poseintegrity.cache_entry`): one per dataset where any
    file was computed (or a killed run's unfinished write removed), then the total."""
    lines = [f"cache of {name}: {describe(tally)}" + (f"; {unfinished[name]} unfinished write(s) of a stopped run "
                                                      f"removed" if unfinished[name] else "")
             for name, tally in tallies.items()
             if unfinished[name] or set(tally) - {"checked"}]
    return "\n".join([*lines, f"cache of {len(tallies)} dataset(s): {describe(sum(tallies.values(), Counter()))}"])


def robot_board_pose(dataset: Dataset, model: StoredModel) -> np.ndarray | None:
    """T_base_board (4, 4, mm) of :mod:`kinematic_consistency`: the pose that placed M_t (the board's in model image
    0, or meta.json's T_cam0_ref with recorded poses) carried into the robot's base frame by the model view's robot
    pose; None when the dataset holds no robot poses."""
    robot = dataset.meta["model"].get("T_base_cam_robot")
    if robot is None:
        return None
    placed = (dataset.meta["model"]["T_cam0_ref"] if dataset.meta.get("ground_truth", "board") == "poses"
              else model.anchor.T_cam_board)
    return np.asarray(robot[0], dtype=np.float64) @ np.asarray(placed, dtype=np.float64)


def exact_model_pose(dataset: Dataset) -> np.ndarray | None:
    """Model image 0's exact board pose (4, 4, mm) when the dataset has one (rendered data), else None."""
    exact = dataset.meta["model"].get("exact_T_cam_board")
    return None if exact is None else np.asarray(exact[0], dtype=np.float64).reshape(4, 4)


def _cache_root(data_dir: Path, params: ExtractParams) -> Path:
    return Path(data_dir) / params.features_dir  # an absolute features_dir stays as it is


def extract_dataset(
    data_dir: str | Path, folder: str | Path, params: ExtractParams, methods: list[str], workers: Workers,
    progress: bool = True, consensus: bool = True,
) -> pd.DataFrame:
    """Artifact rows (one per frame and method) of the dataset in ``data_dir/folder`` (checked on read)."""
    return extract_datasets([load_dataset(data_dir, folder)], params, methods, workers, progress, consensus)


def extract_all(
    data_dir: str | Path, params: ExtractParams, methods: list[str], workers: Workers, progress: bool = True,
    consensus: bool = True,
) -> pd.DataFrame:
    """Artifact rows of every dataset of ``data_dir/datasets/index.parquet`` (or of ``params.datasets``), in index
    order. Every dataset is checked before any work (:mod:`~poseintegrity.localization.dataset`)."""
    index = load_index(data_dir)
    if params.datasets is not None:
        unknown = sorted(set(params.datasets) - set(index["dataset"]))
        if unknown:
            raise DatasetError(f"extract.datasets names datasets {unknown} that are not in the index; "
                               f"known: {sorted(index['dataset'])}")
        index = index[index["dataset"].isin(params.datasets)]
    datasets = [load_dataset(data_dir, row.path, row.dataset) for row in index.itertuples()]
    return extract_datasets(datasets, params, methods, workers, progress, consensus)
