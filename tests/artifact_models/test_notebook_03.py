"""Notebook 03 on tests/params_tiny.yaml and a synthetic stage-02 table drawn from eq. 1 (hygiene:
tests/test_workflow.py)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import papermill
import pytest

from artifact_models.tiny import TINY_PARAMS
from poseintegrity.artifact_models import FIT_STATUSES
from poseintegrity.artifact_models.names import distinct_theta_needed
from poseintegrity.artifact_models.synthetic import synthetic_artifacts

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK = ROOT / "notebooks" / "03_fit_artifact_models.ipynb"


@pytest.mark.notebook
def test_notebook_runs_on_synthetic_artifacts(tmp_path, tiny):
    """Stage 03 alone, on the tiny params (``tiny`` fails the test if they do not validate) and a synthetic stage-02
    table (tests/test_notebooks.py runs it after stage 02)."""
    fit, protocol = tiny.fit, tiny.protocol
    artifacts, _ = synthetic_artifacts(np.random.default_rng(3), n_arcs=2, n_lines=1)
    (tmp_path / "data" / "artifacts").mkdir(parents=True)
    artifacts.to_parquet(tmp_path / "data" / "artifacts" / "artifacts.parquet", index=False)

    papermill.execute_notebook(
        str(NOTEBOOK), str(tmp_path / "03.ipynb"), kernel_name="python3", cwd=str(tmp_path), progress_bar=False,
        parameters={"params_path": str(TINY_PARAMS), "data_dir": "data", "reports_dir": "reports"},
    )  # fmt: skip

    table = pd.read_parquet(tmp_path / "data" / "fits" / "fig2_rmse.parquet")
    ks = list(range(fit.k_min, fit.k_max + 1))
    assert set(table.model) == set(fit.models) and sorted(table.k.unique()) == ks
    n_ks = {model: sum(k >= distinct_theta_needed(model) for k in ks) for model in fit.models}  # free width from 4
    assert len(table) == 3 * sum(n_ks.values()) and set(table.status) <= set(FIT_STATUSES)
    metrics = json.loads((tmp_path / "reports" / "metrics" / "fits.json").read_text())
    k_arc, k_line = protocol.stops_sampled("arc"), protocol.stops_sampled("line")
    assert set(metrics[f"rmse_k{k_arc}"]) == set(fit.models) and set(metrics[f"line_rmse_k{k_line}"]) == set(fit.models)
    for model in fit.models:
        shares = metrics["fit_status"][model]
        assert set(shares) == set(FIT_STATUSES) and sum(shares.values()) == pytest.approx(1.0)
        assert shares["ok"] == pytest.approx((table[table.model == model].status == "ok").mean())
    figures = sorted(p.name for p in (tmp_path / "reports" / "figures").glob("03_*.png"))
    assert figures == ["03_example_fits.png", "03_fig2_mean_rmse.png"]
