"""Every notebook runs as it is when opened in JupyterLab, in pipeline order, on tiny parameters, and writes its
tables, metrics and figures where `dvc repro` writes them.

One module fixture runs the chain once, in a project copy on the tiny parameters (tests/project_copy.py; each
notebook reads the data of the one before): a Jupyter server started there opens each notebook through its REST API,
its kernel starting in notebooks/, and runs every code cell over the kernel's channels, with no parameters injected
(tests/notebook_run.py). The notebooks' relative paths resolve against the project's root (poseintegrity.project);
papermill with injected parameters, from the root, is the stage runner's way (tests/recorded/test_dvc_repro.py). The
tests below each check one stage's outputs. Two frames are spoiled after stage 01, as a recording may hold
them (an image file that is not an image, a NaN ground-truth pose): every later stage must run on with them flagged.
Stage 06 depends on no other stage: it runs once per session (tests/project_copy.py, stage_06_project), the report
reads its metrics, and tests/tracking/test_notebook_06.py runs its notebook in JupyterLab.
"""

import json
import shutil

import numpy as np
import pandas as pd
import pytest

from notebook_run import TINY_PARAMS, NotebookServer
from poseintegrity.artifact_models import FIT_STATUSES
from poseintegrity.params.model_names import distinct_theta_needed
from poseintegrity.config import load_params
from poseintegrity.localization.dataset import recorded_worlds
from poseintegrity.localization.envelope_causes import CAUSES
from poseintegrity.localization.summaries import FAILURE_STATUSES
from poseintegrity.prediction import (ERROR_PREDICTORS, FITTED_PREDICTORS, FREE_WIDTH_PREDICTORS, NO_FIT,
                                      PAPER_PREDICTORS)
from poseintegrity.prediction.hazard.applied import HAZARD_PREDICTORS
from poseintegrity.report.claims import TITLE
from project_copy import project_copy, stage_06_project
from repository import ROOT

pytestmark = pytest.mark.pipeline
TINY = load_params(TINY_PARAMS)
ORDER = ["01_generate_datasets", "02_extract_artifacts", "05_pnp_variants", "03_fit_artifact_models",
         "04_predictor_sweeps", "06_marker_tracking", "07_report"]  # dvc.yaml's order: 04 reads 05's tables
METRICS = {  # notebook -> the metrics file it must write
    "01_generate_datasets": "generate.json",
    "02_extract_artifacts": "artifacts.json",
    "03_fit_artifact_models": "fits.json",
    "04_predictor_sweeps": "predictors.json",
    "05_pnp_variants": "pnp.json",
    "06_marker_tracking": "tracking.json",
    "07_report": "headline.json",  # what DVC compares, from the others
}
SPOILED = "scene_a_arc000"  # its frames (stop 1, image 0): not an image; (stop 2, image 1): a NaN ground-truth pose
FIGURES_04 = ["04_ceiling.png", "04_fig5_long_range.png", "04_fig6_pnp.png", "04_fig7_straight_line.png",
              "04_fig8_next_step.png", "04_free_width.png", "04_loso.png", "04_model_choice.png",
              "04_relative_thresholds.png", "04_tails.png", "04_uncertainty.png"]  # fmt: skip


def spoil_two_frames(data_dir):
    folder = data_dir / "datasets" / SPOILED
    frames = pd.read_parquet(folder / "frames.parquet")
    (folder / frames.loc[(frames.stop == 1) & (frames.image == 0), "file"].item()).write_text("not an image")
    frames.at[frames.index[(frames.stop == 2) & (frames.image == 1)][0], "T_cam_board"] = np.full(16, np.nan)
    frames.to_parquet(folder / "frames.parquet")


@pytest.fixture(scope="module")
def pipeline(tmp_path_factory, run_once):
    work = project_copy(tmp_path_factory.mktemp("pipeline"))
    with NotebookServer(work) as server:
        server.run("notebooks/01_generate_datasets.ipynb")
        spoil_two_frames(work / "data")
        for name in ("02_extract_artifacts", "05_pnp_variants", "03_fit_artifact_models", "04_predictor_sweeps"):
            server.run(f"notebooks/{name}.ipynb")
        shutil.copytree(run_once("stage_06", stage_06_project) / "reports", work / "reports", dirs_exist_ok=True)
        server.run("notebooks/07_report.ipynb")
    return work / "data", work / "reports"


