"""SPL (eq. 3), incursions and R_i (eq. 4), SPL vs R_i curves and the max mean SPL at zero incursion."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poseintegrity.prediction.paper_tables import deciding_datasets
from poseintegrity.prediction import (
    best_operating_point,
    incursion,
    operating_curves,
    relative_improvement,
    safe_path_length,
)

angles = st.lists(st.floats(0.0, 45.0), min_size=1, max_size=20)


@settings(deadline=None, max_examples=50)
@given(theta_p=angles, theta_a=angles)
def test_spl_is_at_most_both_angles_and_incursions_are_indicators(theta_p, theta_a):
    n = min(len(theta_p), len(theta_a))
    theta_p, theta_a = np.array(theta_p[:n]), np.array(theta_a[:n])
    spl = safe_path_length(theta_p, theta_a)
    assert np.all(spl <= theta_p) and np.all(spl <= theta_a) and np.all((spl == theta_p) | (spl == theta_a))
    hits = incursion(theta_p, theta_a)
    assert set(np.unique(hits)) <= {0.0, 1.0}
    np.testing.assert_array_equal(hits == 1.0, theta_p > theta_a)  # I counts theta_p > theta_a (eq. 4)


def _table(theta_p_by_point: dict[float, list[float]], theta_a: list[float]) -> pd.DataFrame:
    rows = [
        dict(predictor="long_range", method="m", trajectory="arc", tolerance="t", dataset=f"d{i}",
             operating_point=point, theta_p=p, theta_a=a)
        for point, theta_p in theta_p_by_point.items()
        for i, (p, a) in enumerate(zip(theta_p, theta_a, strict=True))
    ]  # fmt: skip
    return pd.DataFrame(rows)


def test_curves_and_the_best_point_on_a_table_with_known_answers():
    table = _table({10.0: [5.0, 6.0, 7.0], 20.0: [4.0, 5.0, 6.0], 30.0: [4.0, 5.0, np.nan]}, [6.5, 20.0, 20.0])
    curves = operating_curves(table)
    assert list(curves.incursion_rate) == pytest.approx([0.0, 0.0, 0.0])
    assert list(curves.mean_spl) == pytest.approx([6.0, 5.0, 4.5])
    assert list(curves.n) == [3, 3, 2] and list(curves.n_flagged) == [0, 0, 1]
    assert best_operating_point(curves, 0.0, conservative_high=True) == (pytest.approx(6.0), 10.0)
    risky = operating_curves(_table({10.0: [7.0, 1.0], 20.0: [3.0, 1.0]}, [6.0, 6.0]))
    assert list(risky.incursion_rate) == [0.5, 0.0]
    assert best_operating_point(risky, 0.0, True) == (pytest.approx(2.0), 20.0)
    assert best_operating_point(risky, 0.5, True) == (pytest.approx(3.5), 10.0)
    assert all(np.isnan(best_operating_point(risky.iloc[:1], 0.0, True)))


def test_ties_go_to_the_most_conservative_operating_point():
    curves = operating_curves(_table({1.0: [5.0], 2.0: [5.0], 3.0: [5.0]}, [5.0]))
    assert best_operating_point(curves, 0.0, conservative_high=True)[1] == 3.0
    assert best_operating_point(curves, 0.0, conservative_high=False)[1] == 1.0


@settings(deadline=None, max_examples=30)
@given(st.lists(st.tuples(st.floats(0.0, 45.0), st.floats(0.1, 45.0)), min_size=1, max_size=15))
def test_incursion_rate_lies_in_zero_one(pairs):
    theta_p, theta_a = zip(*pairs, strict=True)
    curves = operating_curves(_table({4.0: list(theta_p)}, list(theta_a)))
    assert 0.0 <= curves.incursion_rate.iloc[0] <= 1.0


def test_relative_improvement_as_in_table_one():
    assert relative_improvement(12.9, 7.0) == pytest.approx(0.8429, abs=1e-4)  # paper: 84.1 % (rounded inputs)
    assert np.isnan(relative_improvement(3.0, 0.0)) and np.isnan(relative_improvement(3.0, np.nan))


def test_the_arcs_that_hold_an_operating_point_are_those_incurring_at_the_next_bolder_one():
    # n_t 10 lets d0 past its envelope, n_t 5 lets d0 and d1 past: n_t 20 (none) is held by d0 alone
    table = _table({5.0: [9.0, 8.0, 2.0], 10.0: [7.0, 5.0, 2.0], 20.0: [5.0, 5.0, 2.0]}, [6.0, 6.0, 6.0])
    best = best_operating_point(operating_curves(table), 0.0, conservative_high=True)
    assert best[1] == 20.0
    assert deciding_datasets(table, "long_range", "m", "arc", "t", best[1]) == ["d0"]
    assert deciding_datasets(table, "long_range", "m", "arc", "t", 10.0) == ["d0", "d1"]
    assert deciding_datasets(table, "long_range", "m", "arc", "t", 5.0) == []
    assert deciding_datasets(table, "long_range", "m", "arc", "t", np.nan) == []
    # the static baseline: a larger envelope size is bolder
    sizes = _table({4.0: [4.0, 4.0], 6.0: [6.0, 6.0], 8.0: [8.0, 8.0]}, [7.0, 9.0]).assign(predictor="static")
    assert deciding_datasets(sizes, "static", "m", "arc", "t", 6.0) == ["d0"]
