"""Notebook 04 on tiny params and synthetic tables whose envelopes are known (hygiene: tests/test_workflow.py)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from pred_synthetic import TINY_FIT, TINY_PREDICT, scene_tables

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK = ROOT / "notebooks" / "04_predictor_sweeps.ipynb"
FIGURES = ["04_fig5_long_range.png", "04_fig6_pnp.png", "04_fig7_straight_line.png", "04_fig8_next_step.png",
           "04_loso.png", "04_relative_thresholds.png", "04_uncertainty.png"]  # fmt: skip


@pytest.mark.notebook
def test_notebook_runs_on_tiny_params(tmp_path):
    papermill = pytest.importorskip("papermill")
    from poseintegrity import config

    if not {"fit", "predict"} <= set(config.Params.model_fields):
        pytest.skip("poseintegrity.config.Params has no `fit` / `predict` section yet (not wired by the lead)")
    predict = {**TINY_PREDICT, "n_t_max": 40, "n_static": 46}  # fewer operating points: a quicker run
    (tmp_path / "params.yaml").write_text(yaml.safe_dump({"fit": TINY_FIT, "predict": predict}))
    artifacts, envelopes = scene_tables(n_arcs=3, n_lines=1, images_per_stop=2)
    (tmp_path / "data" / "artifacts").mkdir(parents=True)
    artifacts.to_parquet(tmp_path / "data" / "artifacts" / "artifacts.parquet", index=False)
    envelopes.to_parquet(tmp_path / "data" / "artifacts" / "envelopes.parquet", index=False)

    papermill.execute_notebook(
        str(NOTEBOOK), str(tmp_path / "04.ipynb"), kernel_name="python3", cwd=str(tmp_path), progress_bar=False,
        parameters={"params_path": "params.yaml", "data_dir": "data", "reports_dir": "reports"},
    )  # fmt: skip

    metrics = json.loads((tmp_path / "reports" / "metrics" / "predictors.json").read_text())
    for predictor in ("static", "long_range", "mlp", "next_step"):
        assert {"2mm_3deg", "4mm_10deg"} <= set(metrics[predictor])
    assert {"straight_line", "pnp", "loso", "live"} <= set(metrics)
    assert sorted(p.name for p in (tmp_path / "reports" / "figures").glob("04_*.png")) == FIGURES
    assert (tmp_path / "data" / "predictions" / "predictions.parquet").exists()