def metrics(reports, name):
    return json.loads((reports / "metrics" / name).read_text())


POPULATION_NOTEBOOKS = ["08_population", "09_hazard"]  # need a population's worlds: tests/population runs them


def test_order_covers_every_notebook():
    assert sorted(ORDER + POPULATION_NOTEBOOKS) == sorted(p.stem for p in (ROOT / "notebooks").glob("*.ipynb"))


def test_every_stage_writes_its_metrics_and_the_report_summarises_them(pipeline):
    _, reports = pipeline
    for name, file in METRICS.items():
        assert file is None or (reports / "metrics" / file).is_file(), f"{name} wrote no metrics"
    summary = (reports / "summary.md").read_text()
    pages = {page.name: page.read_text() for page in (reports / "stages").glob("*.md")}  # a page per stage
    assert "| viewing-angle datasets | 4 |" in pages["01_generate_datasets.md"]  # tiny: 2 scenes x 2 azimuths
    first = summary.split(f"## {TITLE}", 1)[1].split("\n## ", 1)[0].splitlines()  # the claims, one screen first
    assert len(first) <= 40 and len(summary.splitlines()) <= 200
    assert set(metrics(reports, "headline.json")) == {"main", "validation", "tracking"}
    assert "| RMS position error per axis, no filter (mm; paper's metric) | not run |" not in pages[
        "06_marker_tracking.md"]  # stage 06's metrics reached it
    timing = (reports / "timing.md").read_text()  # the machine-dependent figures, on their own page
    assert "| 06_marker_tracking |" in timing and "SR-UKF step speed-up over filterpy" in timing
    assert "| wall time (s) |" not in summary and "](timing.md)" in summary


def test_stage_02_flags_the_spoiled_frames_and_writes_tables_metrics_and_figures(pipeline):
    data, reports = pipeline
    table = pd.read_parquet(data / "artifacts" / "artifacts.parquet")
    index = pd.read_parquet(data / "datasets" / "index.parquet")
    assert set(table["method"]) == {TINY.protocol.pnp_method} and set(table["dataset"]) == set(index["dataset"])
    flagged = table[table.status.isin(["bad_image", "bad_pose"])]
    assert sorted(zip(flagged.dataset, flagged.stop, flagged.image, flagged.status)) == [
        (SPOILED, 1, 0, "bad_image"), (SPOILED, 2, 1, "bad_pose")]
    assert ((table["reason"] != "") == (table["status"] != "ok")).all()  # every row without a pose says why
    env = pd.read_parquet(data / "artifacts" / "envelopes.parquet")
    assert list(env.columns) == ["world", "dataset", "trajectory", "tolerance", "method", "rule", "theta_a", "censored",
                                 "status", "reason"]
    found = metrics(reports, "artifacts.json")
    assert found["flagged_frames"] == {"bad_image": 1, "bad_pose": 1}
    assert recorded_worlds(data) == set()  # rendered: its realism is judged (the recorded run's: described only)
    assert found["status_counts"]["bad_image"] == found["status_counts"]["bad_pose"] == 1
    for key in ("min_abs_spearman", "error_ratio_low_vs_high_inliers", "n_uncensored_4mm10deg",
                "min_theta_a_2mm3deg", "cv_theta_a_2mm3deg"):
        assert key in found["realism"]
    for figure in ("02_inliers_vs_theta", "02_error_vs_inliers", "02_theta_a_distribution", "02_envelope_causes",
                   "02_error_calibration"):
        assert (reports / "figures" / f"{figure}.png").stat().st_size > 0
    posed = table[table.status == "ok"]  # issue 38: every posed frame's predicted error, or why it has none
    assert (posed.covariance_status.isin(["ok", "too_few_points", "degenerate_points"])).all()
    assert (posed.loc[posed.covariance_status == "ok", ["sigma_t_pred_mm", "sigma_r_pred_deg"]] > 0).all().all()
    assert (table.loc[table.n_inliers == 0, "covariance_status"] == "no_pose").all()  # PnP gave no pose
    consensus = ["consensus_t_mm", "consensus_r_deg", "consensus_elsewhere", "consensus_rerun_t_mm"]  # issue 50
    assert (posed[consensus[:3] + ["stop_spread_t_mm", "stop_spread_r_deg"]] >= 0).any().all()
    assert table.loc[table.n_inliers == 0, consensus].isna().all().all()
    calibration = found["error_prediction"]["main"][TINY.protocol.tolerance_names[0]]
    assert 0 <= calibration["within_1sigma_t"] <= calibration["within_2sigma_t"] <= 1
    assert calibration["n_frames"] > 0 and calibration["pixel_noise_px"] > 0
    assert table.loc[table.status == "ok", "E_t_kinematic_mm"].notna().all()  # stage 01 writes the robot's log
    assert calibration["kinematic"]["spearman_t"] > 0 and calibration["kinematic"]["median_first_stop_mm"] < 1.0
    exact = pd.read_parquet(data / "artifacts" / "envelopes_exact.parquet")  # the diagnostic against the exact pose
    assert list(exact.columns) == list(env.columns) and set(exact["dataset"]) == set(env["dataset"])
    causes = pd.DataFrame(found["envelope_causes"])  # one row per dataset of the main world and tolerance
    assert len(causes) == (index.world == "main").sum() * len(TINY.protocol.tolerances)
    assert set(causes["cause"]) <= set(CAUSES)
    assert sum(sum(c.values()) for c in found["envelope_cause_counts"].values()) == len(causes)
    truth = found["realism"]["truth_accuracy"]  # R11 on rendered data: measured against the exact pose
    assert 0 < truth["trusted_share"] <= 1 and np.isfinite(truth["p99_E_t_truth_mm"])
    assert found["realism"]["passed"]["r11_truth_accuracy"] == (truth["p99_E_t_truth_mm"] <= 0.5
                                                                and truth["p99_E_r_truth_deg"] <= 0.5)


