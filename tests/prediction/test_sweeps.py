"""The whole operating-point sweep on synthetic stage-02 tables: shape, invariants, bad datasets, metrics keys."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from poseintegrity.report.metrics import json_ready
from poseintegrity.prediction import (
    PAPER_PREDICTORS,
    attach_envelopes,
    best_table,
    headline_metrics,
    live_trials,
    long_range,
    loso,
    operating_curves,
    sweep,
)

TOLERANCES = ("2mm_3deg", "4mm_10deg")


@pytest.fixture(scope="module")
def swept(tables, tiny_predict, tiny_fit):
    artifacts, envelopes = tables
    theta_p = sweep(artifacts, tiny_predict, tiny_fit, progress=False)
    table = attach_envelopes(theta_p, envelopes)
    return theta_p, table, operating_curves(table)


def test_every_predictor_every_dataset_every_operating_point(swept, tables, tiny_predict):
    theta_p, _, _ = swept
    counts = theta_p.groupby(["method", "dataset", "predictor"]).size().unstack("predictor")
    paper = counts.loc["usac_magsac"]
    assert set(paper.columns) == {"static", "long_range", "long_range_lower", "mlp", "next_step",
                                  "long_range_relative", "next_step_relative"}
    assert (paper[["long_range", "long_range_lower", "mlp", "next_step"]] == 97).all().all()
    relative = tiny_predict.relative_thresholds
    assert relative[0] == 0.02 and relative[-1] == 0.5  # 0.02 .. 0.5 in steps of 0.04: both ends on the grid
    assert (paper[["long_range_relative", "next_step_relative"]] == relative.size).all().all()
    assert (paper["static"] == tiny_predict.n_static).all()
    assert counts.loc["epnp"][["mlp", "next_step", "long_range_relative"]].isna().all().all()  # Fig. 6: long range
    assert len(paper) == tables[0]["dataset"].nunique()


def test_relative_thresholds_are_fractions_of_the_first_stop_mean(swept, tables, tiny_predict, tiny_fit):
    """long_range_relative at fraction r is the long range predictor at n_t = r x (mean n_i of the first stop)."""
    from poseintegrity.artifact_models.series import dataset_series
    from poseintegrity.prediction.predictors import fit_rng

    theta_p, _, _ = swept
    series = next(s for s in dataset_series(tables[0], "usac_magsac") if s.dataset == "scene_2_arc01")
    first_mean = series.n_inliers[series.stop == 0].mean()
    k = tiny_predict.long_range_stops_arc
    fractions = tiny_predict.relative_thresholds
    direct = long_range(series, k, "emg", fractions * first_mean, tiny_fit,
                        fit_rng(tiny_predict.seed, "usac_magsac", series, k), tiny_predict.n_grid)
    rows = theta_p[(theta_p.dataset == "scene_2_arc01") & (theta_p.predictor == "long_range_relative")]
    np.testing.assert_allclose(rows.sort_values("operating_point")["theta_p"], direct.prediction.theta_p)


def test_spl_and_incursions_obey_eq_3_and_4(swept):
    _, table, curves = swept
    assert np.all(table["spl"] <= table["theta_p"]) and np.all(table["spl"] <= table["theta_a"])
    static = table[table["predictor"] == "static"]
    np.testing.assert_array_equal(static["spl"], np.minimum(static["operating_point"], static["theta_a"]))
    assert curves["incursion_rate"].between(0.0, 1.0).all()


def test_incursion_rate_never_grows_with_n_t_for_the_long_range_predictor(swept):
    _, _, curves = swept
    for _, curve in curves[curves["predictor"] == "long_range"].groupby(["method", "trajectory", "tolerance"]):
        rates = curve.sort_values("operating_point")["incursion_rate"].to_numpy()
        assert np.all(np.diff(rates) <= 1e-12)


def test_headline_metrics_have_the_issue_keys_and_are_json(swept, tiny_predict):
    _, table, curves = swept
    folds = loso(table, tiny_predict.loso_target_rates, PAPER_PREDICTORS, tiny_predict.pnp_method)
    best = best_table(curves)
    static = best[(best.predictor == "static") & (best.trajectory == "arc") & (best.method == "usac_magsac")
                  & (best.tolerance == tiny_predict.live_tolerance)].best_operating_point.iloc[0]  # fmt: skip
    live = live_trials(table, tiny_predict, static)
    metrics = json.loads(json.dumps(json_ready(headline_metrics(table, curves, folds, live, tiny_predict)), allow_nan=False))
    for predictor in PAPER_PREDICTORS:
        for tolerance in TOLERANCES:
            assert {"max_mean_spl_zero_incursion", "best_n_t"} <= set(metrics[predictor][tolerance])
            if predictor != "static":
                assert {"heldout_incursion_rate", "heldout_mean_spl"} <= set(metrics["loso"][predictor][tolerance])
    assert "relative_improvement" in metrics["straight_line"]
    assert set(metrics["pnp"]) == {"usac_magsac", "epnp"}
    assert all("max_mean_spl_zero_incursion" in entry for entry in metrics["pnp"].values())
    assert metrics["live"]["n_trials"] == 6 and len(live) == 6
    ours = table[(table.predictor == "next_step") & (table.operating_point == tiny_predict.live_n_t)
                 & (table.tolerance == tiny_predict.live_tolerance) & (table.method == "usac_magsac")
                 & (table.trajectory == "arc")]  # fmt: skip
    assert metrics["live"]["incursions"] == ours["incursion"].sum()


def test_bad_datasets_become_flagged_rows(tables, tiny_predict, tiny_fit):
    artifacts, envelopes = tables
    one = artifacts[(artifacts.dataset == "scene_1_arc00") & (artifacts.method == "usac_magsac")]
    short = one[one.stop < 3].assign(dataset="scene_4_arc00")  # 3 stops: too few for the long range predictor
    blank = one.assign(dataset="scene_5_arc00", n_inliers=np.nan)  # every inlier count missing
    bad = pd.concat([short, blank], ignore_index=True)
    bad_envelopes = pd.concat([envelopes[(envelopes.dataset == "scene_1_arc00") & (envelopes.method == "usac_magsac")]
                               .assign(dataset=name) for name in ("scene_4_arc00", "scene_5_arc00")])  # fmt: skip
    table = attach_envelopes(sweep(bad, tiny_predict, tiny_fit, progress=False), bad_envelopes)
    fitted = table[table.predictor != "static"]
    assert set(fitted.status) == {"too_few_stops"} and fitted["theta_p"].isna().all()
    curves = operating_curves(table)
    assert (curves[curves.predictor == "long_range"]["n_flagged"] == 2).all()


def test_a_dataset_gets_the_same_answers_alone_as_in_the_whole_sweep(swept, tables, tiny_predict, tiny_fit):
    # every fit draws from a Generator seeded by (seed, method, dataset, k): the sweep is the same for any
    # n_jobs and order of work, and a dataset's rows do not depend on the others (the MLP draws random weights)
    theta_p, _, _ = swept
    artifacts = tables[0]
    alone = sweep(artifacts[artifacts.dataset == "scene_2_arc01"], tiny_predict, tiny_fit, progress=False)
    whole = theta_p[theta_p.dataset == "scene_2_arc01"].reset_index(drop=True)
    pd.testing.assert_frame_equal(alone, whole)
