"""The whole operating-point sweep on synthetic stage-02 tables: shape, invariants, fit statuses, bad datasets,
metrics keys, and the same answers on any number of workers; the combined error predictor's rows and the
per-tolerance scoring on rows whose answers are known."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from poseintegrity.artifact_models import FIT_STATUSES
from poseintegrity.artifact_models.fitted import OK
from poseintegrity.artifact_models.series import dataset_series
from poseintegrity.workers import Workers
from poseintegrity.prediction import (
    FITTED_PREDICTORS,
    FREE_WIDTH_PREDICTORS,
    NO_FIT,
    PAPER_PREDICTORS,
    attach_envelopes,
    best_table,
    combined_rows,
    fit_status_shares,
    headline_metrics,
    live_trials,
    long_range,
    loso,
    operating_curves,
    sweep,
    with_pnp_variants,
)
from poseintegrity.prediction.predictors import fit_rng
from poseintegrity.prediction.sweeps import COLUMNS
from poseintegrity.report.metrics import json_ready


@pytest.fixture(scope="module")
def swept(tables, theta_p, protocol):
    table = attach_envelopes(theta_p, tables[1], protocol)
    return theta_p, table, operating_curves(table)


def test_every_predictor_every_dataset_every_operating_point(swept, tables, tiny_predict):
    theta_p, _, _ = swept
    counts = theta_p.groupby(["method", "dataset", "predictor"]).size().unstack("predictor")
    paper = counts.loc["usac_magsac"]
    assert set(paper.columns) == {"static", "long_range", "long_range_lower", "mlp", "next_step",
                                  "long_range_relative", "next_step_relative", *FREE_WIDTH_PREDICTORS}
    absolute = ["long_range", "long_range_lower", "mlp", "next_step", *FREE_WIDTH_PREDICTORS]
    assert (paper[absolute] == tiny_predict.thresholds.size).all().all()
    relative = tiny_predict.relative_thresholds
    assert (relative[0], relative[-1]) == (tiny_predict.relative_min, tiny_predict.relative_max)
    assert (paper[["long_range_relative", "next_step_relative"]] == relative.size).all().all()
    assert (paper["static"] == tiny_predict.n_static).all()
    assert counts.loc["epnp"][["mlp", "next_step", "long_range_relative", *FREE_WIDTH_PREDICTORS]].isna().all().all()
    assert len(paper) == tables[0]["dataset"].nunique()


def test_relative_thresholds_are_fractions_of_the_first_stop_mean(swept, tables, tiny_predict, tiny_fit, protocol):
    """long_range_relative at fraction r is the long range predictor at n_t = r x (mean n_i of the first stop)."""
    theta_p, _, _ = swept
    series = next(s for s in dataset_series(tables[0], "usac_magsac", protocol) if s.dataset == "scene_2_arc01")
    first_mean = series.n_inliers[series.stop == 0].mean()
    n_sampled_stops = protocol.stops_sampled("arc")
    fractions = tiny_predict.relative_thresholds
    direct = long_range(series, n_sampled_stops, tiny_predict.models.long_range, fractions * first_mean, tiny_fit,
                        fit_rng(tiny_predict.seed, "usac_magsac", series, n_sampled_stops),
                        tiny_predict.n_grid)  # fmt: skip
    rows = theta_p[(theta_p.dataset == "scene_2_arc01") & (theta_p.predictor == "long_range_relative")]
    np.testing.assert_allclose(rows.sort_values("operating_point")["theta_p"], direct.prediction.theta_p)
    assert set(rows.fit_status) == {direct.fitted.status} and set(rows.reason) == {direct.fitted.reason}


def test_every_row_says_what_its_fit_was_worth(swept, tables, tiny_predict, tiny_fit, protocol):
    theta_p, _, _ = swept
    assert set(theta_p.fit_status) <= {*FIT_STATUSES, NO_FIT}
    assert set(theta_p[theta_p.predictor == "static"].fit_status) == {NO_FIT}
    for series in dataset_series(tables[0], "usac_magsac", protocol):  # the long range and MLP rows: their one fit
        n_sampled_stops = protocol.stops_sampled(series.trajectory)
        for predictor, model in (("long_range", tiny_predict.models.long_range), ("mlp", tiny_predict.models.mlp)):
            fitted = long_range(series, n_sampled_stops, model, tiny_predict.thresholds, tiny_fit,
                                fit_rng(tiny_predict.seed, "usac_magsac", series, n_sampled_stops),
                                tiny_predict.n_grid).fitted
            rows = theta_p[(theta_p.dataset == series.dataset) & (theta_p.predictor == predictor)
                           & (theta_p.method == "usac_magsac")]  # fmt: skip
            assert set(rows.fit_status) == {fitted.status} and set(rows.reason) == {fitted.reason}
    flagged = theta_p[theta_p.fit_status.isin(["at_bound", "non_physical"])]
    assert flagged.theta_p.notna().all()  # a flagged fit's theta_p counts: the robot would have acted on it


def test_fit_status_shares_count_rows_once_per_tolerance_set(swept):
    theta_p, table, _ = swept
    shares = fit_status_shares(table)
    assert set(shares) == set(FITTED_PREDICTORS)
    for predictor, entry in shares.items():
        rows = theta_p[theta_p.predictor == predictor]  # the error predictors' rows: one per tolerance already
        assert entry["n_rows"] == len(rows)  # not once per tolerance joined
        for status in (*FIT_STATUSES, NO_FIT):
            assert entry[status] == pytest.approx((rows.fit_status == status).mean(), nan_ok=True)


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


def test_headline_metrics_have_the_issue_keys_and_are_json(swept, tiny_predict, protocol):
    _, table, curves = swept
    folds = loso(table, tiny_predict.loso_target_rates, PAPER_PREDICTORS, protocol.pnp_method)
    best = best_table(curves)
    live = live_trials(table, best, tiny_predict, protocol)
    metrics = json.loads(json.dumps(json_ready(headline_metrics(table, curves, folds, live, tiny_predict, protocol)),
                                    allow_nan=False))  # fmt: skip
    for predictor in PAPER_PREDICTORS:
        for tolerance in protocol.tolerance_names:
            assert {"max_mean_spl_zero_incursion", "best_n_t"} <= set(metrics[predictor][tolerance])
            if predictor != "static":
                assert {"heldout_incursion_rate", "heldout_mean_spl"} <= set(metrics["loso"][predictor][tolerance])
    assert "relative_improvement" in metrics["straight_line"]
    assert set(metrics["pnp"]) == {"usac_magsac", "epnp"}
    assert all("max_mean_spl_zero_incursion" in entry for entry in metrics["pnp"].values())
    assert metrics["live"]["n_trials"] == 6 and len(live) == 6
    ours = table[(table.predictor == "next_step") & (table.operating_point == tiny_predict.live_n_t)
                 & (table.tolerance == tiny_predict.live_tolerance) & (table.method == protocol.pnp_method)
                 & (table.trajectory == "arc")]  # fmt: skip
    assert metrics["live"]["incursions"] == ours["incursion"].sum()
    assert metrics["live"]["n_flagged_fits"] == int((ours.fit_status != "ok").sum())
    assert set(metrics["fit_status"]) == set(FITTED_PREDICTORS)


def test_bad_datasets_become_flagged_rows(tables, tiny_predict, tiny_fit, protocol, workers):
    artifacts, envelopes = tables
    one = artifacts[(artifacts.dataset == "scene_1_arc00") & (artifacts.method == "usac_magsac")]
    short = one[one.stop < 3].assign(dataset="scene_4_arc00")  # 3 stops: too few for the long range predictor
    blank = one.assign(dataset="scene_5_arc00", n_inliers=np.nan)  # every inlier count missing
    bad = pd.concat([short, blank], ignore_index=True)
    bad_envelopes = pd.concat([envelopes[(envelopes.dataset == "scene_1_arc00") & (envelopes.method == "usac_magsac")]
                               .assign(dataset=name) for name in ("scene_4_arc00", "scene_5_arc00")])  # fmt: skip
    table = attach_envelopes(sweep(bad, tiny_predict, tiny_fit, protocol, workers, progress=False), bad_envelopes,
                             protocol)
    fitted = table[table.predictor != "static"]
    assert set(fitted.status) == {"too_few_stops"} and fitted["theta_p"].isna().all()
    assert set(fitted.fit_status) == {NO_FIT}
    curves = operating_curves(table)
    assert (curves[curves.predictor == "long_range"]["n_flagged"] == 2).all()


def test_a_dataset_gets_the_same_answers_alone_as_in_the_whole_sweep(swept, tables, tiny_predict, tiny_fit, protocol,
                                                                     workers):  # fmt: skip
    # every fit draws from a Generator seeded by (seed, method, dataset, stops fitted): a dataset's rows do not depend
    # on the others nor on the order of work (the MLP draws random weights)
    theta_p, _, _ = swept
    artifacts = tables[0]
    alone = sweep(artifacts[artifacts.dataset == "scene_2_arc01"], tiny_predict, tiny_fit, protocol, workers,
                  progress=False)  # fmt: skip
    whole = theta_p[theta_p.dataset == "scene_2_arc01"].reset_index(drop=True)
    pd.testing.assert_frame_equal(alone, whole)


def test_a_worker_process_gives_the_same_rows(swept, tables, tiny, tiny_predict, tiny_fit, protocol):
    """The one parallel layer (workers.py): a local worker process returns what the in-process run returns, to the
    bit: every predictor of a dataset, the MLP on the worker's one thread among them. One task (a dataset and PnP
    method), not four: each process that gets one first imports for 4 s (torch, the fitters), and that many tasks come
    back in order, to the byte, is tests/test_workers.py's to show."""
    theta_p, _, _ = swept
    one = (tables[0].dataset == "scene_1_arc00") & (tables[0].method == "usac_magsac")
    with Workers(tiny.parallel.model_copy(update={"n_jobs": 2})) as two:  # variation: worker processes
        apart = sweep(tables[0][one], tiny_predict, tiny_fit, protocol, two, progress=False)
    whole = theta_p[(theta_p.dataset == "scene_1_arc00") & (theta_p.method == "usac_magsac")].reset_index(drop=True)
    assert set(whole.predictor) >= {"mlp", "next_step", "long_range"}
    pd.testing.assert_frame_equal(apart, whole, check_exact=True)


