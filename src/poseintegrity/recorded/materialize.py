"""Write checked recorded datasets into the layout stage 02 reads (``data_dir/datasets/``:
:mod:`poseintegrity.localization.dataset`), so that ``load_dataset`` and ``extract_dataset`` read them unchanged.

Per dataset, named as stage 01 names them: ``meta.json`` (dataset, world, trajectory, ``ground_truth``, board,
model pair), ``camera.yaml`` (as read, rewritten by :func:`poseintegrity.lens.write_camera_yaml`), ``frames.parquet``
(T_cam_board: the recorded pose T_cam_ref, None where none was recorded), ``model/model_<k>.png``,
``model/mask_<k>.png`` (all 255 where the folder gives no mask) and ``images/s<stop>_i<image>.png``. The index
row names the dataset its own scene (a recording is one scene). Images are converted once, to the 8-bit gray PNG the
pipeline reads (:func:`poseintegrity.recorded.reader.read_image`); an 8-bit gray PNG is copied byte for byte. Every
folder is checked before anything is written; each dataset is written into a staging folder and renamed when complete, and
``index.parquet`` is removed first and written last, so an interrupted run leaves nothing that looks complete.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from poseintegrity.atomic_write import staged
from poseintegrity.lens import write_camera_yaml
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.recorded.reader import Recorded, RecordedFormatError, range_problems, read_image, read_recorded


def _write_image(source: Path, target: Path) -> None:
    """``source`` as an 8-bit gray PNG at ``target``: copied when it is one already, else converted once."""
    image, converted = read_image(source)
    if source.suffix.lower() == ".png" and not converted:
        shutil.copyfile(source, target)
    else:
        cv2.imwrite(str(target), image)


def write_dataset(recorded: Recorded, root: Path) -> dict:
    """One checked recorded dataset as ``root / recorded.name`` (written atomically); returns its index row."""
    with staged(root / recorded.name) as tmp:
        (tmp / "model").mkdir()
        (tmp / "images").mkdir()
        model = {"images": [f"model/model_{k}.png" for k in range(2)],
                 "masks": [f"model/mask_{k}.png" for k in range(2)], "T_cam1_cam0": recorded.T_cam1_cam0.tolist()}
        if recorded.ground_truth == "poses":
            model["T_cam0_ref"] = recorded.T_cam0_ref.tolist()
        elif recorded.T_cam0_ref is not None:  # a board, and model image 0's recorded pose in its frame: the
            model["exact_T_cam_board"] = [recorded.T_cam0_ref.tolist()]  # reference of the board's own accuracy (R11)
        if recorded.model_T_base_cam is not None:  # the robot's poses: kinematic_consistency.py
            model["T_base_cam_robot"] = [T.tolist() for T in recorded.model_T_base_cam]
        for k, (image, mask) in enumerate(zip(recorded.model_images, recorded.model_masks)):
            _write_image(recorded.folder / image, tmp / model["images"][k])
            if mask is None:  # no mask: the whole image is target
                cv2.imwrite(str(tmp / model["masks"][k]),
                            np.full((recorded.camera.height, recorded.camera.width), 255, np.uint8))
            else:
                _write_image(recorded.folder / mask, tmp / model["masks"][k])
        rows = []
        for frame in recorded.frames:
            file = f"images/s{frame.stop:02d}_i{frame.image:02d}.png"
            _write_image(recorded.folder / frame.file, tmp / file)
            rows.append({"dataset": recorded.name, "stop": frame.stop, "image": frame.image,
                         "theta_deg": frame.theta_deg, "x_mm": frame.x_mm, "file": file,
                         "T_cam_board": None if frame.T_cam_ref is None else frame.T_cam_ref.ravel().tolist()}
                        | ({} if frame.T_base_cam is None else {"T_base_cam_robot": frame.T_base_cam.ravel().tolist()}))
        pd.DataFrame(rows).to_parquet(tmp / "frames.parquet", index=False)
        meta = {"dataset": recorded.name, "world": recorded.world, "trajectory": recorded.trajectory,
                "source": "recorded", "ground_truth": recorded.ground_truth, "model": model}
        if recorded.board is not None:
            meta["board"] = recorded.board
        (tmp / "meta.json").write_text(json.dumps(meta, indent=1))
        write_camera_yaml(tmp / "camera.yaml", recorded.camera, recorded.name)
    return {"dataset": recorded.name, "world": recorded.world, "scene": recorded.name,
            "trajectory": recorded.trajectory, "n_frames": len(recorded.frames), "path": f"datasets/{recorded.name}"}


def materialize(folders: list[str | Path], data_dir: str | Path, protocol: ProtocolParams | None = None,
                params_name: str = "params.yaml") -> pd.DataFrame:
    """Write the recorded dataset ``folders`` into ``data_dir/datasets/`` and its ``index.parquet`` (returned).

    Every folder is checked first (:func:`~poseintegrity.recorded.reader.read_recorded`), and its stops against the
    range ends of ``protocol`` (default: the published params.yaml's; ``params_name`` names its file in the
    messages, :func:`~poseintegrity.recorded.reader.range_problems`):
    :class:`~poseintegrity.recorded.reader.RecordedFormatError` listing the problems of all of them, nothing written.
    Two folders of the same name (the dataset's name) are refused likewise.
    """
    if protocol is None:
        from poseintegrity.config import published

        protocol = published("protocol")
    datasets, problems = [], []
    for folder in folders:
        try:
            datasets.append(read_recorded(folder))
        except RecordedFormatError as error:
            problems += error.problems
            continue
        problems += range_problems(datasets[-1], protocol, params_name)
    names = [dataset.name for dataset in datasets]
    problems += [f"{dataset.folder}: a second dataset named {dataset.name}" for dataset in datasets
                 if names.count(dataset.name) > 1]
    if not folders:
        problems.append("no recorded dataset folders given")
    if problems:
        raise RecordedFormatError(problems)
    root = Path(data_dir) / "datasets"
    root.mkdir(parents=True, exist_ok=True)
    (root / "index.parquet").unlink(missing_ok=True)
    index = pd.DataFrame([write_dataset(dataset, root) for dataset in datasets])
    index.to_parquet(root / "index.parquet", index=False)
    return index


def recorded_folders(source: str | Path) -> list[Path]:
    """The recorded dataset folders in ``source`` (a folder of them, params ``generate.source``), by name; hidden
    folders (a staging folder left by an interrupted export) are skipped."""
    return sorted(path for path in Path(source).iterdir() if path.is_dir() and not path.name.startswith("."))


def materialize_source(source: str | Path, data_dir: str | Path, protocol: ProtocolParams | None = None,
                       params_name: str = "params.yaml") -> pd.DataFrame:
    """Stage 01 with a recorded source: every dataset folder of ``source`` materialized into ``data_dir/datasets``
    (:func:`materialize`, stops checked against ``protocol``'s range ends); returns the index."""
    source = Path(source)
    if not source.is_dir():
        raise RecordedFormatError(f"{source}: not a folder (generate.source names a folder of recorded dataset "
                                  f"folders)")
    return materialize(recorded_folders(source), data_dir, protocol, params_name)
