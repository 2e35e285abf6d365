"""The failure hazard (prediction/hazard, issue 50): evidence, risk sets, model, stopping rules, the model file."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from sklearn.linear_model import LogisticRegression

from poseintegrity.errors import ArgumentError
from poseintegrity.prediction.hazard.applied import HazardSet, hazard_rows, read_hazard, write_hazard
from poseintegrity.prediction.hazard.model import HazardFitError, HazardModel, brier_score, fit_hazard, reliability
from poseintegrity.prediction.hazard.risk_sets import LONG_RANGE, long_range_rows, next_step_rows
from poseintegrity.prediction.hazard.stop_evidence import EVIDENCE, stop_evidence, with_trends
from poseintegrity.prediction.hazard.stopping import stop_on_failure_probability, stop_on_next_hazard
from poseintegrity.protocol import ProtocolParams

THETA = np.arange(8) * 2.25  # deg


def arc_frames(world: str, dataset: str, counts: list[float], images: int = 2) -> pd.DataFrame:
    """Stage 02's rows of one arc: ``counts`` mean inliers per stop (0: no pose), errors falling with the count."""
    rows = []
    for stop, count in enumerate(counts):
        for image in range(images):
            posed = count > 0
            rows.append({"world": world, "dataset": dataset, "trajectory": "arc", "method": "usac_magsac",
                         "stop": stop, "image": image, "theta_deg": THETA[stop], "x_mm": 0.0,
                         "status": "ok" if posed else "no_pose", "n_inliers": count + image if posed else np.nan,
                         "n_matches": 2 * count + 10, "inlier_ratio": 0.5, "reproj_error_px": 0.3,
                         "inlier_hull_area_px2": 100.0 * count, "model_coverage": 0.01 * count,
                         "sigma_t_pred_mm": 2.0 / np.sqrt(max(count, 1)), "sigma_r_pred_deg": 0.5})
    return pd.DataFrame(rows)


def test_the_evidence_of_a_stop_is_the_mean_of_its_images_and_its_trend_reads_no_later_stop():
    frames = arc_frames("w", "a", [100, 80, 60, 40, 20, 10, 5, 0])
    evidence = stop_evidence(frames, "usac_magsac", (2.0, 3.0))
    assert list(evidence["stop"]) == list(range(8)) and set(EVIDENCE) <= set(evidence.columns)
    assert evidence.loc[0, "log_inliers"] == pytest.approx(np.log1p(100.5))  # counts 100 and 101
    assert evidence.loc[7, "posed_share"] == 0.0 and evidence.loc[7, "log_inliers"] == 0.0
    # the least squares slope of three equally spaced stops is (x_i - x_{i-2}) / 2; a later stop changes nothing
    x = evidence["log_inliers"].to_numpy()
    assert evidence.loc[4, "log_inliers_slope"] == pytest.approx((x[4] - x[2]) / 2)
    assert evidence.loc[4, "log_inliers_acceleration"] == pytest.approx(x[4] - 2 * x[3] + x[2])
    cut = stop_evidence(frames[frames["stop"] <= 4], "usac_magsac", (2.0, 3.0))
    pd.testing.assert_frame_equal(cut, evidence.iloc[:5], check_dtype=False)
    assert evidence["kinematic_error"].isna().all()  # a column stage 02 did not write stays missing (NaN)


def test_the_risk_set_ends_at_the_failing_stop_and_a_censored_arc_never_fails():
    evidence = with_trends(stop_evidence(arc_frames("w", "a", [100] * 8), "usac_magsac", (2.0, 3.0)))
    envelopes = pd.DataFrame({"world": ["w"], "dataset": ["a"], "theta_a": [10.0], "censored": [False]})
    rows = next_step_rows(evidence, envelopes, k=4)
    # stops 3 (6.75 deg) and 4 (9.0 deg) are at risk (theta_a > theta_i); stop 5 (11.25) is the first past theta_a
    assert list(rows["stop"]) == [3, 4] and list(rows["failed"]) == [0, 1]
    ahead = long_range_rows(evidence, envelopes, k=4)  # from stop 1 on, the sampled stops among them
    assert list(ahead["theta_deg"]) == list(THETA[1:6]) and list(ahead["failed"]) == [0, 0, 0, 0, 1]
    assert (ahead["ahead_deg"] == ahead["theta_deg"] - THETA[3]).all() and list(ahead.columns[:len(LONG_RANGE)]) \
        == list(LONG_RANGE)
    censored = envelopes.assign(theta_a=THETA[-1], censored=True)
    assert next_step_rows(evidence, censored, k=4)["failed"].sum() == 0
    assert long_range_rows(evidence, censored, k=4)["failed"].sum() == 0


