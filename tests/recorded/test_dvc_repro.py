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
a rendered world. Each run prints its wall time and CPU seconds (`pytest -s`).
"""

from __future__ import annotations

import json

import cv2
import pytest
import yaml

from foreign_datasets import Folder, write_folder
from project_copy import DVC, project_copy, run
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


@pytest.fixture(scope="session")
def cache_dir(tmp_path_factory):
    """The DVC cache of the session's runs. (DVC's run cache cannot spare the second run stage 06: a stage with an
    uncached output that is neither a metric nor a plot, its timing file, is never saved to it.)"""
    return tmp_path_factory.mktemp("dvc_cache")


def declared_outputs() -> list[str]:
    stages = yaml.safe_load((ROOT / "dvc.yaml").read_text())["stages"]
    return [next(iter(out)) if isinstance(out, dict) else out for stage in stages.values() for out in stage["outs"]]


@pytest.mark.notebook
@pytest.mark.parametrize("name", list(RUNS))
def test_dvc_repro_runs_recorded_data_end_to_end(name, tmp_path, cache_dir):
    """One test per run (xdist spreads them over its workers; a run's checks share its one repro)."""
    folders, overlay = RUNS[name]
    for folder in folders:
        write_folder(tmp_path / "recordings", folder)
    project_copy(tmp_path, {"generate": {"source": "recordings"}, **overlay}, cache_dir)
    output, seconds, cpu = run([str(DVC), "repro"], tmp_path)
    print(f"dvc repro of {name}: {seconds:.0f} s wall, {cpu:.0f} s CPU")
    missing = [out for out in declared_outputs() if not (tmp_path / out).exists()]
    assert not missing, f"declared outputs not written: {missing}\n{output[-3000:]}"
    check_stage_01(name, tmp_path)
    check_summary(name, tmp_path)


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
