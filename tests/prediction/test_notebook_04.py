"""Notebook 04 on tests/params_tiny.yaml and synthetic tables whose envelopes are known (hygiene:
tests/test_workflow.py)."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import papermill
import pytest
from pred_synthetic import scene_tables

from artifact_models.tiny import TINY_PARAMS
from poseintegrity.prediction import FITTED_PREDICTORS, FREE_WIDTH_PREDICTORS, NO_FIT

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK = ROOT / "notebooks" / "04_predictor_sweeps.ipynb"
FIGURES = ["04_fig5_long_range.png", "04_fig6_pnp.png", "04_fig7_straight_line.png", "04_fig8_next_step.png",
           "04_free_width.png", "04_loso.png", "04_model_choice.png", "04_relative_thresholds.png", "04_tails.png",
           "04_uncertainty.png"]  # fmt: skip


@pytest.mark.notebook
def test_notebook_runs_on_tiny_params(tmp_path, tiny):
    """Stage 04 alone on the tiny params (``tiny`` fails the test if they do not validate)."""
    protocol = tiny.protocol
    main, validation = (scene_tables(protocol, seed, n_arcs=3, n_lines=1, images_per_stop=2, world=world)
                        for seed, world in ((0, "main"), (1, "validation")))
    artifacts, envelopes = (pd.concat(parts, ignore_index=True) for parts in zip(main, validation))
    (tmp_path / "data" / "artifacts").mkdir(parents=True)
    artifacts.to_parquet(tmp_path / "data" / "artifacts" / "artifacts.parquet", index=False)
    envelopes.to_parquet(tmp_path / "data" / "artifacts" / "envelopes.parquet", index=False)

    papermill.execute_notebook(
        str(NOTEBOOK), str(tmp_path / "04.ipynb"), kernel_name="python3", cwd=str(tmp_path), progress_bar=False,
        parameters={"params_path": str(TINY_PARAMS), "data_dir": "data", "reports_dir": "reports"},
    )  # fmt: skip

    metrics = json.loads((tmp_path / "reports" / "metrics" / "predictors.json").read_text())
    for predictor in ("static", "long_range", "mlp", "next_step", *FREE_WIDTH_PREDICTORS):
        assert set(protocol.tolerance_names) <= set(metrics[predictor])
    assert {"straight_line", "pnp", "loso", "live", "fit_status", "tails", "envelope_rules",
            "model_choice"} <= set(metrics)
    assert set(metrics["model_choice"]["main"]) == set(tiny.predict.model_choice)  # every candidate, scored
    validation = json.loads((tmp_path / "reports" / "metrics" / "validation.json").read_text())
    for predictor in ("static", "long_range", "mlp", "next_step"):  # the keys
        for tolerance in protocol.tolerance_names:
            assert "max_mean_spl_zero_incursion" in validation[predictor][tolerance]
            assert {"incursion_rate", "mean_spl"} <= set(validation["transfer"][predictor][tolerance])
    tails = pd.read_parquet(tmp_path / "data" / "predictions" / "tails.parquet")
    for predictor, entry in metrics["tails"].items():  # the table the notebook shows is the one the metrics count
        for tolerance, counted in entry.items():
            listed = tails[(tails.predictor == predictor) & (tails.tolerance == tolerance)]
            assert counted == {"n_overshooting": len(listed), "datasets": sorted(listed.dataset)}
    table = pd.read_parquet(tmp_path / "data" / "predictions" / "predictions.parquet")
    table = table[table.world == "main"]  # predictors.json: the main world (validation.json the other)
    for predictor in FITTED_PREDICTORS:
        rows = table[(table.predictor == predictor) & (table.tolerance == protocol.tolerance_names[0])]
        assert metrics["fit_status"][predictor]["n_rows"] == len(rows)
        assert metrics["fit_status"][predictor][NO_FIT] == pytest.approx((rows.fit_status == NO_FIT).mean())
    assert sorted(p.name for p in (tmp_path / "reports" / "figures").glob("04_*.png")) == FIGURES
