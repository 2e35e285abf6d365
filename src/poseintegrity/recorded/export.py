"""Stage-01 datasets (``data_dir/datasets/``) written out in the recorded format (:mod:`poseintegrity.recorded`).

What a rendered dataset knows becomes what a recording would hold: its images and model pair byte for byte (same
relative paths), camera.yaml as it is, board.yaml from meta.json, ``ground_truth: board``, the model pair's relative
pose as the robot reported it (dataset.yaml's T_cam1_cam0), the robot's theta_deg / x_mm per stop, and the exact
renderer pose of every frame and model image (meta.json's ``model.exact_T_cam_board``, when there) as T_cam_ref
(the board frame is the reference), and the robot's reported camera poses (``T_base_cam_robot``, when there) as
T_base_cam. Numbers are written with Python's
shortest round-tripping repr, so materializing the export gives back the same numbers (the round trip of the tests).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import yaml

from poseintegrity.atomic_write import check_new_folder, staged
from poseintegrity.localization.dataset import load_dataset, load_index
from poseintegrity.recorded.reader import write_table


def _pose_text(values) -> str:
    return " ".join(repr(float(value)) for value in np.ravel(values))


def export_dataset(data_dir: str | Path, folder: str | Path, out: str | Path) -> Path:
    """The stage-01 dataset in ``data_dir/folder`` (checked on read) as a recorded folder ``out/<dataset>``
    (written atomically); returns its path."""
    dataset = load_dataset(data_dir, folder)
    meta = dataset.meta
    with staged(Path(out) / dataset.name) as tmp:
        relatives = [*meta["model"]["images"], *meta["model"]["masks"], *dataset.frames["file"]]
        for relative in relatives:
            (tmp / relative).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(dataset.path(relative), tmp / relative)
        shutil.copyfile(dataset.folder / "camera.yaml", tmp / "camera.yaml")
        settings = {"trajectory": meta["trajectory"], "ground_truth": "board", "world": meta["world"],
                    "T_cam1_cam0": dataset.model_baseline().ravel().tolist()}
        (tmp / "dataset.yaml").write_text(yaml.safe_dump(settings, sort_keys=False))
        (tmp / "board.yaml").write_text(yaml.safe_dump(dict(meta["board"]), sort_keys=False))
        exact = meta["model"].get("exact_T_cam_board")
        robot = meta["model"].get("T_base_cam_robot")  # the robot's poses, when the dataset has them
        model_columns = ["T_cam_ref"] * bool(exact) + ["T_base_cam"] * bool(robot)
        write_table(tmp / "model.csv", ["file", "mask", *model_columns],
                    [[image, mask, *(_pose_text(poses[k]) for poses in (exact, robot) if poses)]
                     for k, (image, mask) in enumerate(zip(meta["model"]["images"], meta["model"]["masks"]))])
        stop_columns = ["file", "stop", "theta_deg", "x_mm", "T_cam_ref"] + ["T_base_cam"] * bool(robot)
        write_table(tmp / "stops.csv", stop_columns,
                    [[frame.file, int(frame.stop), repr(float(frame.theta_deg)), repr(float(frame.x_mm)),
                      _pose_text(frame.T_cam_board)] + [_pose_text(frame.T_base_cam_robot)] * bool(robot)
                     for frame in dataset.frames.itertuples()])
    return Path(out) / dataset.name


def export_all(data_dir: str | Path, out: str | Path) -> list[Path]:
    """Every dataset of ``data_dir/datasets/index.parquet`` exported into ``out`` (:func:`export_dataset`), all or
    nothing: ``out`` must be a new or empty folder (:func:`~poseintegrity.atomic_write.check_new_folder`, checked before
    any work), the datasets are written into its staging folder, which becomes ``out`` when every one is written and
    is removed on any error (a broken dataset leaves no export at all). Returns the datasets' folders."""
    out = check_new_folder(out)
    index = load_index(data_dir)
    with staged(out) as tmp:
        names = [export_dataset(data_dir, row.path, tmp).name for row in index.itertuples()]
    return [out / name for name in names]