def test_pnp_variants_add_methods_without_replacing_stage_02s(tables):
    artifacts, envelopes = tables
    usac, usac_envelopes = artifacts[artifacts.method == "usac_magsac"], envelopes[envelopes.method == "usac_magsac"]
    variants = pd.concat([usac.assign(method="sqpnp"), usac.assign(n_inliers=usac.n_inliers + 1000.0)])  # usac rows:
    # stage 02's stay (stage 05's, marked by 1000 more inliers, are left out)
    merged, merged_envelopes = with_pnp_variants(artifacts, envelopes, variants,
                                                 pd.concat([usac_envelopes.assign(method="sqpnp"), usac_envelopes]))
    assert set(merged.method) == {"usac_magsac", "epnp", "sqpnp"}
    assert (merged[merged.method == "usac_magsac"].n_inliers.to_numpy() == usac.n_inliers.to_numpy()).all()
    assert len(merged) == len(artifacts) * 3 // 2
    assert len(merged_envelopes) == len(envelopes) * 3 // 2


# Envelopes checked on read: (how the table is spoiled, what the error says)
BAD_ENVELOPES = [
    (lambda e: e.drop(columns="censored"), r"lacks columns \['censored'\]"),
    (lambda e: e.assign(tolerance=e.tolerance.replace("4mm_10deg", "5mm_10deg")), "another protocol"),
    (lambda e: e[e.tolerance == "2mm_3deg"], "another protocol"),  # a tolerance of the protocol has no envelope
    (lambda e: e.assign(theta_a=e.theta_a + 200.0), "outside"),
    (lambda e: pd.concat([e, e.iloc[[3]]]), "1 failed-frame rule's rows|2 rows for the same dataset"),  # a duplicate
    (lambda e: e.drop(columns="world"), r"lacks columns \['world'\]"),
]


