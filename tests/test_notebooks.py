"""Every notebook runs, in pipeline order, on tiny parameters, and writes its metrics.

One test runs the whole chain in one temporary folder (each notebook reads the data of the one before), so
that test distribution over workers cannot split it.
"""

from pathlib import Path

import papermill
import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
ORDER = ["01_generate_datasets", "02_extract_artifacts", "05_pnp_variants", "03_fit_artifact_models",
         "04_predictor_sweeps", "06_marker_tracking", "07_report"]  # dvc.yaml's order: 04 reads 05's tables
METRICS = {  # notebook -> the metrics file it must write
    "01_generate_datasets": "generate.json",
    "02_extract_artifacts": "artifacts.json",
    "03_fit_artifact_models": "fits.json",
    "04_predictor_sweeps": "predictors.json",
    "05_pnp_variants": "pnp.json",
    "06_marker_tracking": "tracking.json",
    "07_report": None,
}


def test_order_covers_every_notebook():
    assert sorted(ORDER) == [p.stem for p in NOTEBOOKS]


@pytest.mark.notebook
def test_pipeline_notebooks_run_in_order_with_tiny_params(tmp_path):
    for name in ORDER:
        executed = tmp_path / "executed" / f"{name}.ipynb"
        executed.parent.mkdir(exist_ok=True)
        papermill.execute_notebook(
            str(ROOT / "notebooks" / f"{name}.ipynb"), str(executed), kernel_name="python3", progress_bar=False,
            cwd=str(ROOT),
            parameters={"params_path": str(ROOT / "tests" / "params_tiny.yaml"), "data_dir": str(tmp_path / "data"),
                        "reports_dir": str(tmp_path / "reports")},
        )
        if METRICS[name]:
            assert (tmp_path / "reports" / "metrics" / METRICS[name]).is_file(), f"{name} wrote no metrics"
    summary = (tmp_path / "reports" / "summary.md").read_text()
    assert "| viewing-angle datasets | 4 |" in summary  # tiny: 2 scenes x 2 azimuths
    assert "| RMS position error, no filter (mm) | not run |" not in summary  # stage 06's metrics reached it
