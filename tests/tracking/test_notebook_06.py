"""Stage 06's notebook on the tiny parameters, run by `dvc repro 06_marker_tracking`, writes its metrics, figures and
timing. It depends on no other stage, so it runs once per test session on whichever worker comes first (run_once):
here, in the pipeline chain of tests/test_notebooks.py, whose report reads its metrics, or as the start of a recorded
`dvc repro` (tests/recorded/test_dvc_repro.py). Its notebook run as it is in JupyterLab, in a copy of that project,
writes the files `dvc repro` wrote, and `dvc status` says what the README says."""

import json
import re
import shutil

import pytest

from notebook_run import NotebookServer
from project_copy import DVC, run, stage_06_project

FIGURES = ["06_errors.png", "06_noise_vs_lag.png", "06_occlusion.png", "06_small_blobs.png", "06_success_rate.png"]


@pytest.mark.pipeline
def test_stage_06_writes_tracking_metrics_and_figures(run_once):
    reports = run_once("stage_06", stage_06_project) / "reports"
    metrics = json.loads((reports / "metrics" / "tracking.json").read_text())
    assert metrics["n_frames"] > 0 and {"rms", "occlusion_rms_deg", "sigmas_motion_a"} <= set(metrics)
    assert sorted(p.name for p in (reports / "figures").glob("06_*.png")) == FIGURES
    assert json.loads((reports / "metrics" / "timing" / "06_marker_tracking.json").read_text())["wall_time_s"] > 0
    speed = json.loads((reports / "metrics" / "timing" / "subroutines" / "06_marker_tracking.json").read_text())
    assert speed["speedup_vs_filterpy"] > 0 and not {"speedup_vs_filterpy", "timing_ms"} & set(metrics)


@pytest.mark.pipeline
def test_stage_06_run_in_jupyterlab_rewrites_the_outputs_dvc_repro_wrote(run_once, tmp_path):
    """README, "Reading the results": only the machine-dependent timings differ from the run of `dvc repro` (the
    replayed recording holds no run id, tracking.json no time), so `dvc status` lists that one output of stage 06 as
    modified, and nothing is written elsewhere."""
    shutil.copytree(run_once("stage_06", stage_06_project), tmp_path, dirs_exist_ok=True,
                    ignore=shutil.ignore_patterns(".done"))
    before = {p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file() and ".dvc" not in p.parts}
    with NotebookServer(tmp_path) as server:
        server.run("notebooks/06_marker_tracking.ipynb")
    after = {p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file() and ".dvc" not in p.parts}
    assert not {str(p) for p in after - before if not str(p).startswith("data/tracking/")}, "written outside its outputs"
    status, _, _ = run([str(DVC), "status", "06_marker_tracking"], tmp_path)
    assert re.findall(r"modified:\s+(\S+)", status) == ["reports/metrics/timing/subroutines/06_marker_tracking.json"], status