def synthetic_rows(n_worlds: int, n: int, seed: int) -> pd.DataFrame:
    """Rows whose failure follows a known logistic law of two columns (the third is noise)."""
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(n_worlds * n, 3))
    p = 1 / (1 + np.exp(-(-1.5 + 2.0 * x[:, 0] - 1.0 * x[:, 1])))
    return pd.DataFrame({"a": x[:, 0], "b": x[:, 1], "noise": x[:, 2], "failed": (rng.random(len(p)) < p).astype(int),
                         "world": np.repeat([f"w{i}" for i in range(n_worlds)], n), "p_true": p})


def test_the_hazard_is_scikit_learn_s_logistic_regression_calibrated_on_held_out_worlds():
    rows = synthetic_rows(6, 400, 1)
    model = fit_hazard(rows, ("a", "b", "noise"), C=1.0, calibration_folds=3)
    X = rows[["a", "b", "noise"]].to_numpy()
    reference = LogisticRegression(C=1.0).fit((X - X.mean(0)) / X.std(0), rows["failed"])
    np.testing.assert_allclose(model.coef, reference.coef_[0], rtol=1e-4)
    # the held-out calibration of a well specified model is near the identity
    assert model.slope_a == pytest.approx(1.0, abs=0.15) and model.offset_c == pytest.approx(0.0, abs=0.15)
    fresh = synthetic_rows(2, 2000, 2)
    p = model.predict(fresh)
    assert np.abs(p - fresh["p_true"]).mean() < 0.03
    assert brier_score(p, fresh["failed"]) < brier_score(np.full(len(p), fresh["failed"].mean()), fresh["failed"])
    table = reliability(p, fresh["failed"], np.linspace(0, 1, 6))
    busy = table[table["n"] > 200]
    np.testing.assert_allclose(busy["failure_rate"], busy["mean_hazard"], atol=0.05)
    assert table["n"].sum() == len(p)


def test_a_missing_column_is_filled_with_its_training_median():
    rows = synthetic_rows(4, 200, 3)
    model = fit_hazard(rows, ("a", "b"), C=1.0, calibration_folds=2)
    without = rows.drop(columns="b")
    filled = rows.assign(b=model.fill[1])
    np.testing.assert_allclose(model.predict(without), model.predict(filled))


def test_rows_a_hazard_cannot_be_fitted_on_are_refused_by_name(monkeypatch):
    from poseintegrity.prediction.hazard import model

    rows = synthetic_rows(3, 100, 4)
    with pytest.raises(HazardFitError, match="no failures"):
        fit_hazard(rows.assign(failed=0), ("a",), 1.0, 2)
    with pytest.raises(HazardFitError, match="at least 2 worlds"):
        fit_hazard(rows.assign(world="w0"), ("a",), 1.0, 2)
    monkeypatch.setattr(model, "MAX_ITERATIONS", 1)
    with pytest.raises(HazardFitError, match="did not converge in 1 iterations"):
        fit_hazard(rows, ("a", "b"), 1.0, 2)


