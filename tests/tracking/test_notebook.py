import json
from pathlib import Path

import pytest
import yaml

pytest.importorskip("papermill")
import papermill  # noqa: E402

from poseintegrity import config  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK = ROOT / "notebooks" / "06_marker_tracking.ipynb"
PROJECT_TINY = ROOT / "tests" / "params_tiny.yaml"
TINY_TRACK = {
    "seed": 6,
    "motion": {"duration_s": 3.0, "occlusions": [[1.5, 0.5]]},
    "filter": {"sigma_r": 0.003, "sigma_c": 3.0, "sigma_alpha": 30.0},
    "evaluation": {"success_frames": 25, "sigma_scales": [0.3, 3.0], "timing_repeats": 3, "lag_max_ms": 300},
}


@pytest.mark.notebook
def test_notebook_runs_with_tiny_params(tmp_path):
    if "track" not in config.Params.model_fields:
        pytest.skip("config.Params has no `track` section yet (the lead adds TrackParams)")
    raw = yaml.safe_load(PROJECT_TINY.read_text()) if PROJECT_TINY.is_file() else {}
    raw["track"] = TINY_TRACK  # the other stages' tiny sections, this stage's tiny section
    try:
        config.parse_params(raw)
    except config.ParamsError as error:
        pytest.skip(f"other sections need values for a standalone tiny params file: {error}")
    params_path = tmp_path / "params.yaml"
    params_path.write_text(yaml.safe_dump(raw))
    papermill.execute_notebook(
        str(NOTEBOOK), str(tmp_path / "out.ipynb"), kernel_name="python3",
        parameters={"params_path": str(params_path), "data_dir": str(tmp_path / "data"), "reports_dir": str(tmp_path / "reports")},
    )
    metrics = json.loads((tmp_path / "reports" / "metrics" / "tracking.json").read_text())
    for key in ["rms_mm", "rms_deg", "success_rate", "lag_ms", "failed_downdates", "speedup_vs_filterpy"]:
        assert key in metrics
    assert set(metrics["rms_mm"]) >= {"no_filter", "ukf", "ukf_gyro"}
    assert (tmp_path / "data" / "tracking" / "no_filter.parquet").exists()
    assert sorted(p.name for p in (tmp_path / "reports" / "figures").glob("06_*.png"))


def test_source_notebook_is_output_free_with_stable_ids_and_a_parameters_cell():
    nb = json.loads(NOTEBOOK.read_text())
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert all(c["outputs"] == [] and c["execution_count"] is None for c in code)
    assert all("id" in c for c in nb["cells"]) and nb["nbformat_minor"] >= 5
    assert "parameters" in code[0]["metadata"]["tags"] and 'params_path = "params.yaml"' in "".join(code[0]["source"])
