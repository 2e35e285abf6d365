"""The summary on recorded data: a first section says what was measured on each dataset and what the predictors
reach, no rendered-world target is shown, rows of keys a stage that ran did not write are left out rather than
called "not run"."""

from poseintegrity.report.summary import render_summary
from report.metrics_fixtures import RECORDED
from report.report_text import report_text


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
