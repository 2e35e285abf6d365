"""Stage 06's notebook on the tiny parameters, run by `dvc repro 06_marker_tracking`, writes its metrics, figures and
timing. It depends on no other stage, so it runs once per test session on whichever worker comes first (run_once):
here, in the pipeline chain of tests/test_notebooks.py, whose report reads its metrics, or as the start of a recorded
`dvc repro` (tests/recorded/test_dvc_repro.py)."""

import json

import pytest

from project_copy import stage_06_project

FIGURES = ["06_errors.png", "06_noise_vs_lag.png", "06_occlusion.png", "06_small_blobs.png", "06_success_rate.png"]


@pytest.mark.pipeline
def test_stage_06_writes_tracking_metrics_and_figures(run_once):
    reports = run_once("stage_06", stage_06_project) / "reports"
    metrics = json.loads((reports / "metrics" / "tracking.json").read_text())
    assert metrics["n_frames"] > 0 and {"rms", "occlusion_rms_deg", "sigmas_motion_a"} <= set(metrics)
    assert sorted(p.name for p in (reports / "figures").glob("06_*.png")) == FIGURES
    assert json.loads((reports / "metrics" / "timing" / "06_marker_tracking.json").read_text())["wall_time_s"] > 0
