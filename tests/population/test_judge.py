"""The predictors judged across worlds (population/judge.py, issue 49), on planted curves whose answers are known."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.stats import binomtest

from poseintegrity.population.judge import across_worlds, chosen_on, judge_population, paired
from poseintegrity.prediction import operating_curves, with_metrics


def _curves(points: dict[float, tuple[float, float]], predictor: str = "long_range") -> pd.DataFrame:
    """One curve: operating point -> (mean SPL, incursion rate)."""
    return pd.DataFrame([{"predictor": predictor, "tolerance": "2mm_3deg", "method": "m", "trajectory": "arc",
                          "operating_point": p, "mean_spl": spl, "incursion_rate": rate, "n": 21}
                         for p, (spl, rate) in points.items()])


def test_the_point_of_several_worlds_is_the_best_mean_among_those_safe_in_enough_of_them():
    # n_t 10 incurs in 2 of 10 worlds, 20 in 1 of 10, 30 in none; mean SPL 15, 14, 12
    worlds = {f"w{i}": _curves({10.0: (15.0, 0.1 if i < 2 else 0.0), 20.0: (14.0, 0.05 if i == 0 else 0.0),
                                30.0: (12.0, 0.0)}) for i in range(10)}
    assert chosen_on(worlds, 0.9).operating_point.tolist() == [20.0]  # 9 of 10 worlds safe at 20, 8 at 10
    assert chosen_on(worlds, 1.0).operating_point.tolist() == [30.0]  # pooled zero incursion: the most conservative
    assert chosen_on(worlds, 0.8).operating_point.tolist() == [10.0]
    none = {w: c.assign(incursion_rate=0.5) for w, c in worlds.items()}
    choice = chosen_on(none, 0.9)
    assert choice.operating_point.tolist() == [30.0] and not choice.feasible.iloc[0]  # flagged, most conservative


def test_static_s_conservative_end_is_its_smallest_size():
    worlds = {f"w{i}": _curves({5.0: (5.0, 0.0), 10.0: (10.0, 0.0 if i else 0.1), 15.0: (14.0, 0.3)}, "static")
              for i in range(4)}
    assert chosen_on(worlds, 1.0).operating_point.tolist() == [5.0]
    assert chosen_on(worlds, 0.75).operating_point.tolist() == [10.0]


def _world(theta_a: list[float], long_range: dict[float, list[float]], name: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(prediction table, curves) of a world of arcs s<i>_arc000 with static sizes 0..40 step 5."""
    datasets = [f"{name}_s{i}_arc000" for i in range(len(theta_a))]
    rows = [dict(predictor="static", dataset=d, operating_point=s, theta_p=s, theta_a=a)
            for d, a in zip(datasets, theta_a) for s in np.arange(0.0, 40.1, 5.0)]
    rows += [dict(predictor="long_range", dataset=d, operating_point=n_t, theta_p=p, theta_a=a)
             for n_t, values in long_range.items() for d, a, p in zip(datasets, theta_a, values)]
    table = with_metrics(pd.DataFrame(rows).assign(method="m", trajectory="arc", tolerance="2mm_3deg", world="main"))
    return table, operating_curves(table)


def test_each_world_at_its_own_the_main_and_the_others_points():
    worlds = {"a": _world([10.0, 20.0, 30.0], {1.0: [12.0, 22.0, 32.0], 2.0: [9.0, 19.0, 29.0]}, "a"),
              "b": _world([10.0, 20.0, 30.0], {1.0: [9.0, 19.0, 29.0], 2.0: [8.0, 18.0, 28.0]}, "b")}
    main = worlds["b"][1]  # the main world's points: b's (long range n_t 1, static 10)
    judged = judge_population(worlds, main, 1.0, "m", ["2mm_3deg"]).set_index(["world", "predictor", "point"])
    # a: ceiling mean theta_a 20, static 10; own n_t 2: (9 + 19 + 29) / 3 = 19, share 0.9
    assert judged.loc[("a", "long_range", "own"), "mean_spl"] == pytest.approx(19.0)
    assert judged.loc[("a", "long_range", "own"), "share"] == pytest.approx(0.9)
    # at b's n_t 1, a incurs on every arc: SPL (10 + 20 + 30) / 3 = 20, R_i 1, share 1 (what the robot got)
    assert judged.loc[("a", "long_range", "main"), "incursion_rate"] == 1.0
    assert judged.loc[("a", "long_range", "main"), "mean_spl"] == pytest.approx(20.0)
    # the others of a (b alone) choose n_t 1; of b (a alone) n_t 2: b at n_t 2 gets (8 + 18 + 28) / 3 = 18
    assert judged.loc[("b", "long_range", "others"), "operating_point"] == 2.0
    assert judged.loc[("b", "long_range", "others"), "mean_spl"] == pytest.approx(18.0)
    across = across_worlds(judged.reset_index())["2mm_3deg"]["long_range"]
    assert across["main"]["zero_incursion_worlds"] == 0.5 and across["main"]["mean_incursion_rate"] == 0.5
    assert across["own"]["n_worlds"] == 2


def test_paired_wins_and_the_sign_test():
    rows = []
    for i in range(12):  # error_next_step beats long range in 9 worlds, loses in 2, ties in 1
        a = 10.0 + (1.0 if i < 9 else -1.0 if i < 11 else 0.0)
        rows += [{"world": f"w{i}", "tolerance": "t", "point": "own", "predictor": "long_range", "mean_spl": 10.0},
                 {"world": f"w{i}", "tolerance": "t", "point": "own", "predictor": "error_next_step", "mean_spl": a}]
    rows.append({"world": "w12", "tolerance": "t", "point": "own", "predictor": "long_range", "mean_spl": np.nan})
    rows.append({"world": "w12", "tolerance": "t", "point": "own", "predictor": "error_next_step", "mean_spl": 3.0})
    entry = paired(pd.DataFrame(rows))["t"]["error_next_step vs long_range"]
    assert (entry["wins"], entry["losses"], entry["ties"]) == (10, 2, 1)  # no point for long range in w12: its loss
    assert entry["sign_test_p"] == pytest.approx(binomtest(10, 12).pvalue)
