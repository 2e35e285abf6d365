"""The summary report: ours beside the paper's (per tolerance), and an honest word when a figure is missing or
null; the table of paper figures against the papers' printed tables."""

import re

import pytest

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines import HEADLINES, SECTIONS
from poseintegrity.report.summary import render_summary
from report_text import report_text
from repository import ROOT, outside_references

# Rows of Windsor et al.'s tables as printed (system, 2mm/3deg, 4mm/10deg, mean, relative improvement)
TABLE_I = """Static Baseline	7.0	7.0	7.0	84.1%
MLP	11.5	12.5	12.0	7.4%
Predictor (Ours)	12.3	13.5	12.9	-"""
TABLE_II = """Baseline	7.0	7.0	7.0	102.1%
Predictor (Ours)	13.9	14.4	14.2	-"""
TABLE_III = """Long Range Predictor	23	28
Next-Step Predictor	12	15"""


def numbers(row: str) -> list[float]:
    return [float(v) for v in re.findall(r"\d+\.?\d*", row)]


def test_paper_table_holds_the_printed_numbers_per_tolerance():
    static, mlp, ours = (numbers(row) for row in TABLE_I.splitlines())
    for name, row in (("static", static), ("mlp", mlp), ("long_range", ours)):
        assert [paper.WINDSOR_SPL_ZERO_INCURSION[name][t] for t in paper.TOLERANCES] == row[:2]
        assert paper.mean_spl(name) == pytest.approx(row[2], abs=0.05)  # the table's "Mean" column, rounded
    assert paper.WINDSOR_IMPROVEMENTS["long_range_vs_static"] == pytest.approx(static[3] / 100)
    assert paper.WINDSOR_IMPROVEMENTS["long_range_vs_mlp"] == pytest.approx(mlp[3] / 100)
    baseline, next_step = (numbers(row) for row in TABLE_II.splitlines())
    assert [paper.WINDSOR_SPL_ZERO_INCURSION["next_step"][t] for t in paper.TOLERANCES] == next_step[:2]
    assert paper.WINDSOR_IMPROVEMENTS["next_step_vs_static"] == pytest.approx(baseline[3] / 100)
    long_range, step = (numbers(row) for row in TABLE_III.splitlines())
    assert [paper.WINDSOR_THRESHOLDS["long_range"][t] for t in paper.TOLERANCES] == long_range
    assert [paper.WINDSOR_THRESHOLDS["next_step"][t] for t in paper.TOLERANCES] == step


def test_every_headline_belongs_to_a_section():
    assert {h.shown_in for h in HEADLINES} == set(SECTIONS)  # and each section has rows


def test_values_nulls_and_missing_stages_are_told_apart():
    metrics = {
        "generate": {"n_viewing_angle_datasets": 21, "disk_gb": 1.4731},
        "predictors": {"long_range": {"2mm_3deg": {"max_mean_spl_zero_incursion": None},
                                      "4mm_10deg": {"max_mean_spl_zero_incursion": 14.25}}},
    }
    text = report_text(metrics)
    assert "| viewing-angle datasets | 21 | 21 (7 scenes x 3 azimuths) | - |" in text
    assert "| disk (GB) | 1.473 | - | <= 3: pass |" in text
    # each tolerance beside the paper's value for that tolerance (Table I), not the mean of both
    assert "| long range (EMG, eq. 1), 2 mm/3 deg: max mean SPL at zero incursion (deg) | none | 12.3 | - |" in text
    assert "| long range (EMG, eq. 1), 4 mm/10 deg: max mean SPL at zero incursion (deg) | 14.25 | 13.5 | - |" in text
    assert "| RMS position error per axis, no filter (mm; paper's metric) | not run | 3.01 | - |" in text


def test_the_summary_points_nowhere_outside_the_repository():
    summary = ROOT / "reports" / "summary.md"
    assert "docs/references.md" in render_summary({})
    assert outside_references(render_summary({}), summary.parent) == []


