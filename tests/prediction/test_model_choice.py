"""The artifact model chosen on the datasets at hand (ours): the candidate sweep agrees with the sweep's long range
predictor, and the choice table's figures are the curves' and the folds' own, on a synthetic table with known answers."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from poseintegrity.prediction import attach_envelopes
from poseintegrity.prediction.model_choice import (
    CHOICE_COLUMNS,
    candidate_sweep,
    model_choice,
    model_choice_metrics,
)


@pytest.fixture(scope="module")
def candidates(tables, tiny_predict, tiny_fit, protocol, workers):
    artifacts, envelopes = tables
    return candidate_sweep(artifacts, tiny_predict, tiny_fit, protocol, workers, progress=False)


def test_the_paper_model_candidate_is_the_sweeps_long_range_predictor(candidates, theta_p, tiny_predict, protocol):
    """Same fit, same generator: the rows of predict.models.long_range equal the sweep's long range rows."""
    ours = candidates[candidates.model == tiny_predict.models.long_range].reset_index(drop=True)
    theirs = theta_p[(theta_p.predictor == "long_range") & (theta_p.method == protocol.pnp_method)]
    pd.testing.assert_frame_equal(ours, theirs.reset_index(drop=True))


def test_every_candidate_model_every_dataset_every_threshold(candidates, tables, tiny_predict, protocol):
    artifacts, _ = tables
    datasets = artifacts.loc[artifacts.method == protocol.pnp_method, "dataset"].nunique()
    counts = candidates.groupby(["model", "dataset"]).size()
    assert set(candidates.model) == set(tiny_predict.model_choice)
    assert len(counts) == len(tiny_predict.model_choice) * datasets
    assert (counts == tiny_predict.thresholds.size).all()
    assert set(candidates.method) == {protocol.pnp_method}


def test_choice_table_runs_on_the_sweep(candidates, tables, tiny_predict, protocol):
    _, envelopes = tables
    choice = model_choice(attach_envelopes(candidates, envelopes, protocol), tiny_predict.loso_target_rates[0])
    assert list(choice.columns) == CHOICE_COLUMNS
    assert len(choice) == choice.world.nunique() * len(tiny_predict.model_choice) * len(protocol.tolerance_names)
    finite = choice.dropna(subset=["max_mean_spl_zero_incursion"])
    assert (finite.max_mean_spl_zero_incursion >= 0).all() and (choice.heldout_incursion_rate.dropna() <= 1).all()


def _known_table() -> pd.DataFrame:
    """Two models on three one-dataset scenes (the way a recorded dataset is its own scene), one tolerance.
    model "wide": theta_p 8 at n_t 10, 5 at n_t 20; model "tight": theta_p 5 at n_t 10, 4 at n_t 20.
    theta_a: a 6, b 9, c 4.5."""
    rows = []
    for model, answers in (("wide", ((10.0, 8.0), (20.0, 5.0))), ("tight", ((10.0, 5.0), (20.0, 4.0)))):
        for dataset, theta_a in (("a", 6.0), ("b", 9.0), ("c", 4.5)):
            for n_t, theta_p in answers:
                rows.append(dict(predictor="long_range", model=model, method="m", trajectory="arc", tolerance="t",
                                 world="main", dataset=dataset, operating_point=n_t, theta_p=theta_p,
                                 theta_a=theta_a, spl=min(theta_p, theta_a), incursion=float(theta_p > theta_a)))
    return pd.DataFrame(rows)


def test_choice_figures_on_a_table_with_known_answers():
    choice = model_choice(_known_table(), 0.0).set_index("model")
    # in-sample: "wide" is safe only at n_t 20 (5 > 4.5 on c: no; 5 <= 6, 9 but 5 > 4.5 -> incursion on c): never
    # safe, so NaN; "tight" is safe at n_t 20 (4 < 4.5): mean SPL 4, and at n_t 10 5 > 4.5 -> not safe
    assert np.isnan(choice.loc["wide", "max_mean_spl_zero_incursion"])
    assert choice.loc["tight", "max_mean_spl_zero_incursion"] == pytest.approx(4.0)
    assert choice.loc["tight", "best_n_t"] == 20.0
    # held out, "tight": leaving a or b out, n_t 20 is chosen on the rest (c forbids 10); leaving c out, n_t 10
    # (5 <= 6, 9) is chosen and is an incursion on c (5 > 4.5): R_i 1/3, SPL (4 + 4 + 4.5) / 3
    assert choice.loc["tight", "heldout_incursion_rate"] == pytest.approx(1 / 3)
    assert choice.loc["tight", "heldout_mean_spl"] == pytest.approx((4.0 + 4.0 + 4.5) / 3)
    assert choice.loc["tight", "heldout_n"] == 3
    metrics = model_choice_metrics(model_choice(_known_table(), 0.0))
    assert metrics["main"]["tight"]["t"]["best_n_t"] == 20.0 and set(metrics["main"]) == {"wide", "tight"}