def test_the_stopping_rules_stop_where_the_hazard_first_reaches_h():
    theta = np.arange(6) * 2.0
    hazard_next = np.array([0.9, 0.9, 0.1, 0.3, 0.2, np.nan])  # stops 0-1 sampled (k = 3): read from stop 2 on
    found = stop_on_next_hazard(theta, hazard_next, 3, np.array([0.05, 0.25, 0.5]))
    assert list(found.theta_p) == [4.0, 6.0, 10.0] and list(found.status) == ["stopped", "stopped", "end_of_path"]
    ahead = np.array([0.0, 0.0, 0.1, 0.2, 0.5])  # stops 1-5: failed by 0, 0, 0.1, 0.28, 0.64
    found = stop_on_failure_probability(theta, ahead, 3, np.array([0.05, 0.2, 0.5, 0.9]))
    assert list(found.theta_p) == [4.0, 6.0, 8.0, 10.0] and list(found.status) == ["root"] * 3 + ["censored"]
    early = stop_on_failure_probability(theta, np.array([0.6, 0.0, 0.0, 0.0, 0.0]), 3, np.array([0.5]))
    assert early.theta_p[0] == 0.0  # as the paper's long range, the end may lie among the sampled stops
    assert np.isnan(stop_on_next_hazard(theta[:2], hazard_next[:2], 3, np.array([0.1])).theta_p).all()


def test_the_model_file_round_trips_and_a_dataset_it_was_trained_on_gets_no_rows(tmp_path):
    protocol = ProtocolParams.model_validate(load_protocol())
    frames = pd.concat([arc_frames("main", f"s{i}_arc", [100, 90, 70, 50, 30, 15, 8, 0]) for i in range(3)])
    evidence_rows = synthetic_rows(3, 100, 5)
    models = {(name, predictor): fit_hazard(evidence_rows.rename(columns={"a": "log_inliers"}), ("log_inliers",), 1.0, 2)
              for name in protocol.tolerance_names for predictor in ("hazard_next_step", "hazard_long_range")}
    hazard = HazardSet(("s0_arc",), models, {key: 0.1 for key in models})
    write_hazard(tmp_path / "model.json", hazard)
    back = read_hazard(tmp_path / "model.json")
    assert back.trained_on == ("s0_arc",) and back.chosen == hazard.chosen
    levels = np.array([0.01, 0.1, 0.5])
    rows = hazard_rows(frames, back, protocol, levels)
    assert set(rows["dataset"]) == {"s1_arc", "s2_arc"}  # never a prediction for a dataset the model was trained on
    assert len(rows) == 2 * 2 * len(protocol.tolerance_names) * len(levels)
    pd.testing.assert_frame_equal(rows, hazard_rows(frames, hazard, protocol, levels))
    (tmp_path / "bad.json").write_text('{"format": 1, "tolerances": {"2mm_3deg": {"hazard_next_step": {"coef": 1}}}}')
    with pytest.raises(ArgumentError, match="bad.json, 2mm_3deg.hazard_next_step: not a hazard model"):
        read_hazard(tmp_path / "bad.json")
    with pytest.raises(ArgumentError, match="predict.hazard.model: cannot read"):
        read_hazard(tmp_path / "absent.json")


def load_protocol() -> dict:
    import yaml

    from repository import ROOT

    return yaml.safe_load((ROOT / "params.yaml").read_text())["protocol"]


def test_a_population_too_small_to_hold_a_world_out_trains_nothing_and_says_why():
    from poseintegrity.population.hazard import train_population

    protocol = ProtocolParams.model_validate(load_protocol())
    worlds = {f"w{i}": (arc_frames("main", f"w{i}_a", [100, 80, 60, 40, 20]), pd.DataFrame()) for i in range(3)}
    with pytest.raises(HazardFitError, match="at least 4 worlds in population.worlds .* got 3"):
        train_population(worlds, protocol, np.array([0.1]), 1.0, 2, 1, 0, 0.9, progress=False)


def test_each_failed_arc_is_given_the_mode_its_failing_stop_shows():
    from poseintegrity.population.hazard import World, failure_modes

    protocol = ProtocolParams.model_validate(load_protocol())
    frames = pd.concat([arc_frames("main", "cliff", [100, 90, 80, 70, 60, 5, 5, 5]),
                        arc_frames("main", "lost", [100, 90, 80, 70, 60, 0, 0, 0]),
                        arc_frames("main", "bias", [100] * 8), arc_frames("main", "never", [100] * 8)])
    name = protocol.tolerance_names[0]
    envelopes = pd.DataFrame({"world": "main", "dataset": ["cliff", "lost", "bias", "never"], "trajectory": "arc",
                              "method": "usac_magsac", "tolerance": name, "theta_a": [10.0, 10.0, 12.0, THETA[-1]],
                              "censored": [False, False, False, True]})
    world = World("w9", frames, envelopes, protocol.tolerances[0], name, protocol)
    modes = failure_modes(world, protocol.envelope.max_failed_fraction).set_index("dataset")
    assert modes["mode"].to_dict() == {"cliff": "cliff", "lost": "no_pose", "bias": "accelerating_bias"}
    assert modes.loc["bias", "failed_stop"] == 6 and modes.loc["bias", "stop_before"] == 5  # 12 deg: after 11.25