def test_stage_wall_times_say_where_the_tasks_ran_and_stay_out_of_the_summary():
    """Wall times and speed-ups are on the machine-dependent page, each bar passed or failed; the summary only links
    it, so that it holds no number that changes with the machine."""
    from poseintegrity.report.timing_page import render_timing
    from poseintegrity.timing import StageTiming

    timings = [StageTiming("01_generate_datasets", 501.4, "local", 2, None, "2026-11-23T10:02:03"),
               StageTiming("02_extract_artifacts", 250.0, "dask", 8, "tcp://10.0.0.5:8786", "2026-11-23T10:06:13")]
    speed = {"speedup_vs_filterpy": 12.3, "speedup_vs_pykalman": 40.0, "filter_step_ms": {"srukf": 0.05},
             "subroutine_ms": {"Contour detection": 1.25}}
    text = render_timing(timings, {"06_marker_tracking": speed}, "AMD EPYC, 2 logical cores (x86_64)")
    assert ("| 01_generate_datasets | 501 | local, n_jobs 2 | 2026-11-23 10:02 | <= 480 s, rendering every world on 2 "
            "cores: fail |") in text
    assert "| 02_extract_artifacts | 250 | dask at tcp://10.0.0.5:8786, n_jobs 8 | 2026-11-23 10:06 |  |" in text
    assert "| total (without the report) | 751 | | | |" in text and "AMD EPYC, 2 logical cores" in text
    assert "| SR-UKF step speed-up over filterpy's UKF | 12.3x | >= 10x: pass |" in text
    assert "| Contour detection (ms) | 1.250 | |" in text
    assert "No stage timing yet" in render_timing([], {}, "x") and "has not written its timings" in render_timing([], {}, "x")
    summary = render_summary({"tracking": {"rms_mm": {"ukf": 1.1}}})
    assert "](timing.md)" in summary and "wall time (s)" not in summary and "| SR-UKF step speed-up" not in summary


def test_metrics_file_is_valid_json_with_null_for_nan(tmp_path):
    """json.dumps alone writes NaN / Infinity, which no JSON reader (dvc metrics) accepts."""
    import json

    import numpy as np

    from poseintegrity.report.metrics import write_metrics

    path = tmp_path / "stage.json"
    write_metrics(path, {"a": np.float64("nan"), "b": [np.int64(3), np.bool_(True), np.inf], "c": {"d": np.float32(0.5)}})
    assert json.loads(path.read_text()) == {"a": None, "b": [3, True, None], "c": {"d": 0.5}}
    assert [p.name for p in tmp_path.iterdir()] == ["stage.json"]  # the partial file was renamed


def test_fit_statuses_have_a_row_per_model_and_predictor():
    """Stages 03 and 04 count flagged fits (artifact_models/fitted.py): the summary shows every status of every model
    of Fig. 2 and of every predictor, beside the RMSE and SPL they qualify."""
    from poseintegrity.artifact_models import FIT_STATUSES
    from poseintegrity.params.model_names import MODEL_NAMES
    from poseintegrity.report.headlines import FIT_STATUS_LABELS, MODEL_LABELS

    assert list(FIT_STATUS_LABELS) == list(FIT_STATUSES) and set(MODEL_LABELS) == set(MODEL_NAMES)
    keys = {(h.stage, h.key) for h in HEADLINES}
    assert {("fits", f"fit_status.{m}.{s}") for m in MODEL_NAMES for s in FIT_STATUSES} <= keys
    assert {("predictors", f"fit_status.{p}.{s}") for p in ("long_range", "mlp", "next_step")
            for s in FIT_STATUSES} <= keys
    metrics = {"fits": {"fit_status": {"emg": {"ok": 0.975, "at_bound": 0.025, "non_physical": 0.0, "fallback": 0.0}}},
               "predictors": {"fit_status": {"next_step": {"non_physical": 0.125}}, "live": {"n_flagged_fits": 2}}}
    text = report_text(metrics)
    assert "| EMG (eq. 1): share of fits ok | 97.5% | - | >= 99 %: fail |" in text
    assert "| ... at a bound | 2.5% | - | - |" in text
    assert "| ... non-physical | 12.5% | - | - |" in text  # next step's rows
    assert "| simulated live trials that went by a flagged fit | 2 | - | - |" in text


