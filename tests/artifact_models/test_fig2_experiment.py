"""The Fig. 2 experiment on a synthetic artifacts table drawn from eq. 1 + noise."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from poseintegrity.artifact_models import (
    EMG,
    FIT_STATUSES,
    at_sampled_stops,
    dataset_series,
    fig2_rmse,
    fits_metrics,
    mean_rmse,
    status_counts,
)
from poseintegrity.artifact_models.fitted import OK
from poseintegrity.params.model_names import MODEL_NAMES, distinct_theta_needed


@pytest.fixture(scope="module")
def rmse_table(artifacts_table, tiny_fit, protocol, workers):
    return fig2_rmse(artifacts_table[0], tiny_fit, protocol, workers, progress=False)


def test_series_are_one_per_dataset_of_the_chosen_method(artifacts_table, protocol):
    artifacts, _ = artifacts_table
    series = dataset_series(artifacts, "usac_magsac", protocol)
    assert [(s.trajectory, s.dataset) for s in series] == [
        ("arc", "arc_00"), ("arc", "arc_01"), ("arc", "arc_02"), ("line", "line_00"), ("line", "line_01")
    ]  # fmt: skip
    arc, line = series[0], series[-1]
    assert arc.n_stops == 20 and line.n_stops == 15
    assert (arc.theta_end, line.theta_end) == (protocol.range_end("arc"), protocol.range_end("line"))
    np.testing.assert_array_equal(np.unique(arc.theta), 2.25 * np.arange(20))  # theta_deg for arcs
    np.testing.assert_array_equal(np.unique(line.theta), 10.0 * np.arange(15))  # x_mm for lines
    rows = artifacts[(artifacts.dataset == "arc_00") & (artifacts.method == "usac_magsac")]
    np.testing.assert_array_equal(np.sort(arc.n_inliers), np.sort(rows.n_inliers.to_numpy(float)))
    theta4, _ = arc.first_stops(4)
    np.testing.assert_array_equal(np.unique(theta4), [0.0, 2.25, 4.5, 6.75])  # from the model view


def test_unknown_method_names_the_methods_present(artifacts_table, protocol):
    with pytest.raises(ValueError, match=r"no rows with method 'sqpnp'.*epnp.*usac_magsac"):
        dataset_series(artifacts_table[0], "sqpnp", protocol)


# Data checked on read: (how the table is spoiled, what the error says)
BAD_TABLES = [
    (lambda t: t.drop(columns="n_inliers"), r"lacks columns \['n_inliers'\]"),
    (lambda t: t.assign(trajectory=t.trajectory.replace("line", "spiral")), "unknown trajectory type"),
    (lambda t: t.assign(theta_deg=t.theta_deg * 1.2), r"arc_00 .* outside \[0, 45\]"),  # rendered for 54 deg
    (lambda t: t.assign(x_mm=np.where(t.trajectory == "line", -t.x_mm, t.x_mm)), "line_00 .*does not increase"),
    (lambda t: t.assign(theta_deg=np.where(t.dataset == "arc_01", np.nan, t.theta_deg)), "arc_01 .*non-finite"),
]


@pytest.mark.parametrize(("spoil", "message"), BAD_TABLES)
def test_a_table_that_does_not_fit_the_protocol_is_refused_on_read(artifacts_table, protocol, spoil, message):
    with pytest.raises(ValueError, match=message):
        dataset_series(spoil(artifacts_table[0]), "usac_magsac", protocol)


def test_too_few_stops_for_k_min_is_a_configuration_error(artifacts_table, tiny_fit, protocol, workers):
    short = artifacts_table[0].query("stop < 2")
    with pytest.raises(ValueError, match=f"no dataset has k_min = {tiny_fit.k_min} stops"):
        fig2_rmse(short, tiny_fit, protocol, workers, progress=False)


def test_metrics_name_every_model_even_without_fits_at_the_sampled_stops(artifacts_table, tiny_fit, protocol, workers):
    short = artifacts_table[0].query("stop < 3")  # 3 stops: fits at k = 3 only, none at the 4 / 5 sampled stops
    only_emg = tiny_fit.model_copy(update={"models": ("emg",)})  # variation: one model
    table = fig2_rmse(short, only_emg, protocol, workers, progress=False)
    metrics = fits_metrics(table, tiny_fit, protocol)
    assert metrics[f"rmse_k{protocol.stops_sampled('arc')}"] == {name: None for name in tiny_fit.models}
    assert metrics["n_fits"] == {name: 5 if name == "emg" else 0 for name in tiny_fit.models}  # 5 datasets, k = 3
    assert set(metrics["fit_status"]["emg"]) == set(FIT_STATUSES)
    assert metrics["fit_status"]["emg"][OK] == pytest.approx((table.status == OK).mean())
    assert metrics["fit_status"]["exponential"] is None


def test_table_has_one_row_per_dataset_k_and_model(rmse_table, tiny_fit):
    assert list(rmse_table.columns) == ["trajectory", "dataset", "k", "model", "rmse", "status", "reason",
                                        "n_samples"]  # fmt: skip
    ks = list(range(tiny_fit.k_min, tiny_fit.k_max + 1))  # k_max < every dataset's stop count
    assert tiny_fit.k_min == 3  # eq. 1's 3 parameters; the free-width EMG (4) joins at k = 4
    ks_of = {model: [k for k in ks if k >= distinct_theta_needed(model)] for model in tiny_fit.models}
    assert ks_of["emg"] == ks and ks_of["emg_free_width"] == ks[1:]
    assert len(rmse_table) == 5 * sum(len(model_ks) for model_ks in ks_of.values())
    for model, model_ks in ks_of.items():
        assert sorted(rmse_table[rmse_table.model == model].k.unique()) == model_ks
    assert list(tiny_fit.models) == list(MODEL_NAMES)  # the tiny run compares every model
    assert (rmse_table.n_samples == 10 * rmse_table.k).all()
    assert rmse_table.rmse.notna().all() and set(rmse_table.status) <= set(FIT_STATUSES)
    assert ((rmse_table.status == OK) == (rmse_table.reason == "ok")).all()


def test_rmse_is_over_the_whole_dataset(rmse_table, artifacts_table, tiny_fit, protocol):
    series = dataset_series(artifacts_table[0], "usac_magsac", protocol)[1]
    theta, n = series.first_stops(4)
    model = EMG.fit(theta, n, theta_end=series.theta_end, max_nfev=tiny_fit.max_nfev)
    expected = np.sqrt(np.mean((model.predict(series.theta) - series.n_inliers) ** 2))
    row = rmse_table.query("dataset == @series.dataset and k == 4 and model == 'emg'")
    assert row.rmse.item() == pytest.approx(expected, rel=1e-12)
    assert row.status.item() == model.status and row.reason.item() == model.reason


def test_mean_rmse_and_metrics(rmse_table, tiny_fit, protocol):
    k_arc, k_line = protocol.stops_sampled("arc"), protocol.stops_sampled("line")
    means = mean_rmse(rmse_table)
    expected = rmse_table.query("trajectory == 'arc' and k == @k_arc").groupby("model").rmse.mean()
    got = at_sampled_stops(means, protocol).query("trajectory == 'arc'").set_index("model").mean_rmse
    np.testing.assert_allclose(got.sort_index(), expected.sort_index(), rtol=1e-12)
    assert set(at_sampled_stops(means, protocol).query("trajectory == 'line'").k) == {k_line}
    metrics = fits_metrics(rmse_table, tiny_fit, protocol)
    assert set(metrics) == {f"rmse_k{k_arc}", f"line_rmse_k{k_line}", "fit_status", "n_fits"}
    assert set(metrics[f"rmse_k{k_arc}"]) == set(MODEL_NAMES) and set(metrics["fit_status"]) == set(MODEL_NAMES)
    assert metrics[f"rmse_k{k_arc}"]["emg"] == pytest.approx(expected["emg"])
    for model, shares in metrics["fit_status"].items():
        rows = rmse_table[rmse_table.model == model]
        assert metrics["n_fits"][model] == len(rows)
        assert shares == {status: pytest.approx((rows.status == status).mean()) for status in FIT_STATUSES}
        assert sum(shares.values()) == pytest.approx(1.0)


def test_status_counts_count_every_fit_once():
    table = pd.DataFrame({"model": ["emg", "emg", "emg", "mlp_scratch"],
                          "status": ["ok", "at_bound", "ok", "non_physical"]})  # fmt: skip
    counts = status_counts(table)
    assert counts.loc["emg"].to_dict() == {"ok": 2, "at_bound": 1, "non_physical": 0, "fallback": 0, "n_fits": 3}
    assert counts.loc["mlp_scratch", "non_physical"] == 1 and counts.loc["mlp_scratch", "n_fits"] == 1


def test_paper_findings_hold_on_curves_drawn_from_eq1(rmse_table, protocol):
    """Windsor et al. III-D: EMG best or near-best of the paper's models at the 4 sampled stops; the scratch MLP
    extrapolates worst. (Our free-width EMG is not one of the paper's.)"""
    k = protocol.stops_sampled("arc")
    at_k = rmse_table.query("trajectory == 'arc' and k == @k").groupby("model").rmse.mean()
    assert at_k["emg"] <= 1.05 * at_k.drop(["emg", "emg_free_width"]).min()
    assert at_k["mlp_scratch"] > at_k["mlp_pretrained"]
    assert (rmse_table.query("model == 'emg'").status == OK).all()


def test_each_fit_is_seeded_by_its_own_dataset_and_k(rmse_table, artifacts_table, tiny_fit, protocol, workers):
    """Rows depend on neither the other datasets, nor the other models, nor the order of work (nor the workers)."""
    params = tiny_fit.model_copy(update={"models": ("mlp_pretrained",), "k_max": 4})  # variation: fewer fits
    alone = fig2_rmse(artifacts_table[0].query("dataset == 'arc_01'"), params, protocol, workers, progress=False)
    together = rmse_table.query("dataset == 'arc_01' and k <= 4 and model in @params.models")
    np.testing.assert_array_equal(alone.rmse.to_numpy(), together.rmse.to_numpy())
