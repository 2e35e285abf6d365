"""The stage pages (report/stage_pages.py): ours beside the paper's per tolerance, and an honest word when a figure is
missing or null."""

from report.report_text import report_text


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