def test_free_width_rows_and_tail_counts_stand_beside_the_papers_rows():
    """Ours (predictors on the free-width EMG, the tail diagnosis) are rows of their own, labelled ours; the paper's
    rows keep their labels and paper values."""
    metrics = {"predictors": {
        "long_range": {"2mm_3deg": {"max_mean_spl_zero_incursion": 11.0, "best_n_t": 60.0}},
        "long_range_free_width": {"2mm_3deg": {"max_mean_spl_zero_incursion": 12.5, "best_n_t": 25.0},
                                  "relative_improvement_vs_long_range": 0.125},
        "tails": {"long_range": {"2mm_3deg": {"n_overshooting": 2, "datasets": ["scene_1_arc00", "scene_4_arc17"]}},
                  "long_range_free_width": {"2mm_3deg": {"n_overshooting": 0, "datasets": []}}}}}
    text = report_text(metrics)
    assert "| long range (EMG, eq. 1), 2 mm/3 deg: max mean SPL at zero incursion (deg) | 11 | 12.3 | - |" in text
    assert ("| ours: long range on the free-width EMG, 2 mm/3 deg: max mean SPL at zero incursion (deg) | 12.5 | - | - |"
            in text)
    assert "| ours: long range on the free-width EMG over long range on eq. 1 (mean of both tolerances) | +12.5% |" in text
    assert ("| ours: arcs whose long range theta_p on eq. 1 overshoots theta_a at every n_t up to predict.tail_n_t_max, "
            "2 mm/3 deg | 2 | - | - |") in text
    assert "| ... which arcs | scene_1_arc00, scene_4_arc17 | - | - |" in text
    assert "| ... which arcs | none | - | - |" in text  # the free-width EMG: an empty list
    assert "| ... which arcs | not measured | - | - |" in text  # 4 mm/10 deg: stage 04 ran, its metrics lack it
    assert "| RMS position error per axis, no filter (mm; paper's metric) | not run |" in text  # stage 06 did not run


def test_each_headline_names_the_arcs_that_decide_it_and_how_they_end():
    cause = dict(dataset="a_arc090", tolerance="2mm_3deg", theta_a=17.77, theta_a_exact=24.5, limit="translation",
                 cause="resolution", truth_shift=0.332, n_inliers_at_theta_a=38.3)
    metrics = {
        "predictors": {"long_range": {"2mm_3deg": {"max_mean_spl_zero_incursion": 16.08, "best_n_t": 18.0,
                                                   "decided_by": ["a_arc090"]}},
                       "static": {"2mm_3deg": {"max_mean_spl_zero_incursion": 14.5, "best_size": 14.5,
                                               "best_n_t": None, "decided_by": []}}},
        "validation": {"world": "validation", "next_step": {"2mm_3deg": {"max_mean_spl_zero_incursion": 12.45,
                                                                         "best_n_t": 33.0, "decided_by": ["v_arc270"]}}},
        "artifacts": {"envelope_causes": [cause],
                      "worlds": {"validation": {"envelope_causes": [cause | dict(dataset="v_arc270", cause="estimate",
                                                                                  truth_shift=0.1)]}}},
    }
    summary = report_text(metrics)
    assert ("| main | 2mm_3deg | long_range | 16.08 | 18 | a_arc090 | 17.77 | 24.50 | translation | resolution | "
            "0.332 | 38.3 |") in summary
    assert "| main | 2mm_3deg | static | 14.50 | 14.5 | none | - |" in summary
    assert ("| validation | 2mm_3deg | next_step | 12.45 | 33 | v_arc270 | 17.77 | 24.50 | translation | "
            "estimate |") in summary
    assert "Which arcs decide" not in report_text({"predictors": {"static": {"2mm_3deg": {}}}})
