"""Recorded datasets of every kind through `.venv/bin/dvc repro`, exactly as the README says, with a PATH that holds
no Python of the project (its venv's `python` is found through venv-on-path.pth), in temporary copies of the project.

One run covers the cases, through datasets written by a user's own script (foreign_datasets.py: cv2, yaml and csv,
never the exporter), in three worlds:

- ``lab_a`` and ``lab_b``, named by the user: the first (where the operating points are chosen) of straight lines
  only, the second (held out) of an arc and a line: both trajectory types in the run; colour 16-bit TIFF with board
  ground truth, mono 8-bit PNG of two sizes with pose ground truth.
- ``recorded``, the format's default (no ``world`` field), reported as a further world: arcs only, one out to 175 deg
  (``protocol.arc_span_deg: 180``), pose ground truth on colour 8-bit JPEGs of 360 x 240 px with theta given, board
  ground truth on mono 16-bit PNGs of 320 x 200 px with theta computed from the poses.

Every output dvc.yaml declares must exist, and the summary must say what was measured on the data without judging
a rendered world. What a run of one world only writes (no held-out world, a first world of arcs only) is checked on
the summary's side in tests/report/test_recorded.py. The run starts from the session's project copy in which stage
06 (marker tracking, which reads no recording) is done (tests/project_copy.py, stage_06_project): DVC finds it
unchanged and runs the other six stages. It prints its wall time and CPU seconds (`pytest -s`).
"""

from __future__ import annotations

import json
import shutil

import cv2
import numpy as np
import pandas as pd
import pytest
import yaml

from foreign_datasets import Folder, write_folder
from poseintegrity.localization.dataset import load_dataset, recorded_worlds
from poseintegrity.report.claims import TITLE
from project_copy import DVC, run, stage_06_project, write_params
from repository import ROOT

FOLDERS = [
    Folder("line_a", trajectory="line", stops=(0.0, 30.0, 60.0, 90.0, 120.0), world="lab_a", seed=2),
    Folder("arc_b", stops=(5.0, 15.0, 25.0, 35.0, 44.0), world="lab_b", ground_truth="board", colour=True, bits=16,
           suffix=".tif", seed=3, robot=True),
    Folder("line_b", trajectory="line", stops=(0.0, 40.0, 80.0, 120.0, 140.0), world="lab_b", size=(400, 250), seed=4),
    Folder("arc_poses_jpeg", stops=(5.0, 30.0, 60.0, 120.0, 175.0), colour=True, suffix=".jpg", size=(360, 240),
           robot=True),
    Folder("arc_board_16", ground_truth="board", bits=16, images_per_stop=2, positions=False, seed=1),
]
OVERLAY = {"protocol": {"arc_span_deg": 180.0}}  # arc_poses_jpeg's last stop; the others end within it
pytestmark = pytest.mark.pipeline


def declared_outputs() -> list[str]:
    stages = yaml.safe_load((ROOT / "dvc.yaml").read_text())["stages"]
    return [next(iter(out)) if isinstance(out, dict) else out for stage in stages.values() for out in stage["outs"]]


@pytest.fixture(scope="module")
def recorded_project(tmp_path_factory, run_once):
    """The recordings written into a copy of the stage-06 project and `dvc repro` run there; every declared output
    written."""
    copy = tmp_path_factory.mktemp("recorded")
    shutil.copytree(run_once("stage_06", stage_06_project), copy, dirs_exist_ok=True,
                    ignore=shutil.ignore_patterns(".done"))
    for folder in FOLDERS:
        write_folder(copy / "recordings", folder)
    write_params(copy, {"generate": {"source": "recordings"}, **OVERLAY})
    output, seconds, cpu = run([str(DVC), "repro"], copy)
    print(f"dvc repro of the recordings: {seconds:.0f} s wall, {cpu:.0f} s CPU")
    assert "'06_marker_tracking' didn't change" in output  # the copy's stage 06 was taken as done
    missing = [out for out in declared_outputs() if not (copy / out).exists()]
    assert not missing, f"declared outputs not written: {missing}\n{output[-3000:]}"
    return copy


def test_stage_01_brings_every_dataset_in(recorded_project):
    """Every dataset brought in, its images 8-bit gray of its own size; no calibration session, said so."""
    copy = recorded_project
    generate = json.loads((copy / "reports/metrics/generate.json").read_text())
    assert generate["source"] == str(copy / "recordings") and generate["n_datasets"] == len(FOLDERS)
    assert set(generate["worlds"]) == {"lab_a", "lab_b", "recorded"}
    for folder in FOLDERS:
        images = sorted((copy / "data/datasets" / folder.name / "images").glob("*.png"))
        assert len(images) == len(folder.stops) * folder.images_per_stop
        image = cv2.imread(str(images[0]), cv2.IMREAD_UNCHANGED)
        assert image.dtype.name == "uint8" and image.shape == folder.size[::-1]
    assert (copy / "data/calibration/README.txt").read_text().startswith("No calibration session")


