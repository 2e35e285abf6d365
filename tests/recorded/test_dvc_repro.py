"""Recorded datasets of every kind through `.venv/bin/dvc repro`, exactly as the README says, with a PATH that holds
no Python of the project (its venv's `python` is found through venv-on-path.pth), in temporary copies of the project.

Two runs cover the cases between them, through datasets written by a user's own script (foreign_datasets.py: cv2,
yaml and csv, never the exporter):

- ``arcs``: arcs only, one world, the format's defaults (no ``world`` field: ``recorded``), one arc out to 175 deg
  (``protocol.arc_span_deg: 180``), pose ground truth on colour 8-bit JPEGs of 360 x 240 px with theta given, board
  ground truth on mono 16-bit PNGs of 320 x 200 px with theta computed from the poses.
- ``worlds``: two worlds named by the user, the first (``lab_a``) of straight lines only, the second (``lab_b``) of an
  arc and a line: lines only where the operating points are chosen, both trajectory types in the run, a held-out
  world; colour 16-bit TIFF with board ground truth, mono 8-bit PNG of two sizes with pose ground truth.

Every output dvc.yaml declares must exist, and the summary must say what was measured on the data without judging
a rendered world. Each run starts from the session's project copy in which stage 06 (marker tracking, which reads no
recording) is done (tests/project_copy.py, stage_06_project): DVC finds it unchanged and runs the other six stages.
Each run prints its wall time and CPU seconds (`pytest -s`).
"""

from __future__ import annotations

import json
import shutil

import cv2
import pandas as pd
import pytest
import yaml

from foreign_datasets import Folder, write_folder
from poseintegrity.localization.dataset import load_dataset, recorded_worlds
from poseintegrity.report.claims import TITLE
from project_copy import DVC, run, stage_06_project, write_params
from repository import ROOT

RUNS = {
    "arcs": ([Folder("arc_poses_jpeg", stops=(5.0, 30.0, 60.0, 120.0, 175.0), colour=True, suffix=".jpg",
                     size=(360, 240)),
              Folder("arc_board_16", ground_truth="board", bits=16, images_per_stop=2, positions=False, seed=1)],
             {"protocol": {"arc_span_deg": 180.0}}),
    "worlds": ([Folder("line_a", trajectory="line", stops=(0.0, 30.0, 60.0, 90.0, 120.0), world="lab_a", seed=2),
                Folder("arc_b", stops=(5.0, 15.0, 25.0, 35.0, 44.0), world="lab_b", ground_truth="board", colour=True,
                       bits=16, suffix=".tif", seed=3),
                Folder("line_b", trajectory="line", stops=(0.0, 40.0, 80.0, 120.0, 140.0), world="lab_b",
                       size=(400, 250), seed=4)],
               {}),
}


def declared_outputs() -> list[str]:
    stages = yaml.safe_load((ROOT / "dvc.yaml").read_text())["stages"]
    return [next(iter(out)) if isinstance(out, dict) else out for stage in stages.values() for out in stage["outs"]]


def repro(name, tmp_path, run_once):
    """The run ``name``: its recordings written, `dvc repro` in a copy of the stage-06 project, every declared output
    there; the stage 01 and summary checks."""
    shutil.copytree(run_once("stage_06", stage_06_project), tmp_path, dirs_exist_ok=True,
                    ignore=shutil.ignore_patterns(".done"))
    folders, overlay = RUNS[name]
    for folder in folders:
        write_folder(tmp_path / "recordings", folder)
    write_params(tmp_path, {"generate": {"source": "recordings"}, **overlay})
    output, seconds, cpu = run([str(DVC), "repro"], tmp_path)
    print(f"dvc repro of {name}: {seconds:.0f} s wall, {cpu:.0f} s CPU")
    assert "'06_marker_tracking' didn't change" in output  # the copy's stage 06 was taken as done
    missing = [out for out in declared_outputs() if not (tmp_path / out).exists()]
    assert not missing, f"declared outputs not written: {missing}\n{output[-3000:]}"
    check_stage_01(name, tmp_path)
    check_summary(name, tmp_path)


# A class per run: xdist's --dist loadscope gives each class, not only each module, to one worker, so the two runs
# go to both workers at once.
@pytest.mark.notebook
class TestArcs:
    def test_dvc_repro_runs_recorded_data_end_to_end(self, tmp_path, run_once):
        repro("arcs", tmp_path, run_once)
        check_ground_truth_kinds(tmp_path)


@pytest.mark.notebook
class TestWorlds:
    def test_dvc_repro_runs_recorded_data_end_to_end(self, tmp_path, run_once):
        repro("worlds", tmp_path, run_once)


