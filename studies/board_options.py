"""Which ground-truth board, and where (issues 30 and 39): the board's own error as it enters E_t and E_r (R11), and
the share of frames it can judge, measured on a world rendered with each option, before one is chosen for params.yaml.

For each option (``OPTIONS``: a ``generate.board``, whether the lab measures its printed boards, how flat they are, how
it calibrates), one world of stage 01 (``--world``: the main one by default, or the validation world, or the world of
another params file) is rendered with one image per stop (every arc and line), and every frame's
board pose is found and checked as stage 02 does (:func:`poseintegrity.localization.ground_truth.board_pose`, with
the world's calibrated camera). Reported per option: the share of frames whose board pose is trusted (status "ok"),
and over them the median and 99th percentile of what the ground truth adds to E_t (mm) and E_r (deg)
(:func:`~poseintegrity.localization.ground_truth.truth_error`: relative to model image 0, where M_t is placed),
beside the absolute error of model image 0's board pose (the model placement). The R11 bar: p99 <= 0.5 mm and
0.5 deg. With ``--true-camera`` the renderer's camera replaces the calibration (what the calibration adds).

    .venv/bin/python studies/board_options.py [--options planned charuco_7x5 ...] [--world validation]
        [--params held_out.yaml] [--per-dataset] [--out /tmp/board_options]

Prints one table (and with ``--per-dataset`` each dataset's board, trusted share and fewest corners); writes
``<out>/<option>/<world>/frames.parquet`` (one row per frame).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import poseintegrity  # noqa: F401  (first: it pins the CPU dispatch before numpy loads)
import numpy as np
import pandas as pd
from tqdm import tqdm

from poseintegrity.config import load_params
from poseintegrity.errors import PoseIntegrityError
from poseintegrity.lens import Camera
from poseintegrity.localization.dataset import load_dataset, load_index
from poseintegrity.localization.features import read_gray
from poseintegrity.localization.ground_truth import board_pose, truth_error
from poseintegrity.poses import pose_errors
from poseintegrity.scenes.dataset import generate
from poseintegrity.workers import Workers

CHARUCO = dict(type="charuco", dictionary="DICT_4X4_50", margin_mm=6.0, px_per_mm=8.0, placement="facing_camera")
SIZES = [12.0, 15.0, 18.0, 21.0, 24.0]
PLANNED = CHARUCO | dict(squares_x=7, squares_y=5, square_mm=15.0, marker_mm=11.0, placement="planned",
                         plan_sigma_t_mm=0.15)  # issue 39: scenes/board_plan.py
ARUCO = dict(type="aruco_grid", dictionary="DICT_4X4_50", px_per_mm=8.0)
LAB = dict(printed_boards=dict(caliper_std_mm=0.02, board_sag_std_mm=0.03, calibration_sag_std_mm=0.03),
           calibration=dict(n_views=60, max_tilt_deg=50.0))  # boards on glass, measured; a careful calibration
CARD = dict(printed_boards=dict(caliper_std_mm=None, board_sag_std_mm=0.15, calibration_sag_std_mm=0.5),
            calibration=dict(n_views=25, max_tilt_deg=40.0))  # the lab before issue 30
OPTIONS = {  # name: (generate.board, overrides of generate's sections)
    "aruco_3x2_flat_card": (ARUCO | dict(markers_x=3, markers_y=2, marker_length_mm=24.0, separation_mm=6.0,
                                         margin_mm=8.0, placement="flat"), CARD),  # the board and lab before
    "aruco_3x2_flat": (ARUCO | dict(markers_x=3, markers_y=2, marker_length_mm=24.0, separation_mm=6.0, margin_mm=8.0,
                                    placement="flat"), LAB),
    "aruco_5x4_facing": (ARUCO | dict(markers_x=5, markers_y=4, marker_length_mm=16.0, separation_mm=4.0, margin_mm=6.0,
                                      placement="facing_camera"), LAB),
    "charuco_7x5_card": (CHARUCO | dict(squares_x=7, squares_y=5, square_mm=15.0, marker_mm=11.0), CARD),
    "charuco_5x4": (CHARUCO | dict(squares_x=5, squares_y=4, square_mm=15.0, marker_mm=11.0), LAB),
    "charuco_7x5": (CHARUCO | dict(squares_x=7, squares_y=5, square_mm=15.0, marker_mm=11.0), LAB),  # issue 30
    "planned_15_one": (PLANNED | dict(sizes_mm=[15.0], max_boards=1), LAB),  # the rule's placement, one size
    "planned_one": (PLANNED | dict(sizes_mm=SIZES, max_boards=1), LAB),  # and sized per scene
    "planned": (PLANNED | dict(sizes_mm=SIZES, max_boards=2), LAB),  # and a second board where one cannot serve
    "planned_from_15": (PLANNED | dict(sizes_mm=[s for s in SIZES if s >= 15.0], max_boards=2), LAB),  # no 12 mm
}


def render(option: str, params_path: Path, out: Path, world: str) -> Path:
    """Stage 01's world ``world`` with ``option``'s board, one image per stop, under ``out / option / world``."""
    board, overrides = OPTIONS[option]
    params = load_params(params_path)
    world_params = params.generate.world(world)
    sections = {name: getattr(world_params, name).model_copy(update=values) for name, values in overrides.items()}
    generate_params = world_params.model_copy(update=sections | {
        "board": type(params.generate.board).model_validate(board), "images_per_stop": 1})
    data = out / option / world
    if not (data / "datasets" / "index.parquet").exists():
        with Workers(params.parallel) as workers:
            generate(generate_params, params.protocol, data / "datasets", workers, calibration_dir=data / "calibration")
    return data


def measure(data: Path, params_path: Path, true_camera: bool) -> pd.DataFrame:
    """One row per frame: board status, trusted or not, its errors against the exact pose (absolute and as it enters
    E_t), its predicted uncertainty."""
    ground_truth = load_params(params_path).extract.ground_truth
    rows = []
    index = load_index(data)
    for entry in tqdm(list(index.itertuples()), desc=f"datasets of {data.name}"):
        dataset = load_dataset(data, entry.path, entry.dataset)
        camera = dataset.camera
        if true_camera:
            truth = dataset.meta["true_camera"]
            camera = Camera(np.asarray(truth["K"]), np.asarray(truth["dist"]), camera.width, camera.height)
        model = dataset.meta["model"]
        anchor = board_pose(read_gray(dataset.path(model["images"][0])), dataset.meta["board"], camera, ground_truth)
        exact_0 = np.asarray(model["exact_T_cam_board"][0])
        placement = pose_errors(anchor.T_cam_board, exact_0)
        for frame in dataset.frames.itertuples():
            found = board_pose(read_gray(dataset.path(frame.file)), dataset.meta["board"], camera, ground_truth)
            exact = np.asarray(frame.T_cam_board).reshape(4, 4)
            E_t_abs, E_r_abs = pose_errors(found.T_cam_board, exact)
            E_t, E_r = truth_error(found.T_cam_board, exact, anchor.T_cam_board, exact_0)
            rows.append(dict(dataset=dataset.name, trajectory=dataset.meta["trajectory"], stop=frame.stop,
                             board_first_id=dataset.meta["board"].get("first_id", 0),
                             square_mm=dataset.meta["board"].get("square_mm", np.nan),
                             status=found.status, reason=found.reason, n_points=found.n_points,
                             n_dropped=found.n_dropped, rms_px=found.rms_px, sigma_t_mm=found.sigma_t_mm,
                             sigma_r_deg=found.sigma_r_deg, E_t_abs_mm=float(E_t_abs), E_r_abs_deg=float(E_r_abs),
                             E_t_truth_mm=E_t, E_r_truth_deg=E_r, anchor_status=anchor.status,
                             placement_E_t_mm=float(placement[0]), placement_E_r_deg=float(placement[1])))
    return pd.DataFrame(rows)


def summary(frames: pd.DataFrame) -> dict[str, float]:
    ok = frames[frames["status"] == "ok"]
    return {"trusted": float((frames["status"] == "ok").mean()),
            "not_detected": float(frames["status"].isin(["board_not_detected", "board_pnp_failed"]).mean()),
            "E_t_truth_median_mm": float(ok["E_t_truth_mm"].median()),
            "E_t_truth_p99_mm": float(ok["E_t_truth_mm"].quantile(0.99)),
            "E_r_truth_median_deg": float(ok["E_r_truth_deg"].median()),
            "E_r_truth_p99_deg": float(ok["E_r_truth_deg"].quantile(0.99)),
            "E_t_truth_max_mm": float(ok["E_t_truth_mm"].max()),
            "all_frames_E_t_truth_p99_mm": float(frames["E_t_truth_mm"].quantile(0.99)),
            "placement_E_t_max_mm": float(frames.groupby("dataset")["placement_E_t_mm"].first().max()),
            "placement_E_r_max_deg": float(frames.groupby("dataset")["placement_E_r_deg"].first().max()),
            "median_points": float(ok["n_points"].median()),
            "dropped_share": float((frames["n_dropped"] > 0).mean())}


def per_dataset(frames: pd.DataFrame) -> pd.DataFrame:
    """Per dataset: its board (square size, first marker id), the share of its frames trusted, and the fewest board
    corners (or marker corners) of a pose at any stop (0 where the board was not found)."""
    return frames.groupby("dataset").agg(
        square_mm=("square_mm", "first"), first_id=("board_first_id", "first"),
        trusted=("status", lambda status: float((status == "ok").mean())),
        min_corners=("n_points", "min"), median_sigma_t_mm=("sigma_t_mm", "median"),
        max_sigma_t_mm=("sigma_t_mm", "max"))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--options", nargs="+", default=list(OPTIONS), choices=list(OPTIONS))
    parser.add_argument("--params", default="params.yaml", type=Path)
    parser.add_argument("--out", default=Path("/tmp/board_options"), type=Path)
    parser.add_argument("--true-camera", action="store_true")
    parser.add_argument("--world", default="main", help="the world of --params to render (main, validation)")
    parser.add_argument("--per-dataset", action="store_true", help="print each dataset's trusted share too")
    args = parser.parse_args()
    results = {}
    for option in args.options:
        try:
            data = render(option, args.params, args.out, args.world)
        except PoseIntegrityError as error:  # e.g. no place for the board in some scene
            print(option, f"cannot be rendered: {error}", flush=True)
            continue
        frames = measure(data, args.params, args.true_camera)
        frames.to_parquet(data / f"frames{'_true_camera' if args.true_camera else ''}.parquet", index=False)
        results[option] = summary(frames)
        print(option, json.dumps({k: round(v, 4) for k, v in results[option].items()}), flush=True)
        if args.per_dataset:
            print(per_dataset(frames).round(3).to_string(), flush=True)
    print(pd.DataFrame(results).T.round(3).to_string())
    return 0


if __name__ == "__main__":
    sys.exit(main())
