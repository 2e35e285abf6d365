"""Intervals on the headlines (issue 49): scene-clustered bootstrap, leave-one-arc-out and paired differences,
checked on tables whose answers are known by hand, and the selection against Tables I-III's own."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from poseintegrity.prediction import best_table, operating_curves, with_metrics
from poseintegrity.prediction.intervals import (
    family, headline_intervals, leave_one_out_weights, live_intervals, select,
)
from poseintegrity.resampling import cluster_weights, percentile_interval

SIZES = np.arange(0.0, 45.01, 5.0)  # static envelope sizes, deg


def _table(theta_a: dict[str, float], long_range: dict[float, list[float]],
           others: dict[str, dict[float, list[float]]] | None = None) -> pd.DataFrame:
    """A prediction table of one method / trajectory / tolerance: static at SIZES, long range (and ``others``) at
    the given n_t with theta_p per dataset in the order of ``theta_a``."""
    rows = [dict(predictor="static", dataset=d, operating_point=s, theta_p=s, theta_a=a)
            for d, a in theta_a.items() for s in SIZES]
    for predictor, by_point in {"long_range": long_range, **(others or {})}.items():
        rows += [dict(predictor=predictor, dataset=d, operating_point=n_t, theta_p=p, theta_a=a)
                 for n_t, theta_p in by_point.items() for (d, a), p in zip(theta_a.items(), theta_p, strict=True)]
    table = pd.DataFrame(rows).assign(method="usac", trajectory="arc", tolerance="2mm_3deg")
    return with_metrics(table)


# three scenes of one arc each: theta_a 10, 20, 30 deg; long range at n_t 1 incurs on all, n_t 2 is safe
PLANTED = _table({"s1_arc000": 10.0, "s2_arc000": 20.0, "s3_arc000": 30.0},
                 {1.0: [12.0, 22.0, 32.0], 2.0: [9.0, 19.0, 29.0], 3.0: [5.0, 15.0, 25.0]})


def _intervals(table, n_draws=500, seed=0, pairs=()):
    return headline_intervals(table, ("static", "long_range", *{p for p in table.predictor} - {"static", "long_range"}),
                              pairs, n_draws, 0.9, np.random.default_rng(seed))


def test_leave_one_arc_out_range_of_a_planted_table_as_computed_by_hand():
    # all: static 10, long range n_t 2: (9 + 19 + 29) / 3 = 19, gain 9, mean theta_a 20, share 9 / 10
    # without s1: static 20, (19 + 29) / 2 = 24, gain 4, mean theta_a 25, share 4 / 5
    # without s2: static 10, (9 + 29) / 2 = 19, gain 9, mean theta_a 20, share 0.9
    # without s3: static 10, (9 + 19) / 2 = 14, gain 4, mean theta_a 15, share 0.8
    loo = _intervals(PLANTED)["long_range"]["leave_one_arc_out"]
    assert loo["max_mean_spl"] == pytest.approx([14.0, 24.0])
    assert loo["gain"] == pytest.approx([4.0, 9.0])
    assert loo["ceiling_share"] == pytest.approx([0.8, 0.9])


def test_identical_arcs_give_a_zero_width_interval():
    table = _table({f"s{i}_arc000": 20.0 for i in range(5)}, {1.0: [25.0] * 5, 2.0: [18.0] * 5, 3.0: [12.0] * 5})
    figures = _intervals(table)["long_range"]
    assert figures["max_mean_spl"] == [18.0, 18.0]
    assert figures["gain"] == [-2.0, -2.0]  # static reaches 20 on every draw: the size grid's 20 deg
    assert figures["no_point_share"] == 0.0
    assert figures["leave_one_arc_out"]["max_mean_spl"] == [18.0, 18.0]


def test_a_scene_s_arcs_are_drawn_together():
    scenes = np.array(["a", "a", "b", "c", "c", "c"])
    weights = cluster_weights(scenes, 400, np.random.default_rng(1))
    assert weights.shape == (400, 6)
    np.testing.assert_array_equal(weights[:, 0], weights[:, 1])  # arcs of one scene share their weight
    np.testing.assert_array_equal(weights[:, 3], weights[:, 5])
    per_scene = weights[:, [0, 2, 3]]
    np.testing.assert_array_equal(per_scene.sum(axis=1), 3)  # three scenes drawn per draw
    assert set(np.unique(per_scene)) <= {0.0, 1.0, 2.0, 3.0}
    assert abs(per_scene.mean() - 1.0) < 0.1  # each scene drawn once per draw on average
    np.testing.assert_array_equal(cluster_weights(scenes, 5, np.random.default_rng(7)),
                                  cluster_weights(scenes, 5, np.random.default_rng(7)))  # seeded
    np.testing.assert_array_equal(leave_one_out_weights(3), [[0, 1, 1], [1, 0, 1], [1, 1, 0]])


def test_unit_weights_select_what_tables_i_to_iii_select():
    rng = np.random.default_rng(3)
    theta_a = {f"s{i // 3}_arc{i % 3:03d}": float(a) for i, a in enumerate(rng.uniform(8, 40, 12))}
    drift = rng.normal(0, 4, 12)
    by_point = {float(n_t): list(np.clip(np.array(list(theta_a.values())) + drift + 30 - n_t, 0, 45))
                for n_t in range(4, 60)}
    by_point[30.0][4] = np.nan  # a flagged row
    table = _table(theta_a, by_point)
    best = best_table(operating_curves(table)).set_index("predictor")
    for predictor, high in (("long_range", True), ("static", False)):
        rows = table[table.predictor == predictor]
        fam = family(rows, np.sort(rows.dataset.unique()))
        spl, point = select(fam, np.ones((1, 12)), high)
        assert spl[0] == pytest.approx(best.loc[predictor, "max_mean_spl"], abs=1e-12)
        assert point[0] == best.loc[predictor, "best_operating_point"]


def test_paired_difference_and_the_share_of_draws_where_one_beats_the_other():
    better = {n_t: [p + 1.0 for p in theta_p] for n_t, theta_p in
              {1.0: [12.0, 22.0, 32.0], 2.0: [9.0, 19.0, 29.0], 3.0: [5.0, 15.0, 25.0]}.items()}
    better[1.0] = [12.0, 22.0, 32.0]  # incurs: its best is n_t 2, one degree above long range's on every arc
    table = pd.concat([PLANTED, _table({"s1_arc000": 10.0, "s2_arc000": 20.0, "s3_arc000": 30.0}, better)
                       .query("predictor == 'long_range'").assign(predictor="error_long_range")])
    pair = _intervals(table, pairs=(("error_long_range", "long_range"),))["pairs"]["error_long_range vs long_range"]
    assert pair["difference"] == pytest.approx([1.0, 1.0])
    assert pair["p_better"] == 1.0


def test_a_draw_without_an_operating_point_ranks_lowest():
    # long range incurs on s1 at every n_t: any draw holding s1 has no operating point
    table = _table({"s1_arc000": 10.0, "s2_arc000": 20.0, "s3_arc000": 30.0},
                   {1.0: [12.0, 19.0, 29.0], 2.0: [11.0, 15.0, 25.0]})
    figures = _intervals(table, n_draws=2000)["long_range"]
    assert figures["no_point_share"] == pytest.approx(1 - (2 / 3) ** 3, abs=0.03)  # s1 drawn at least once
    assert figures["max_mean_spl"][0] is None and figures["max_mean_spl"][1] is not None
    assert figures["leave_one_arc_out"]["max_mean_spl"][0] is None  # leaving s2 or s3 out keeps s1


def test_percentile_interval_takes_draws_not_interpolations():
    assert percentile_interval(np.arange(101.0), 0.9) == [5.0, 95.0]
    assert percentile_interval(np.array([np.nan, np.nan]), 0.9) == [None, None]
    assert percentile_interval(np.array([-np.inf] * 10 + [1.0] * 90), 0.9) == [None, 1.0]


def test_the_live_trials_resampled_by_scene():
    theta_a = {f"s{i}_arc000": a for i, a in enumerate((12.0, 20.0, 26.0, 31.0, 40.0))}
    table = _table(theta_a, {15.0: [10.0, 18.0, 30.0, 25.0, 35.0]}).query("predictor == 'static'")
    table = pd.concat([table, _table(theta_a, {15.0: [10.0, 18.0, 30.0, 25.0, 35.0]}).query(
        "predictor == 'long_range'").assign(predictor="next_step")])
    spread = live_intervals(table, "next_step", 15.0, 1000, 0.9, np.random.default_rng(2))
    # all arcs: next step's share of each envelope 10/12, 18/20, 26/26, 25/31, 35/40; static at 10 deg: 10/theta_a
    ours = np.mean([10 / 12, 18 / 20, 1.0, 25 / 31, 35 / 40])
    static = np.mean([10 / a for a in theta_a.values()])
    low, high = spread["envelope_share_gain"]
    assert low < ours - static < high
    same = _table({f"s{i}_arc000": 20.0 for i in range(4)}, {15.0: [16.0] * 4}).replace("long_range", "next_step")
    assert live_intervals(same, "next_step", 15.0, 200, 0.9, np.random.default_rng(0))["envelope_share_gain"] == [
        pytest.approx(16 / 20 - 1.0)] * 2  # static reaches the whole envelope (its size grid holds 20 deg)
    assert live_intervals(same, "next_step", 99.0, 200, 0.9, np.random.default_rng(0)) == {}  # no such point
