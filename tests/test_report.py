"""The summary report: ours beside the paper's, and an honest word when a figure is missing or null."""

from poseintegrity.report.summary import HEADLINES, SECTIONS, render_summary


def test_every_headline_belongs_to_a_section():
    assert {h.stage for h in HEADLINES} <= set(SECTIONS)


def test_values_nulls_and_missing_stages_are_told_apart():
    metrics = {
        "generate": {"n_viewing_angle_datasets": 21, "disk_gb": 1.4731},
        "predictors": {"long_range": {"2mm_3deg": {"max_mean_spl_zero_incursion": None}}},
    }
    text = render_summary(metrics)
    assert "| viewing-angle datasets | 21 | 21 (7 scenes x 3 azimuths) | - |" in text
    assert "| disk (GB) | 1.473 | - | <= 3 |" in text
    assert "| long range, 2 mm/3 deg: max mean SPL at zero incursion (deg) | none | 12.9 | - |" in text
    assert "| RMS position error per axis, no filter (mm; paper's metric) | not run | 3.01 | - |" in text