def test_stage_05_writes_one_row_per_frame_and_method_with_stage_02s_evidence(pipeline):
    data, reports = pipeline
    methods = TINY.extract.pnp_methods
    table = pd.read_parquet(data / "artifacts" / "pnp_variants.parquet")
    usac = pd.read_parquet(data / "artifacts" / "artifacts.parquet")
    assert set(table["method"]) == set(methods) and len(table) == len(usac) * len(methods)
    assert list(table.columns) == list(usac.columns)
    same_frames = ["dataset", "stop", "image", "status", "reason", "n_keypoints", "n_matches", "board_status",
                   "E_t_board_exact_mm"]  # stage 02's evidence, read back: the same flags, matches and ground truth
    flagged = usac.status.isin(["bad_image", "bad_pose"])
    for method in methods:
        variant = table[table.method == method].reset_index(drop=True)
        pd.testing.assert_frame_equal(variant.loc[flagged, same_frames], usac.loc[flagged, same_frames])
        pd.testing.assert_frame_equal(variant[same_frames[:3] + same_frames[5:]], usac[same_frames[:3] + same_frames[5:]])
    assert ((table["reason"] != "") == (table["status"] != "ok")).all()  # classic RANSAC says why too
    assert table[["consensus_t_mm", "consensus_elsewhere"]].isna().all().all()  # stage 02's method alone
    found = metrics(reports, "pnp.json")
    assert set(found["methods"]) == {TINY.protocol.pnp_method, *methods}
    assert found["iteration_caps"] == {"epnp": 672, "sqpnp": 672}  # w = 0.4, p = 0.999, samples of 5
    for method, shares in found["failure_shares"].items():  # the causes add up to the method's failure rate
        assert set(FAILURE_STATUSES) <= set(shares)  # every cause, 0 where none
        assert sum(shares.values()) == pytest.approx(found["methods"][method]["failure_rate"])
    assert (reports / "figures" / "05_theta_a_by_method.png").stat().st_size > 0


def test_stage_03_fits_every_model_at_every_k_and_counts_fit_statuses(pipeline):
    data, reports = pipeline
    fit, protocol = TINY.fit, TINY.protocol
    table = pd.read_parquet(data / "fits" / "fig2_rmse.parquet")
    ks = list(range(fit.k_min, fit.k_max + 1))
    assert set(table.model) == set(fit.models) and sorted(table.k.unique()) == ks
    n_ks = {model: sum(k >= distinct_theta_needed(model) for k in ks) for model in fit.models}  # free width from 4
    assert len(table) == table.dataset.nunique() * sum(n_ks.values()) and set(table.status) <= set(FIT_STATUSES)
    found = metrics(reports, "fits.json")
    k_arc, k_line = protocol.stops_sampled("arc"), protocol.stops_sampled("line")
    assert set(found[f"rmse_k{k_arc}"]) == set(fit.models) and set(found[f"line_rmse_k{k_line}"]) == set(fit.models)
    for model in fit.models:
        shares = found["fit_status"][model]
        assert set(shares) == set(FIT_STATUSES) and sum(shares.values()) == pytest.approx(1.0)
        assert shares["ok"] == pytest.approx((table[(table.model == model) & (table.world == "main")].status
                                              == "ok").mean())
    figures = sorted(p.name for p in (reports / "figures").glob("03_*.png"))
    assert figures == ["03_example_fits.png", "03_fig2_mean_rmse.png"]