def test_the_summary_says_what_was_measured_and_judges_no_rendered_world(recorded_project):
    """The summary says what was measured on each dataset and judges no rendered world; the metrics name the
    worlds as the user did: the first where the operating points are chosen, the second held out, the third
    reported beside it."""
    copy = recorded_project
    summary = (copy / "reports/summary.md").read_text()
    section = summary.split("## Your recorded data: what was measured", 1)[1].split("\n## ", 1)[0]
    for folder in FOLDERS:
        assert f"| {folder.world or 'recorded'} | {folder.name} | {folder.trajectory} |" in section
    assert "Stage 01 · rendered robot datasets" not in summary and "realism bars passed" not in summary
    # the first screen (report/claims.py): the claims on the user's worlds, before any stage table
    first = summary.split(f"## {TITLE}", 1)[1].split("\n## ", 1)[0].splitlines()
    assert len(first) <= 40 and summary.index(f"## {TITLE}") < summary.index("## Your recorded data")
    worlds = {"lab_a", "lab_b"}  # the first world (operating points chosen) and the held-out one; the third is beside
    assert {cell[len("ours: "):] for cell in next(line for line in first if line.startswith("| claim")).split(" | ")
            if cell.startswith("ours: ")} == worlds
    headline = json.loads((copy / "reports/metrics/headline.json").read_text())
    assert set(headline) - {"tracking"} <= worlds and "a_markers4" in headline["tracking"]
    headlines = "\n".join(page.read_text() for page in (copy / "reports/stages").glob("*.md"))  # the stages' tables
    rows = [line.split("|") for line in headlines.splitlines() if line.startswith("| ") and line.count("|") == 5]
    assert rows and all(cells[4].strip() in ("-", "---", "target") for cells in rows)  # no rendered-world target
    artifacts = json.loads((copy / "reports/metrics/artifacts.json").read_text())
    validation = json.loads((copy / "reports/metrics/validation.json").read_text())
    assert {row["world"] for row in artifacts["datasets"]} == {"lab_a"}
    assert {row["dataset"] for row in artifacts["worlds"]["lab_b"]["datasets"]} == {"arc_b", "line_b"}
    further = {row["dataset"]: row["last_stop"] for row in artifacts["worlds"]["recorded"]["datasets"]}
    assert further["arc_poses_jpeg"] == 175.0 and further["arc_board_16"] == pytest.approx(35.0, abs=1e-6)
    assert validation["world"] == "lab_b" and validation["chosen_on"] == "lab_a"
    assert "No arcs in this world" in section and "Held-out world `lab_b`" in section
    assert "No arcs in `lab_a`: no arc operating point to apply." in section and "| lines: predictor |" in section


def test_both_kinds_of_ground_truth_are_measured_and_nothing_is_judged_as_a_world(recorded_project):
    """arc_poses_jpeg is measured against its recorded poses (no board judged), arc_board_16 against the board in its
    images; nothing is rendered, calibrated or judged as a world."""
    copy = recorded_project
    data = copy / "data"
    assert load_dataset(data, "datasets/arc_poses_jpeg").meta["ground_truth"] == "poses"
    assert load_dataset(data, "datasets/arc_board_16").meta["ground_truth"] == "board"
    rows = pd.read_parquet(data / "artifacts" / "artifacts.parquet")
    poses = rows[rows.dataset == "arc_poses_jpeg"]
    assert set(poses.board_status) == {"no_board"} and (poses.status == "ok").any()
    assert poses.loc[poses.status == "ok", "E_t_mm"].notna().all()  # measured against the recorded poses
    assert (rows.loc[rows.dataset == "arc_board_16", "board_status"] == "ok").any()
    assert recorded_worlds(data) == {"lab_a", "lab_b", "recorded"} and not (data / "calibration" / "recorded").exists()
    realism = json.loads((copy / "reports" / "metrics" / "artifacts.json").read_text())["realism"]
    assert "passed" not in realism and "recorded data" in realism["description_only"]  # described, not judged
    assert "Realism bars: recorded data" in (copy / "reports" / "stages" / "01_generate_datasets.md").read_text()


def test_a_robot_log_is_what_the_robot_observes_and_calibrates_the_error_predictor(recorded_project):
    """The robot's poses of arc_b (board) and arc_poses_jpeg (poses) reach stage 02 as each estimate's disagreement
    with the (exact) robot, which is then its error against the truth as placed by model image 0 (the recorded poses,
    exact here: E_t itself), and stage 04 runs error_next_step_observed on them; the other datasets have none."""
    copy = recorded_project
    rows = pd.read_parquet(copy / "data" / "artifacts" / "artifacts.parquet")
    posed = rows[rows.status == "ok"]
    logged = posed.dataset.isin(["arc_b", "arc_poses_jpeg"])
    assert posed.loc[logged, "E_t_kinematic_mm"].notna().all() and posed.loc[~logged, "E_t_kinematic_mm"].isna().all()
    jpeg = posed[posed.dataset == "arc_poses_jpeg"]
    np.testing.assert_allclose(jpeg.E_t_kinematic_mm, jpeg.E_t_mm, rtol=1e-6, atol=1e-6)
    made = pd.read_parquet(copy / "data" / "predictions" / "predictions.parquet")
    assert set(made.loc[made.predictor == "error_next_step_observed", "dataset"]) == {"arc_b", "arc_poses_jpeg"}
    # issue 50: the hazard models trained on the population run on every recorded arc, robot log or not (a column
    # the recording lacks is filled with the training median)
    arcs = made[(made.trajectory == "arc") & (made.method == made.loc[made.predictor == "next_step", "method"].iloc[0])]
    for predictor in ("hazard_next_step", "hazard_long_range"):
        assert set(arcs.loc[arcs.predictor == predictor, "dataset"]) == set(arcs.loc[arcs.predictor == "static",
                                                                                    "dataset"])
