"""Stage 06's notebook on the tiny parameters writes its metrics and figures. It depends on no other stage, so it
runs once per test session on whichever worker comes first (run_once): here, or in the pipeline chain of
tests/test_notebooks.py, whose report reads its metrics."""

import json

import pytest

from notebook_run import stage_06

FIGURES = ["06_errors.png", "06_noise_vs_lag.png", "06_occlusion.png", "06_small_blobs.png", "06_success_rate.png"]


@pytest.mark.notebook
def test_stage_06_writes_tracking_metrics_and_figures(run_once):
    reports = run_once("stage_06", stage_06) / "reports"
    metrics = json.loads((reports / "metrics" / "tracking.json").read_text())
    assert metrics["n_frames"] > 0 and {"rms", "occlusion_rms_deg", "sigmas_motion_a"} <= set(metrics)
    assert sorted(p.name for p in (reports / "figures").glob("06_*.png")) == FIGURES
