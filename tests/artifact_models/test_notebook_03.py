"""Notebook 03 on a synthetic stage-02 table drawn from eq. 1 (hygiene: tests/test_workflow.py)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import papermill
import pytest
import yaml

from poseintegrity.artifact_models.synthetic import synthetic_artifacts

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK = ROOT / "notebooks" / "03_fit_artifact_models.ipynb"
MODELS = {"emg", "exponential", "gaussian", "logistic", "power_law", "mlp_scratch", "mlp_pretrained"}


@pytest.mark.notebook
def test_notebook_runs_on_synthetic_artifacts(tmp_path, tiny_fit_raw):
    """Stage 03 alone, on a synthetic stage-02 table (tests/test_notebooks.py runs it after stage 02)."""
    (tmp_path / "params.yaml").write_text(yaml.safe_dump({"fit": tiny_fit_raw}))
    artifacts, _ = synthetic_artifacts(np.random.default_rng(3), n_arcs=2, n_lines=1)
    (tmp_path / "data" / "artifacts").mkdir(parents=True)
    artifacts.to_parquet(tmp_path / "data" / "artifacts" / "artifacts.parquet", index=False)

    papermill.execute_notebook(
        str(NOTEBOOK), str(tmp_path / "03.ipynb"), kernel_name="python3", cwd=str(tmp_path), progress_bar=False,
        parameters={"params_path": "params.yaml", "data_dir": "data", "reports_dir": "reports"},
    )  # fmt: skip

    table = pd.read_parquet(tmp_path / "data" / "fits" / "fig2_rmse.parquet")
    assert set(table.model) == MODELS and sorted(table.k.unique()) == [3, 4, 5]
    assert len(table) == 3 * 3 * len(MODELS)
    metrics = json.loads((tmp_path / "reports" / "metrics" / "fits.json").read_text())
    assert set(metrics["rmse_k4"]) == MODELS and set(metrics["converged"]) == MODELS
    assert set(metrics["line_rmse_k5"]) == MODELS
    figures = sorted(p.name for p in (tmp_path / "reports" / "figures").glob("03_*.png"))
    assert figures == ["03_example_fits.png", "03_fig2_mean_rmse.png"]
