"""Stage 01 with ``generate.source`` a folder of recorded datasets: the notebook materializes them instead of
rendering (no calibration, no robot), and the stage 02 notebook runs on the result as on rendered data; a source that
is not a folder is refused naming the key."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd
import papermill
import pytest

from poseintegrity.config import ParamsError, load_params
from poseintegrity.localization.dataset import load_dataset, load_index, recorded_worlds
from poseintegrity.report.summary import render_summary
from repository import ROOT


def overlay(tmp_path, source) -> str:
    path = tmp_path / "params.yaml"
    path.write_text(f"extends: {ROOT / 'tests' / 'params_tiny.yaml'}\ngenerate:\n  source: {source}\n")
    return str(path)


def test_a_source_that_is_not_a_folder_is_refused_naming_the_key(tmp_path):
    with pytest.raises(ParamsError, match="generate.source"):
        load_params(overlay(tmp_path, tmp_path / "no_such_folder"))
    assert load_params(overlay(tmp_path, tmp_path)).generate.source == tmp_path


@pytest.mark.notebook
def test_stage_01_materializes_a_recorded_source_that_stage_02_reads(exported, rendered_dir, tmp_path):
    """One source holding both kinds of ground truth: arc_r with its board, line_r with its exported exact poses as
    the truth (its board.yaml removed); stages 01 and 02 once for both."""
    source = Path(shutil.copytree(exported, tmp_path / "recorded"))
    (source / "line_r" / "board.yaml").unlink()
    settings = source / "line_r" / "dataset.yaml"
    settings.write_text(settings.read_text().replace("ground_truth: board", "ground_truth: poses"))
    parameters = {"params_path": overlay(tmp_path, source), "data_dir": str(tmp_path / "data"),
                  "reports_dir": str(tmp_path / "reports")}
    for notebook in ("01_generate_datasets", "02_extract_artifacts"):
        papermill.execute_notebook(str(ROOT / "notebooks" / f"{notebook}.ipynb"), str(tmp_path / f"{notebook}.ipynb"),
                                   kernel_name="python3", progress_bar=False, cwd=str(ROOT), parameters=parameters)
    assert (tmp_path / "reports" / "metrics" / "artifacts.json").is_file()
    index = load_index(tmp_path / "data")
    assert list(index["dataset"]) == ["arc_r", "line_r"] and list(index["world"]) == ["main", "main"]
    columns = ["stop", "image", "theta_deg", "x_mm"]
    for name in index["dataset"]:
        again = load_dataset(tmp_path / "data", f"datasets/{name}")
        assert again.frames[columns].equals(load_dataset(rendered_dir, f"datasets/{name}").frames[columns])
        assert again.meta["ground_truth"] == ("board" if name == "arc_r" else "poses")
    rows = pd.read_parquet(tmp_path / "data" / "artifacts" / "artifacts.parquet")
    assert set(rows.loc[rows.dataset == "line_r", "board_status"]) == {"no_board"}  # the recorded poses instead
    assert (rows.loc[rows.dataset == "arc_r", "board_status"] == "ok").any()
    posed = rows[(rows.dataset == "line_r") & (rows.status == "ok")]
    assert len(posed) and posed.E_t_mm.notna().all()  # measured against the recorded poses
    metrics = json.loads((tmp_path / "reports" / "metrics" / "generate.json").read_text())
    assert metrics["source"] == str(source) and metrics["n_datasets"] == 2 and metrics["n_images"] == 6 + 2 + 2 * 2
    assert not (tmp_path / "data" / "calibration" / "main").exists()  # nothing rendered or calibrated
    assert recorded_worlds(tmp_path / "data") == {"main"} and recorded_worlds(rendered_dir) == set()
    realism = json.loads((tmp_path / "reports" / "metrics" / "artifacts.json").read_text())["realism"]
    assert "passed" not in realism and "recorded data" in realism["description_only"]  # described, not judged
    summary = render_summary({"artifacts": {"realism": realism}}, [])
    assert "Realism bars: recorded data" in summary