@pytest.mark.parametrize(("spoil", "message"), BAD_ENVELOPES)
def test_envelopes_that_do_not_fit_the_protocol_are_refused(swept, tables, protocol, spoil, message):
    theta_p, _, _ = swept
    with pytest.raises(ValueError, match=message):
        attach_envelopes(theta_p, spoil(tables[1]), protocol)


def test_free_width_variants_have_rows_of_their_own_beside_the_papers(swept, tiny_predict, protocol):
    """The free-width rows flow through the curves, Tables I-III and predictors.json under their own names; the
    paper's figures are what they are without them."""
    theta_p, table, curves = swept
    free = theta_p[theta_p.predictor.isin(FREE_WIDTH_PREDICTORS)]
    assert set(free.model) == {"emg_free_width"} and set(theta_p[theta_p.predictor == "long_range"].model) == {"emg"}
    best = best_table(curves)
    paper_arcs = best[(best.method == protocol.pnp_method) & (best.trajectory == "arc")]
    for predictor in FREE_WIDTH_PREDICTORS:
        assert set(paper_arcs[paper_arcs.predictor == predictor].tolerance) == set(protocol.tolerance_names)
    folds = loso(table, tiny_predict.loso_target_rates, PAPER_PREDICTORS, protocol.pnp_method)
    live = live_trials(table, best, tiny_predict, protocol)
    metrics = headline_metrics(table, curves, folds, live, tiny_predict, protocol)
    paper_only = table[~table.predictor.isin(FREE_WIDTH_PREDICTORS)]
    without = headline_metrics(paper_only, operating_curves(paper_only), folds, live, tiny_predict, protocol)
    for predictor in (*PAPER_PREDICTORS, "long_range_lower", "long_range_relative", "next_step_relative"):
        assert json_ready(metrics[predictor]) == json_ready(without[predictor])
    for ours, paper in (("long_range_free_width", "long_range"), ("next_step_free_width", "next_step")):
        for tolerance in protocol.tolerance_names:
            row = paper_arcs[(paper_arcs.predictor == ours) & (paper_arcs.tolerance == tolerance)].iloc[0]
            entry = metrics[ours][tolerance]
            assert entry["max_mean_spl_zero_incursion"] == pytest.approx(row.max_mean_spl, nan_ok=True)
            assert entry["best_n_t"] == pytest.approx(row.best_operating_point, nan_ok=True)
        mean_ours, mean_paper = (metrics[p]["mean_max_mean_spl_zero_incursion"] for p in (ours, paper))
        assert metrics[ours][f"relative_improvement_vs_{paper}"] == pytest.approx(
            (mean_ours - mean_paper) / mean_paper, nan_ok=True)
    assert set(metrics["tails"]) == {"long_range", "long_range_free_width"}
    assert set(metrics["tails"]["long_range"]) == set(protocol.tolerance_names)


