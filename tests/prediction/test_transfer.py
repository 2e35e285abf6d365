import numpy as np
import pandas as pd
import pytest

from poseintegrity.prediction.metrics import operating_curves
from poseintegrity.prediction.paper_tables import best_table
from poseintegrity.prediction.transfer import transfer, transfer_metrics


def prediction_rows(theta_a: dict[str, float], slope: float) -> pd.DataFrame:
    """A long range predictor whose theta_p falls linearly with n_t (theta_p = 40 - slope n_t), on a few arcs."""
    return pd.DataFrame([dict(predictor="long_range", method="usac_magsac", trajectory="arc", tolerance="2mm_3deg",
                              dataset=dataset, operating_point=float(n_t), theta_p=40.0 - slope * n_t, theta_a=a)
                         for dataset, a in theta_a.items() for n_t in range(4, 31)])


def test_the_point_chosen_on_one_world_is_read_on_the_other_curve():
    main = operating_curves(prediction_rows({"a": 20.0, "b": 30.0}, 1.0))
    best = best_table(main)  # zero incursion on main: theta_p <= 20 -> n_t >= 20, mean SPL (20 + 20) / 2
    assert best.loc[0, "best_operating_point"] == 20.0 and best.loc[0, "max_mean_spl"] == pytest.approx(20.0)
    other = operating_curves(prediction_rows({"c": 15.0, "d": 25.0}, 1.0))
    row = transfer(best, other).iloc[0]
    # at n_t = 20: theta_p = 20 > 15 for c (an incursion), SPL (15 + 20) / 2
    assert row.operating_point == 20.0 and row.incursion_rate == pytest.approx(0.5)
    assert row.mean_spl == pytest.approx(17.5) and row.chosen_mean_spl == pytest.approx(20.0) and row.n == 2
    metrics = transfer_metrics(transfer(best, other), ("long_range", "next_step"), "usac_magsac")
    assert metrics["long_range"]["2mm_3deg"] == {"operating_point": 20.0, "incursion_rate": 0.5, "mean_spl": 17.5}
    assert metrics["next_step"] == {}


def test_no_zero_incursion_point_or_no_curve_gives_nan_not_a_number_from_elsewhere():
    main = operating_curves(prediction_rows({"a": 1.0}, 0.0))  # theta_p = 40 > theta_a at every n_t
    best = best_table(main)
    assert np.isnan(best.loc[0, "best_operating_point"])
    row = transfer(best, operating_curves(prediction_rows({"c": 50.0}, 0.0))).iloc[0]
    assert np.isnan(row.incursion_rate) and np.isnan(row.mean_spl)
    elsewhere = operating_curves(prediction_rows({"c": 50.0}, 1.0)).assign(tolerance="4mm_10deg")
    assert np.isnan(transfer(best_table(operating_curves(prediction_rows({"a": 20.0}, 1.0))), elsewhere)
                    .iloc[0].incursion_rate)
