"""Every notebook runs, in pipeline order, on tiny parameters, and writes its metrics."""

from pathlib import Path

import papermill
import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
METRICS = {  # notebook -> the metrics file it must write
    "01_generate_datasets": "generate.json",
    "02_extract_artifacts": "artifacts.json",
    "03_fit_artifact_models": "fits.json",
    "04_predictor_sweeps": "predictors.json",
    "05_pnp_variants": "pnp.json",
    "06_marker_tracking": "tracking.json",
    "07_report": None,
}


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    return tmp_path_factory.mktemp("pipeline")


@pytest.mark.notebook
@pytest.mark.xdist_group("notebooks")
@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs_with_tiny_params(notebook, workdir):
    executed = workdir / "executed" / notebook.name
    executed.parent.mkdir(exist_ok=True)
    papermill.execute_notebook(
        str(notebook), str(executed), kernel_name="python3", progress_bar=False, cwd=str(ROOT),
        parameters={"params_path": str(ROOT / "tests" / "params_tiny.yaml"), "data_dir": str(workdir / "data"),
                    "reports_dir": str(workdir / "reports")},
    )
    metrics = METRICS[notebook.stem]
    if metrics:
        assert (workdir / "reports" / "metrics" / metrics).is_file()
    if notebook.stem == "07_report":
        summary = (workdir / "reports" / "summary.md").read_text()
        assert "| viewing-angle datasets |" in summary
