"""The rows of the stage pages (report/headlines/): every row in a section, a row per fit status of every model and
predictor, ours beside the paper's rows."""

from poseintegrity.artifact_models import FIT_STATUSES
from poseintegrity.params.model_names import MODEL_NAMES
from poseintegrity.report.headlines import HEADLINES, SECTIONS
from poseintegrity.report.headlines.fits import FIT_STATUS_LABELS, MODEL_LABELS
from report.report_text import report_text


def test_every_headline_belongs_to_a_section():
    assert {h.shown_in for h in HEADLINES} == set(SECTIONS)  # and each section has rows


def test_fit_statuses_have_a_row_per_model_and_predictor():
    """Stages 03 and 04 count flagged fits (artifact_models/fitted.py): the summary shows every status of every model
    of Fig. 2 and of every predictor, beside the RMSE and SPL they qualify."""
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