def test_an_envelope_stage_02_could_not_read_is_left_out_of_the_scoring_by_name(swept, tables, protocol):
    """theta_a NaN is allowed only where stage 02 says it could not be read (status not_measured: no trusted ground
    truth before the envelope ends); those rows leave the scores, named in a warning, and the rest are unchanged."""
    theta_p, _, _ = swept
    envelopes = tables[1].assign(status="ok", reason="")
    unread = envelopes.dataset == envelopes.dataset.iloc[0]
    spoiled = envelopes.assign(theta_a=envelopes.theta_a.mask(unread), status=envelopes.status.mask(unread, "not_measured"))
    with pytest.warns(UserWarning, match=f"1 dataset.* left out of the scoring.*{envelopes.dataset.iloc[0]}"):
        scored = attach_envelopes(theta_p, spoiled, protocol)
    full = attach_envelopes(theta_p, envelopes, protocol)
    pd.testing.assert_frame_equal(scored, full[full.dataset != envelopes.dataset.iloc[0]].reset_index(drop=True))
    with pytest.raises(ValueError, match="non-finite theta_a"):  # a NaN stage 02 did not flag
        attach_envelopes(theta_p, spoiled.assign(status="ok"), protocol)


def sweep_rows(predictor, theta_p, operating_point, tolerance=""):
    return pd.DataFrame({"predictor": predictor, "model": "emg", "method": "usac_magsac", "trajectory": "arc",
                         "dataset": "scene_1_arc000", "operating_point": operating_point, "theta_p": theta_p,
                         "status": "root", "fit_status": OK, "reason": predictor, "tolerance": tolerance},
                        columns=COLUMNS)


def test_combined_takes_the_earlier_stop_at_the_chosen_n_t():
    theta_p = pd.concat([sweep_rows("next_step", [30.0, 20.0, 10.0], [5.0, 10.0, 15.0]),
                         sweep_rows("error_next_step", [25.0, 15.0], [1.0, 2.0], "2mm_3deg"),
                         sweep_rows("error_next_step", [40.0, 35.0], [1.0, 2.0], "4mm_10deg")])
    best = pd.DataFrame({"predictor": "next_step", "method": "usac_magsac", "trajectory": "arc",
                         "tolerance": ["2mm_3deg", "4mm_10deg"], "max_mean_spl": 1.0, "best_operating_point": [10, 15]})
    rows = combined_rows(theta_p, best).sort_values(["tolerance", "operating_point"])
    np.testing.assert_allclose(rows.theta_p, [20.0, 15.0, 10.0, 10.0])  # min(err(k), n_i at n_t 10 | 15)
    assert list(rows.reason) == ["next_step", "error_next_step", "next_step", "next_step"]
    assert set(rows.predictor) == {"error_combined"}


def envelopes_of(theta_a: dict[str, float]) -> pd.DataFrame:
    return pd.DataFrame({"world": "main", "dataset": "scene_1_arc000", "trajectory": "arc", "method": "usac_magsac",
                         "tolerance": list(theta_a), "theta_a": list(theta_a.values()), "censored": False})


def test_a_row_made_for_one_tolerance_is_scored_on_it_alone(protocol):
    theta_p = pd.concat([sweep_rows("long_range", [12.0], [10.0]),
                         sweep_rows("error_long_range", [30.0], [1.0], "4mm_10deg")])
    table = attach_envelopes(theta_p, envelopes_of({"2mm_3deg": 20.0, "4mm_10deg": 25.0}), protocol)
    assert sorted(table[table.predictor == "long_range"].tolerance) == ["2mm_3deg", "4mm_10deg"]
    error = table[table.predictor == "error_long_range"]
    assert list(error.tolerance) == ["4mm_10deg"] and list(error.incursion) == [1.0] and list(error.spl) == [25.0]