def check_stage_01(name, copy):
    """Every dataset brought in, its images 8-bit gray of its own size; no calibration session, said so."""
    generate = json.loads((copy / "reports/metrics/generate.json").read_text())
    folders, _ = RUNS[name]
    assert generate["source"] == str(copy / "recordings") and generate["n_datasets"] == len(folders)
    assert set(generate["worlds"]) == {folder.world or "recorded" for folder in folders}
    for folder in folders:
        images = sorted((copy / "data/datasets" / folder.name / "images").glob("*.png"))
        assert len(images) == len(folder.stops) * folder.images_per_stop
        image = cv2.imread(str(images[0]), cv2.IMREAD_UNCHANGED)
        assert image.dtype.name == "uint8" and image.shape == folder.size[::-1]
    assert (copy / "data/calibration/README.txt").read_text().startswith("No calibration session")


def check_summary(name, copy):
    """The summary says what was measured on each dataset and judges no rendered world; the metrics name the
    worlds as the user did."""
    summary = (copy / "reports/summary.md").read_text()
    section = summary.split("## Your recorded data: what was measured", 1)[1].split("\n## ", 1)[0]
    for folder in RUNS[name][0]:
        assert f"| {folder.world or 'recorded'} | {folder.name} | {folder.trajectory} |" in section
    assert "Stage 01 · rendered robot datasets" not in summary and "realism bars passed" not in summary
    # the first screen (report/claims.py): the claims on the user's worlds, before any stage table
    first = summary.split(f"## {TITLE}", 1)[1].split("\n## ", 1)[0].splitlines()
    assert len(first) <= 40 and summary.index(f"## {TITLE}") < summary.index("## Your recorded data")
    worlds = {folder.world or "recorded" for folder in RUNS[name][0]}
    assert {cell[len("ours: "):] for cell in next(line for line in first if line.startswith("| claim")).split(" | ")
            if cell.startswith("ours: ")} == worlds
    headline = json.loads((copy / "reports/metrics/headline.json").read_text())
    assert set(headline) - {"tracking"} <= worlds and "a_markers4" in headline["tracking"]
    headlines = summary.split("## Stage wall times")[0]  # the tables "figure | ours | paper | target"
    rows = [line.split("|") for line in headlines.splitlines() if line.startswith("| ") and line.count("|") == 5]
    assert rows and all(cells[4].strip() in ("-", "---", "target") for cells in rows)  # no rendered-world target
    artifacts = json.loads((copy / "reports/metrics/artifacts.json").read_text())
    validation = json.loads((copy / "reports/metrics/validation.json").read_text())
    if name == "arcs":
        assert {row["world"] for row in artifacts["datasets"]} == {"recorded"} and not artifacts["worlds"]
        last = {row["dataset"]: row["last_stop"] for row in artifacts["datasets"]}
        assert last["arc_poses_jpeg"] == 175.0 and last["arc_board_16"] == pytest.approx(35.0, abs=1e-6)
        assert validation["world"] is None and "one world only (recorded)" in section
        assert "No straight lines in this world" in section
    else:
        assert {row["world"] for row in artifacts["datasets"]} == {"lab_a"}
        assert {row["dataset"] for row in artifacts["worlds"]["lab_b"]["datasets"]} == {"arc_b", "line_b"}
        assert validation["world"] == "lab_b" and validation["chosen_on"] == "lab_a"
        assert "No arcs in this world" in section and "Held-out world `lab_b`" in section
        assert "No arcs in `lab_a`: no arc operating point to apply." in section and "| lines: predictor |" in section


def check_ground_truth_kinds(copy):
    """The arcs run holds both kinds of ground truth: arc_poses_jpeg is measured against its recorded poses (no board
    judged), arc_board_16 against the board in its images; nothing is rendered, calibrated or judged as a world."""
    data = copy / "data"
    assert load_dataset(data, "datasets/arc_poses_jpeg").meta["ground_truth"] == "poses"
    assert load_dataset(data, "datasets/arc_board_16").meta["ground_truth"] == "board"
    rows = pd.read_parquet(data / "artifacts" / "artifacts.parquet")
    poses = rows[rows.dataset == "arc_poses_jpeg"]
    assert set(poses.board_status) == {"no_board"} and (poses.status == "ok").any()
    assert poses.loc[poses.status == "ok", "E_t_mm"].notna().all()  # measured against the recorded poses
    assert (rows.loc[rows.dataset == "arc_board_16", "board_status"] == "ok").any()
    assert recorded_worlds(data) == {"recorded"} and not (data / "calibration" / "recorded").exists()
    realism = json.loads((copy / "reports" / "metrics" / "artifacts.json").read_text())["realism"]
    assert "passed" not in realism and "recorded data" in realism["description_only"]  # described, not judged
    assert "Realism bars: recorded data" in (copy / "reports" / "summary.md").read_text()
