"""A frame's ground truth, its boards' checked poses, at a reference commit (each board detecting the image's ArUco
markers itself) against this tree (one detection per image shared by its boards, ground_truth.ImageMarkers, as
stage 02's frame evidence uses it), measured in the same run on real rendered frames.

Frames: ``--frames`` spread evenly over each dataset of ``--data-dir`` (stage 01's output) whose meta.json lists
handover boards (a dataset with one board detects once either way). Per frame, every board's pose by the reference's
board_pose (its ground_truth.py read from git at ``--reference``, loaded as a module of its own) and by this tree's,
run alternately ``--repeats`` times: medians of wall and CPU seconds (OpenCV on one thread, as in a stage-02
worker), this tree's over the reference's, and whether the poses are equal (every field, to the bit, NaN equal to
NaN). Then what that saves stage 02: the saved CPU-seconds per frame times the frames of the index's datasets with
handover boards, over stage 02's CPU-seconds (``--stage-seconds`` wall on ``--workers`` cores: 460 s on 2 for the
paper-scale 5 880 frames).

    .venv/bin/python benchmarks/bench_board_detection.py [--data-dir data] [--reference 1191a2f] [--frames 4]

from the repository root.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import poseintegrity  # noqa: F401 (first: pins the kernels' dispatch before numpy and OpenCV load)
import cv2
import numpy as np

from poseintegrity.boards import board_from_dict
from poseintegrity.config import load_section
from poseintegrity.localization.dataset import DatasetError, load_dataset, load_index
from poseintegrity.localization.features import read_gray
from poseintegrity.localization.ground_truth import ImageMarkers, board_pose

from git_reference import ROOT, module_at  # benchmarks/ (the scripts run from the repository root)


def reference_ground_truth(commit: str):
    """localization/ground_truth.py at ``commit``, imported as the module ``ground_truth_<commit>``."""
    return module_at(commit, "src/poseintegrity/localization/ground_truth.py")


def same(a, b) -> bool:
    """Two BoardPoses (of either module) equal in every field, to the bit (NaN equal to NaN)."""
    return all(np.array_equal(x, y, equal_nan=not isinstance(x, str))
               for x, y in zip(dataclasses.astuple(a), dataclasses.astuple(b)))


def timed(function, wall: list, cpu: list):
    start, start_cpu = time.perf_counter(), time.process_time()
    result = function()
    wall.append(time.perf_counter() - start)
    cpu.append(time.process_time() - start_cpu)
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-dir", type=Path, default=ROOT / "data")
    parser.add_argument("--reference", default="1191a2f", help="the commit before the markers were shared")
    parser.add_argument("--frames", type=int, default=4, help="frames per dataset, spread evenly")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--params", type=Path, default=ROOT / "params.yaml", help="params file of the extract section")
    parser.add_argument("--stage-seconds", type=float, default=460.0, help="stage 02's wall seconds at paper scale")
    parser.add_argument("--workers", type=int, default=2, help="the cores stage 02 ran on")
    args = parser.parse_args()
    try:
        index = load_index(args.data_dir)
    except DatasetError as error:
        print(f"no rendered datasets to measure on, nothing timed: {error} (or pass --data-dir)")
        return
    datasets = [load_dataset(args.data_dir, path) for path in index["path"]]
    handover = [dataset for dataset in datasets if dataset.meta.get("handover_boards")]
    if not handover:
        print(f"no dataset of {args.data_dir} has handover boards: one board per frame, nothing is shared")
        return
    cv2.setNumThreads(1)
    params = load_section(args.params, "extract").ground_truth
    reference = reference_ground_truth(args.reference)
    print(f"{'dataset':16s} {'frame':18s} {'old ms':>7s} {'new ms':>7s} {'ratio':>6s}   {'old CPU':>7s} "
          f"{'new CPU':>7s} {'ratio':>6s}  equal  statuses")
    total, all_equal, n_frames = {"old": [0.0, 0.0], "new": [0.0, 0.0]}, True, 0
    for dataset in handover:
        boards = [board_from_dict(b) for b in [dataset.meta["board"], *dataset.meta["handover_boards"]]]
        files = dataset.frames["file"].to_numpy()
        for file in files[np.linspace(0, len(files) - 1, args.frames).round().astype(int)]:
            image = read_gray(dataset.path(file), dataset.image_size)

            def old():
                return [reference.board_pose(image, board, dataset.camera, params) for board in boards]

            def new():
                markers = ImageMarkers(image)
                return [board_pose(image, board, dataset.camera, params, markers) for board in boards]

            wall, cpu = {"old": [], "new": []}, {"old": [], "new": []}
            for _ in range(args.repeats):  # alternately, so that both see the same machine load
                poses_old = timed(old, wall["old"], cpu["old"])
                poses_new = timed(new, wall["new"], cpu["new"])
            equal = all(map(same, poses_old, poses_new))
            all_equal &= equal
            medians = {k: (float(np.median(wall[k])), float(np.median(cpu[k]))) for k in wall}
            for k in total:
                total[k] = [t + m for t, m in zip(total[k], medians[k])]
            (ow, oc), (nw, nc) = medians["old"], medians["new"]
            print(f"{dataset.name:16s} {file:18s} {1e3 * ow:7.1f} {1e3 * nw:7.1f} {nw / ow:6.3f}   {1e3 * oc:7.1f} "
                  f"{1e3 * nc:7.1f} {nc / oc:6.3f}  {str(equal):5s}  {' '.join(p.status for p in poses_new)}",
                  flush=True)
            n_frames += 1
    (ow, oc), (nw, nc) = total["old"], total["new"]
    print(f"{n_frames} frames of {len(handover)} datasets, medians of {args.repeats} (reference {args.reference}); "
          f"per frame: old {1e3 * ow / n_frames:.1f} ms, new {1e3 * nw / n_frames:.1f} ms, ratio {nw / ow:.3f} "
          f"(CPU {1e3 * oc / n_frames:.1f} -> {1e3 * nc / n_frames:.1f} ms, ratio {nc / oc:.3f}); "
          f"poses equal in every field, to the bit: {all_equal}")
    handover_frames = sum(len(dataset.frames) for dataset in handover)
    saved = (oc - nc) / n_frames * handover_frames
    budget = args.stage_seconds * args.workers
    print(f"stage 02: {handover_frames} of {sum(len(dataset.frames) for dataset in datasets)} frames have handover "
          f"boards; "
          f"{saved:.0f} CPU-s saved of {budget:.0f} ({args.stage_seconds:g} s on {args.workers} cores): "
          f"{100 * saved / budget:.1f} % of the stage, about {saved / args.workers:.0f} s of its wall time")


if __name__ == "__main__":
    main()
