"""The simulated live trials (Windsor et al. V-C): at the paper's fixed n_t beside static at its best size, and held
out, each scene's n_t and static's size chosen on the other scenes, checked against a brute-force choice written here
from the prediction table (every operating point's pooled R_i and mean SPL over the other scenes' arcs), not through
loso.py; and the safety factor of error_next_step's trials."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from poseintegrity.prediction import (attach_envelopes, best_table, heldout_interval, heldout_live_trials,
                                      heldout_metrics, live_safety_factor, live_trials, operating_curves, scene_of)
from poseintegrity.seeding import keyed_rng


@pytest.fixture(scope="module")
def table(tables, theta_p, protocol):
    return attach_envelopes(theta_p, tables[1], protocol)


def brute_force_point(rows: pd.DataFrame, conservative_high: bool) -> float:
    """The operating point with the largest mean SPL among those at zero incursion over ``rows``; ties go to the more
    conservative point; none at zero incursion: the most conservative point of all."""
    per_point = rows.groupby("operating_point").agg(incursions=("incursion", "sum"), spl=("spl", "mean"))
    safe = per_point[per_point.incursions == 0]
    if safe.empty:
        return float(per_point.index.max() if conservative_high else per_point.index.min())
    best = safe[np.isclose(safe.spl, safe.spl.max())].index
    return float(best.max() if conservative_high else best.min())


def test_live_trials_run_the_static_baseline_at_its_best_size(table, tiny_predict, protocol):
    best = best_table(operating_curves(table))
    live = live_trials(table, best, tiny_predict, protocol)
    size = best[(best.predictor == "static") & (best.trajectory == "arc") & (best.method == protocol.pnp_method)
                & (best.tolerance == tiny_predict.live_tolerance)].best_operating_point.item()  # fmt: skip
    assert (live.static_size == size).all() and live.static_incursion.sum() == 0  # its zero-incursion size
    np.testing.assert_allclose(live.static_share, np.minimum(size, live.theta_a) / live.theta_a)


def test_each_scene_runs_at_the_point_chosen_on_the_others(table, tiny_predict, protocol):
    trials = heldout_live_trials(table, tiny_predict, protocol)
    rows = table[(table.trajectory == "arc") & (table.method == protocol.pnp_method)
                 & (table.tolerance == tiny_predict.live_tolerance)]
    scenes = rows.dataset.map(scene_of)
    assert len(trials) == rows.loc[rows.predictor == "next_step", "dataset"].nunique() and scenes.nunique() >= 2
    for scene, group in trials.groupby("scene"):
        others = rows[scenes != scene]
        n_t = brute_force_point(others[others.predictor == "next_step"], conservative_high=True)
        size = brute_force_point(others[others.predictor == "static"], conservative_high=False)
        assert (group.n_t == n_t).all() and (group.static_size == size).all(), scene
        for trial in group.itertuples():
            ours = rows[(rows.dataset == trial.dataset) & (rows.predictor == "next_step") & (rows.operating_point == n_t)]
            assert trial.incursion == ours.incursion.item()
            assert trial.share == pytest.approx(ours.spl.item() / ours.theta_a.item())


def test_the_interval_resamples_scenes_and_holds_the_pooled_gain(table, tiny_predict, protocol):
    trials = heldout_live_trials(table, tiny_predict, protocol)
    spread = heldout_interval(trials, 2000, 0.9, np.random.default_rng(3))
    gain = trials.share.mean() - trials.static_share.mean()
    low, high = spread["envelope_share_gain"]
    assert low <= gain <= high and low < high
    one = trials.assign(scene="only")  # one scene: every draw is the whole set, the interval a point
    assert heldout_interval(one, 50, 0.9, np.random.default_rng(0))["envelope_share_gain"] == pytest.approx([gain, gain])
    assert heldout_interval(trials.iloc[:0], 50, 0.9, np.random.default_rng(0)) == {}


def test_one_scene_has_no_fold(table, tiny_predict, protocol):
    one = table[table.dataset.map(scene_of) == table.dataset.map(scene_of).iloc[0]]
    assert heldout_live_trials(one, tiny_predict, protocol).empty


def test_the_metrics_of_the_held_out_trials_are_their_rows_summed(table, tiny_predict, protocol):
    trials = heldout_live_trials(table, tiny_predict, protocol)
    metrics = heldout_metrics(trials, tiny_predict)
    assert metrics["n_trials"] == len(trials) and metrics["incursions"] == trials.incursion.sum()
    assert metrics["envelope_share"] == pytest.approx(trials.share.mean())
    assert metrics["static_envelope_share"] == pytest.approx(trials.static_share.mean())
    assert metrics["n_t"] == {scene: float(n) for scene, n in trials.groupby("scene").n_t.first().items()}
    rng = keyed_rng(tiny_predict.seed, "held-out live intervals")  # the same draws, so the same interval
    assert metrics["interval"] == heldout_interval(trials, tiny_predict.intervals.n_draws, tiny_predict.intervals.level,
                                                   rng)


def test_a_null_live_k_takes_table_iii_s_k_at_the_live_tolerance_and_a_number_is_taken_as_given(tiny_predict,
                                                                                                 protocol):
    """Only error_next_step's row on the arcs of the paper's PnP path at the live tolerance is read; a given live_k
    wins over it, and without such a row a null live_k is NaN."""
    row = dict(predictor="error_next_step", trajectory="arc", method=protocol.pnp_method,
               tolerance=tiny_predict.live_tolerance, max_mean_spl=9.0, best_operating_point=3.25)
    other = next(name for name in protocol.tolerance_names if name != tiny_predict.live_tolerance)
    best = pd.DataFrame([row, row | dict(tolerance=other, best_operating_point=1.5),
                         row | dict(predictor="next_step", best_operating_point=15.0),
                         row | dict(trajectory="line", best_operating_point=0.5),
                         row | dict(method="another_method", best_operating_point=0.75)])
    assert tiny_predict.error.live_k is None
    assert live_safety_factor(best, tiny_predict, protocol) == 3.25
    assert np.isnan(live_safety_factor(best.iloc[1:], tiny_predict, protocol))
    given = tiny_predict.model_copy(update={"error": tiny_predict.error.model_copy(update={"live_k": 2.5})})
    assert live_safety_factor(best, given, protocol) == 2.5
