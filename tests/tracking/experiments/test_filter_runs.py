import numpy as np
import pandas as pd

from poseintegrity.tracking.experiments.filter_runs import (
    FilterRun,
    accuracy_runs,
    agreement_runs,
    filter_agreement,
    pace_runs,
    study_filter_runs,
    sweep_runs,
)

from tracking.track_section import TINY


def test_each_filter_run_is_made_once_and_shared_by_the_experiments_that_need_it():
    params = TINY.model_copy(update={"evaluation": TINY.evaluation.model_copy(update={"sigma_scales": [0.5, 1.0, 2.0]})})
    runs = study_filter_runs(params)
    assert len(runs) == len(set(runs))
    assert sweep_runs(params)[1.0] == accuracy_runs(params)["ukf"]  # the sweep at scale 1 is the accuracy run
    sr, _ = agreement_runs(params)[f"alpha_{params.filter.alpha:g}"]
    assert sr == accuracy_runs(params)["ukf_gyro"] and isinstance(sr, FilterRun)
    assert set(pace_runs(params).values()) <= set(runs) and {run.recording for run in pace_runs(params).values()} == {"pace"}
    # 5 sigma variants on motion (a), the published sigmas and ours at the paper's pace, ukf and ukf_gyro, 2 new sweep
    # scales, and 3 new agreement runs
    assert len(runs) == 5 + 2 + 2 + 2 + 3


def test_the_agreement_is_nan_when_a_filter_never_ran():
    never = pd.DataFrame({"x_mm": [np.nan] * 3, "y_mm": [np.nan] * 3, "z_mm": [np.nan] * 3})
    ran = pd.DataFrame({"x_mm": [1.0, 2.0, 3.0], "y_mm": [0.0] * 3, "z_mm": [450.0] * 3})
    a, b = FilterRun("accuracy", True, TINY.filter), FilterRun("accuracy", False, TINY.filter)
    assert np.isnan(filter_agreement({a: (ran, None), b: (never, None)}, (a, b)))
    assert filter_agreement({a: (ran, None), b: (ran, None)}, (a, b)) == 0.0
