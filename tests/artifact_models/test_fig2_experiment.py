"""The Fig. 2 experiment on a synthetic artifacts table drawn from eq. 1 + noise."""

from __future__ import annotations

import numpy as np
import pytest

from poseintegrity.artifact_models import EMG, dataset_series, fig2_rmse, fits_metrics, mean_rmse

MODELS = ("emg", "exponential", "gaussian", "logistic", "power_law", "mlp_scratch", "mlp_pretrained")


@pytest.fixture(scope="module")
def rmse_table(artifacts_table, tiny_fit):
    return fig2_rmse(artifacts_table[0], tiny_fit, progress=False)


def test_series_are_one_per_dataset_of_the_chosen_method(artifacts_table):
    artifacts, _ = artifacts_table
    series = dataset_series(artifacts, "usac_magsac")
    assert [(s.trajectory, s.dataset) for s in series] == [
        ("arc", "arc_00"), ("arc", "arc_01"), ("arc", "arc_02"), ("line", "line_00"), ("line", "line_01")
    ]  # fmt: skip
    arc, line = series[0], series[-1]
    assert arc.n_stops == 20 and line.n_stops == 15
    np.testing.assert_array_equal(np.unique(arc.theta), 2.25 * np.arange(20))  # theta_deg for arcs
    np.testing.assert_array_equal(np.unique(line.theta), 10.0 * np.arange(15))  # x_mm for lines
    rows = artifacts[(artifacts.dataset == "arc_00") & (artifacts.method == "usac_magsac")]
    np.testing.assert_array_equal(np.sort(arc.n_inliers), np.sort(rows.n_inliers.to_numpy(float)))
    theta4, _ = arc.first_stops(4)
    np.testing.assert_array_equal(np.unique(theta4), [0.0, 2.25, 4.5, 6.75])  # from the model view


def test_unknown_method_names_the_methods_present(artifacts_table):
    with pytest.raises(ValueError, match=r"no rows with method 'sqpnp'.*epnp.*usac_magsac"):
        dataset_series(artifacts_table[0], "sqpnp")


def test_too_few_stops_for_k_min_is_a_configuration_error(artifacts_table, tiny_fit):
    short = artifacts_table[0].query("stop < 2")
    with pytest.raises(ValueError, match="no dataset has k_min = 3 stops"):
        fig2_rmse(short, tiny_fit, progress=False)


def test_metrics_name_every_model_even_without_fits_at_the_report_k(artifacts_table, tiny_fit):
    short = artifacts_table[0].query("stop < 3")
    metrics = fits_metrics(fig2_rmse(short, tiny_fit.model_copy(update={"models": ("emg",)}), progress=False), tiny_fit)
    assert metrics["rmse_k4"] == {name: None for name in MODELS}
    assert metrics["converged"] == {name: 1.0 if name == "emg" else None for name in MODELS}


def test_table_has_one_row_per_dataset_k_and_model(rmse_table, tiny_fit):
    assert list(rmse_table.columns) == [
        "trajectory", "dataset", "k", "model", "rmse", "converged", "reason", "n_samples"
    ]  # fmt: skip
    assert len(rmse_table) == 5 * (5 - 3 + 1) * len(MODELS)  # k_max = 5 < every dataset's stop count
    assert set(rmse_table.model) == set(tiny_fit.models)
    assert sorted(rmse_table.k.unique()) == [3, 4, 5]
    assert (rmse_table.n_samples == 10 * rmse_table.k).all()
    assert rmse_table.rmse.notna().all()


def test_rmse_is_over_the_whole_dataset(rmse_table, artifacts_table):
    series = dataset_series(artifacts_table[0], "usac_magsac")[1]
    theta, n = series.first_stops(4)
    model = EMG.fit(theta, n)
    expected = np.sqrt(np.mean((model.predict(series.theta) - series.n_inliers) ** 2))
    row = rmse_table.query("dataset == @series.dataset and k == 4 and model == 'emg'")
    assert row.rmse.item() == pytest.approx(expected, rel=1e-12)


def test_mean_rmse_and_metrics(rmse_table, tiny_fit):
    means = mean_rmse(rmse_table)
    arcs_k4 = rmse_table.query("trajectory == 'arc' and k == 4")
    expected = arcs_k4.groupby("model").rmse.mean()
    got = means.query("trajectory == 'arc' and k == 4").set_index("model").mean_rmse
    np.testing.assert_allclose(got.sort_index(), expected.sort_index(), rtol=1e-12)
    metrics = fits_metrics(rmse_table, tiny_fit)
    assert set(metrics) == {"rmse_k4", "line_rmse_k5", "converged"}
    assert set(metrics["rmse_k4"]) == set(MODELS) and set(metrics["converged"]) == set(MODELS)
    assert metrics["rmse_k4"]["emg"] == pytest.approx(expected["emg"])
    assert metrics["converged"]["emg"] == pytest.approx(rmse_table.query("model == 'emg'").converged.mean())


def test_paper_findings_hold_on_curves_drawn_from_eq1(rmse_table):
    """Windsor et al. III-D: EMG best or near-best at k = 4; the scratch MLP extrapolates worst."""
    at_k4 = rmse_table.query("trajectory == 'arc' and k == 4").groupby("model").rmse.mean()
    assert at_k4["emg"] <= 1.05 * at_k4.drop("emg").min()
    assert at_k4["mlp_scratch"] > at_k4["mlp_pretrained"]
    assert rmse_table.query("model == 'emg'").converged.all()


def test_each_fit_is_seeded_by_its_own_dataset_and_k(rmse_table, artifacts_table, tiny_fit):
    """Rows depend on neither the other datasets, nor the other models, nor the order of work (nor n_jobs)."""
    params = tiny_fit.model_copy(update={"models": ("mlp_pretrained",), "k_max": 4})
    alone = fig2_rmse(artifacts_table[0].query("dataset == 'arc_01'"), params, progress=False)
    together = rmse_table.query("dataset == 'arc_01' and k <= 4 and model in @params.models")
    np.testing.assert_array_equal(alone.rmse.to_numpy(), together.rmse.to_numpy())