def test_the_brier_comparison_resamples_worlds_and_says_which_hazard_is_better():
    from poseintegrity.population.hazard import brier_table

    rows = synthetic_rows(8, 300, 6)
    risk = rows.assign(tolerance="2mm_3deg", predictor="hazard_next_step", hazard=rows["p_true"],
                       error_alone=rows["failed"].mean(), inliers_alone=rows["p_true"])
    table = brier_table(risk, 500, 0.9, np.random.default_rng(0)).iloc[0]
    assert table["hazard"] == pytest.approx(np.mean((rows["p_true"] - rows["failed"]) ** 2))
    assert table["error_alone"] == pytest.approx(table["base_rate"])
    low, high = table["error_alone_minus_hazard"]
    assert 0 < low < table["error_alone"] - table["hazard"] < high  # the true law beats knowing the base rate alone
    assert table["inliers_alone_minus_hazard"] == [0.0, 0.0]  # the same hazard: no difference in any draw


def synthetic_world(name: str, seed: int) -> tuple[pd.DataFrame, pd.DataFrame]:
    """A world of 6 arcs whose counts fall at their own rates, each arc failing where its count drops below 30."""
    rng = np.random.default_rng(seed)
    protocol = ProtocolParams.model_validate(load_protocol())
    frames, envelopes = [], []
    for arc in range(6):
        rate = rng.uniform(0.1, 0.5)
        counts = [float(np.round(120 * np.exp(-rate * stop))) for stop in range(8)]
        frames.append(arc_frames("main", f"{name}_a{arc}", counts))
        failing = next((stop for stop, count in enumerate(counts) if count < 30), None)
        for tolerance in protocol.tolerance_names:
            envelopes.append({"world": "main", "dataset": f"{name}_a{arc}", "trajectory": "arc",
                              "method": "usac_magsac", "tolerance": tolerance, "rule": "fail_fraction",
                              "theta_a": THETA[-1] if failing is None else THETA[failing] - 1.0,
                              "censored": failing is None, "status": "ok", "reason": ""})
    return pd.concat(frames, ignore_index=True), pd.DataFrame(envelopes)


def test_every_world_is_predicted_by_models_fitted_without_it():
    from poseintegrity.population.hazard import FEATURES, train_population, world_tables

    protocol = ProtocolParams.model_validate(load_protocol())
    worlds = {f"w{i}": world_tables(*synthetic_world(f"w{i}", i), protocol) for i in range(5)}
    levels = np.array([0.01, 0.05, 0.2, 0.5])
    trained = train_population(worlds, protocol, levels, 1.0, 2, 2, 0, 0.6, progress=False)
    assert set(trained["predictions"]["world"]) == set(worlds) and set(trained["chosen"]["world"]) == set(worlds)
    assert len(trained["hazard"].trained_on) == 30 and len(trained["hazard"].models) == 2 * len(protocol.tolerances)
    # world w0's rows are those of models fitted on w1-w4 alone (recomputed here): nothing of w0 went into them
    from poseintegrity.population.hazard import World, fit_models, predicted

    name, tolerance = protocol.tolerance_names[0], protocol.tolerances[0]
    population = [World(w, *tables, tolerance, name, protocol) for w, tables in worlds.items()]
    models = fit_models(population[1:], 1.0, 2)
    expected = predicted(population[0], models, protocol, name, levels)
    found = trained["predictions"]
    found = found[(found["world"] == "w0") & (found["tolerance"] == name)].reset_index(drop=True)
    pd.testing.assert_frame_equal(found, expected.reset_index(drop=True))
    assert set(models) == set(FEATURES)
