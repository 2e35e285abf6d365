"""The arcs that decide each headline and how each ends (report/deciding.py)."""

from report.report_text import report_text


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
