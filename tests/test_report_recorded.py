"""The summary on recorded data: a first section says what was measured on each dataset and what the predictors
reach, no rendered-world target is shown, rows of keys a stage that ran did not write are left out rather than
called "not run"; and which world heads the metrics (poseintegrity.worlds)."""

from poseintegrity.report.summary import render_summary
from report_text import report_text
from poseintegrity.worlds import world_order

DATASET = {"world": "lab_a", "trajectory": "arc", "dataset": "knee_01", "n_frames": 40, "n_stops": 20,
           "last_stop": 88.0, "localized_share": 0.75, "first_stop_mean_n_inliers": 143.5,
           "theta_a_2mm_3deg": 31.25, "censored_2mm_3deg": False, "theta_a_4mm_10deg": 88.0, "censored_4mm_10deg": True}
RECORDED = {
    "generate": {"source": "/data/mine", "n_datasets": 2, "n_viewing_angle_datasets": 1, "n_straight_line_datasets": 1,
                 "n_images": 70, "worlds": {"lab_a": {"n_datasets": 1}, "lab_b": {"n_datasets": 1}}},
    "artifacts": {"datasets": [DATASET], "realism": {"min_abs_spearman": 0.9, "description_only": "recorded data"},
                  "worlds": {"lab_b": {"datasets": [DATASET | {"world": "lab_b", "trajectory": "line",
                                                              "dataset": "shaft_01", "last_stop": 140.0}]}}},
    "predictors": {"static": {"2mm_3deg": {"max_mean_spl_zero_incursion": 20.5, "best_size": 21.0}},
                   "long_range": {"2mm_3deg": {"max_mean_spl_zero_incursion": 25.0, "best_n_t": 23.0}},
                   "straight_line": {"tolerance": "2mm_3deg"}},
    "validation": {"world": "lab_b", "chosen_on": "lab_a",
                   "transfer": {"long_range": {"2mm_3deg": {"incursion_rate": 0.0, "mean_spl": 12.5}}}},
}


def test_the_summary_of_recorded_data_says_what_was_measured_on_each_dataset():
    text = render_summary(RECORDED)
    section = text.split("## Your recorded data: what was measured", 1)[1].split("\n## ", 1)[0]
    assert "Recorded datasets from `/data/mine`" in section and "`lab_a` (1 datasets), `lab_b` (1 datasets)" in section
    assert ("| lab_a | knee_01 | arc | 40 | 20 | 88 deg | 75% | 144 | 31.2 deg | >= 88 deg (censored: no failure up "
            "to the last stop) |") in section
    assert "| lab_b | shaft_01 | line | 40 | 20 | 140 mm |" in section
    assert "The predictors on world `lab_a`" in section
    assert "| static baseline | 20.5; size 21 |" in section and "| long range (eq. 1) | 25; n_t 23 |" in section
    assert "Held-out world `lab_b`" in section and "| long range (eq. 1) | 0; 12.5 |" in section
    assert "No lines in `lab_a`: no line operating point to apply." in section
    text = report_text(RECORDED)
    assert "## Stage 01 · rendered robot datasets" not in text  # replaced by the section above
    assert "| weakest decay over arcs: min of -Spearman(theta, mean n_i) | 0.9 | n_i 'decays' with viewing angle | - |" \
        in text  # its rendered-world target (>= 0.8) is not shown
    assert "smallest mean n_i at the first stop" not in text  # a key stage 02 did not write: left out, not "not run"
    assert "| RMS position error per axis, no filter (mm; paper's metric) | not run |" in text  # stage 06 not run


def test_one_world_says_nothing_was_held_out_and_the_rendered_summary_is_unchanged():
    one = RECORDED | {"validation": {"world": None, "chosen_on": "lab_a",
                                     "note": "one world only (lab_a): no second world to apply its operating points to"}}
    text = report_text(one)
    assert text.count("one world only (lab_a)") == 2  # in the section on the data and as stage 04's held-out part
    assert "No straight lines in this world: Fig. 7 has nothing to show." in text  # lab_a: one arc
    rendered = report_text({"generate": {"disk_gb": 1.4731}})
    assert "Your recorded data" not in rendered and "| disk (GB) | 1.473 | - | <= 3: pass |" in rendered


def test_main_heads_then_validation_then_the_others_by_name():
    assert world_order(["validation", "zeta", "main", "alpha", "main"]) == ["main", "validation", "alpha", "zeta"]
    assert world_order(["recorded"]) == ["recorded"] and world_order(["lab_b", "lab_a", "lab_b"]) == ["lab_a", "lab_b"]
