"""Leave-one-scene-out threshold choice (prediction/loso.py) on a table with known answers."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from poseintegrity.prediction import loso_folds, loso_summary, pooled, scene_of


def test_scene_of_dataset_ids():
    assert scene_of("scene_3_arc090") == "scene_3"
    assert scene_of("scene_2_line05") == "scene_2"
    assert scene_of("other") == "other"


def _table() -> pd.DataFrame:
    # scenes a, b are safe at n_t = 10 (theta_p 5 < theta_a 6); scene c needs n_t = 20 (theta_p 3 < theta_a 4)
    rows = []
    for scene, theta_a in (("a", 6.0), ("b", 6.0), ("c", 4.0)):
        for n_t, theta_p in ((10.0, 5.0), (20.0, 3.0)):
            rows.append(dict(predictor="long_range", method="m", trajectory="arc", tolerance="t",
                             dataset=f"{scene}_arc0", operating_point=n_t, theta_p=theta_p, theta_a=theta_a,
                             spl=min(theta_p, theta_a), incursion=float(theta_p > theta_a)))  # fmt: skip
    return pd.DataFrame(rows)


def _folds() -> pd.DataFrame:
    return loso_folds(_table(), (0.0,), conservative_high=True)


def test_several_target_rates_give_the_folds_of_each_rate_in_turn():
    table = _table()
    one_by_one = pd.concat([loso_folds(table, (rate,), conservative_high=True) for rate in (0.0, 0.5)],
                           ignore_index=True)  # fmt: skip
    pd.testing.assert_frame_equal(loso_folds(table, (0.0, 0.5), conservative_high=True), one_by_one)
    assert set(one_by_one.loc[one_by_one.target_rate == 0.5, "operating_point"]) == {10.0}  # 1/2 allowed: the SPL 5


def test_loso_chooses_on_other_scenes_and_scores_the_held_out_one():
    folds = _folds()
    assert dict(zip(folds.scene, folds.operating_point, strict=True)) == {"a": 20.0, "b": 20.0, "c": 10.0}
    assert list(folds.heldout_incursions) == [0.0, 0.0, 1.0]  # the threshold from a, b is unsafe on c
    summary = loso_summary(folds, 0.0)["long_range"]["t"]
    assert summary["heldout_incursion_rate"] == pytest.approx(1 / 3)
    assert summary["heldout_mean_spl"] == pytest.approx((3.0 + 3.0 + 4.0) / 3)
    assert summary["thresholds"] == {"a": 20.0, "b": 20.0, "c": 10.0} and summary["n_infeasible_folds"] == 0


def test_pooled_is_what_the_summary_reports_and_survives_empty_folds():
    folds = _folds()
    row = pooled(folds).iloc[0]
    assert (row.predictor, row.tolerance, row.target_rate, row.heldout_n) == ("long_range", "t", 0.0, 3)
    assert row.heldout_incursion_rate == pytest.approx(1 / 3) and row.heldout_mean_spl == pytest.approx(10 / 3)
    empty = pooled(folds.assign(heldout_n=0, heldout_incursions=0.0, heldout_spl_sum=0.0)).iloc[0]
    assert np.isnan(empty.heldout_incursion_rate) and np.isnan(empty.heldout_mean_spl)  # no held-out data: no rate
