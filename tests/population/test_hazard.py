"""The failure hazard trained on the population's worlds (population/hazard.py): too few worlds train nothing, each
failed arc is given its failure mode, the Brier comparison, and every world predicted by models fitted without it."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.prediction.hazard.model import HazardFitError
from prediction.hazard.hazard_synthetic import THETA, arc_frames, load_protocol, synthetic_rows


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