def test_stage_04_scores_every_predictor_on_both_worlds_and_draws_every_figure(pipeline):
    data, reports = pipeline
    protocol = TINY.protocol
    found = metrics(reports, "predictors.json")
    for predictor in ("static", "long_range", "mlp", "next_step", *FREE_WIDTH_PREDICTORS, *ERROR_PREDICTORS):
        assert set(protocol.tolerance_names) <= set(found[predictor])
    for tolerance in protocol.tolerance_names:  # issue 38: the ceiling, and every predictor's share of it
        limit = found["ceiling"][tolerance]
        assert limit["gain"] == pytest.approx(limit["mean_theta_a"] / limit["min_theta_a"] - 1)
        for predictor in (*PAPER_PREDICTORS, *ERROR_PREDICTORS):
            spl, share = (np.nan if v is None else v for v in (found[predictor][tolerance]["max_mean_spl_zero_incursion"],
                                                                found[predictor][tolerance]["ceiling_share"]))
            gap = limit["mean_theta_a"] - limit["static_spl"]
            assert share == pytest.approx((spl - limit["static_spl"]) / gap if gap > 0 else np.nan, nan_ok=True)
    assert {"k", "incursions", "envelope_share"} <= set(found["live"]["error_next_step"])
    # issue 50: the committed hazard models (trained on the population, not on these datasets) ran on both worlds
    assert set(found["hazard"]["worlds"]) == {"main", "validation"} and found["hazard"]["trained_on_arcs"] > 0
    for predictor in HAZARD_PREDICTORS:
        assert set(protocol.tolerance_names) <= set(found[predictor])
    made = pd.read_parquet(data / "predictions" / "predictions.parquet").predictor
    assert (made == "error_next_step_observed").any()  # the robot's log reached stage 04
    assert {"straight_line", "pnp", "loso", "live", "fit_status", "tails", "envelope_rules",
            "model_choice"} <= set(found)
    assert set(found["model_choice"]["main"]) == set(TINY.predict.model_choice)  # every candidate, scored
    for predictor in ("static", "long_range"):  # the exact-pose rows: a named diagnostic, never the headline
        assert set(protocol.tolerance_names) <= set(found["exact_pose_diagnostic"][predictor])
    validation = metrics(reports, "validation.json")
    for predictor in ("static", "long_range", "mlp", "next_step"):  # the keys
        for tolerance in protocol.tolerance_names:
            assert "max_mean_spl_zero_incursion" in validation[predictor][tolerance]
            assert {"incursion_rate", "mean_spl"} <= set(validation["transfer"][predictor][tolerance])
    tails = pd.read_parquet(data / "predictions" / "tails.parquet")
    for predictor, entry in found["tails"].items():  # the table the notebook shows is the one the metrics count
        for tolerance, counted in entry.items():
            listed = tails[(tails.predictor == predictor) & (tails.tolerance == tolerance)]
            assert counted == {"n_overshooting": len(listed), "datasets": sorted(listed.dataset)}
    table = pd.read_parquet(data / "predictions" / "predictions.parquet")
    table = table[table.world == "main"]  # predictors.json: the main world (validation.json the other)
    for predictor in FITTED_PREDICTORS:  # a row per tolerance swept (the error predictors'), or one for all
        rows = table[(table.predictor == predictor) & ((table.tolerance == protocol.tolerance_names[0])
                                                       | table.predictor.isin((*ERROR_PREDICTORS,
                                                                                *HAZARD_PREDICTORS)))]
        assert found["fit_status"][predictor]["n_rows"] == len(rows)
        share = found["fit_status"][predictor][NO_FIT]  # null: no rows (error_combined without a Table III n_t)
        assert (np.nan if share is None else share) == pytest.approx((rows.fit_status == NO_FIT).mean(), nan_ok=True)
    assert sorted(p.name for p in (reports / "figures").glob("04_*.png")) == FIGURES_04
