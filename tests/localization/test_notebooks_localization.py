"""Execute notebooks 02 and 05 with papermill on the tiny synthetic datasets."""

import json
import os
import shutil
from pathlib import Path

import pandas as pd
import papermill
import pytest

from poseintegrity import config
from poseintegrity.localization.summaries import FAILURE_STATUSES

ROOT = Path(__file__).resolve().parents[2]
PNP_METHODS = config.load_params(ROOT / "tests" / "params_tiny.yaml").extract.pnp_methods
pytestmark = pytest.mark.notebook


@pytest.fixture(scope="module")
def executed(synthetic_data_dir, tmp_path_factory):
    work = tmp_path_factory.mktemp("notebooks")
    data_dir, reports_dir = work / "data", work / "reports"
    shutil.copytree(synthetic_data_dir / "datasets", data_dir / "datasets")
    params_path = ROOT / "tests" / "params_tiny.yaml"
    env_path = os.environ.get("PYTHONPATH", "")
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [env_path, str(ROOT / "src")]))
    try:
        for name in ("02_extract_artifacts", "05_pnp_variants"):
            papermill.execute_notebook(
                ROOT / "notebooks" / f"{name}.ipynb", work / f"{name}.ipynb", kernel_name="python3", progress_bar=False,
                parameters=dict(params_path=str(params_path), data_dir=str(data_dir), reports_dir=str(reports_dir)),
            )
    finally:
        os.environ["PYTHONPATH"] = env_path
    return data_dir, reports_dir


def test_stage_02_writes_tables_metrics_and_figures(executed):
    data_dir, reports_dir = executed
    table = pd.read_parquet(data_dir / "artifacts" / "artifacts.parquet")
    assert set(table["method"]) == {"usac_magsac"} and table["dataset"].nunique() == 3
    env = pd.read_parquet(data_dir / "artifacts" / "envelopes.parquet")
    assert list(env.columns) == ["world", "dataset", "trajectory", "tolerance", "method", "rule", "theta_a", "censored",
                                 "status", "reason"]
    assert set(table.loc[table.status.isin(["bad_image", "bad_pose"]), "image"]) == {3, 4}  # of dataset "bad"
    metrics = json.loads((reports_dir / "metrics" / "artifacts.json").read_text())
    assert metrics["flagged_frames"] == {"bad_image": 1, "bad_pose": 1}
    assert metrics["status_counts"]["bad_image"] == metrics["status_counts"]["bad_pose"] == 1
    for key in ("min_abs_spearman", "error_ratio_low_vs_high_inliers", "n_uncensored_4mm10deg",
                "min_theta_a_2mm3deg", "cv_theta_a_2mm3deg"):
        assert key in metrics["realism"]
    for figure in ("02_inliers_vs_theta", "02_error_vs_inliers", "02_theta_a_distribution"):
        assert (reports_dir / "figures" / f"{figure}.png").stat().st_size > 0


def test_stage_05_writes_one_row_per_frame_and_method(executed):
    data_dir, reports_dir = executed
    table = pd.read_parquet(data_dir / "artifacts" / "pnp_variants.parquet")
    assert set(table["method"]) == set(PNP_METHODS)
    usac = pd.read_parquet(data_dir / "artifacts" / "artifacts.parquet")
    assert len(table) == len(usac) * len(PNP_METHODS)
    assert list(table.columns) == list(usac.columns)
    same_frames = ["dataset", "stop", "image", "status", "reason", "n_keypoints", "n_matches", "board_status",
                   "E_t_board_exact_mm"]  # stage 02's evidence, read back: the same flags, matches and ground truth
    for method in PNP_METHODS:
        variant = table[table.method == method].reset_index(drop=True)
        flagged = usac.status.isin(["bad_image", "bad_pose"])
        pd.testing.assert_frame_equal(variant.loc[flagged, same_frames], usac.loc[flagged, same_frames])
        pd.testing.assert_frame_equal(variant[same_frames[:3] + same_frames[5:]], usac[same_frames[:3] + same_frames[5:]])
    for rows in (usac, table):  # every row without a pose says why, USAC and classic alike
        assert ((rows["reason"] != "") == (rows["status"] != "ok")).all()
    metrics = json.loads((reports_dir / "metrics" / "pnp.json").read_text())
    assert set(metrics["methods"]) == {"usac_magsac", *PNP_METHODS}
    assert metrics["iteration_caps"] == {"epnp": 672, "sqpnp": 672}  # w = 0.4, p = 0.999, samples of 5
    for method, shares in metrics["failure_shares"].items():  # the causes add up to the method's failure rate
        assert set(FAILURE_STATUSES) <= set(shares)  # every cause, 0 where none
        assert sum(shares.values()) == pytest.approx(metrics["methods"][method]["failure_rate"])
    assert (reports_dir / "figures" / "05_theta_a_by_method.png").stat().st_size > 0
