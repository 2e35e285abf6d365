import numpy as np
import pandas as pd

from poseintegrity.tracking.experiments.small_blobs import small_blob_sweep, sweep_summary
from poseintegrity.tracking.simulation.errors import rms
from poseintegrity.tracking.experiments.accuracy import summarize_accuracy
from poseintegrity.tracking.experiments.filter_runs import (
    FilterRun,
    accuracy_runs,
    agreement_runs,
    pace_runs,
    experiment_rng,
    filter_agreement,
    study_filter_runs,
    sweep_runs,
)
from poseintegrity.tracking.experiments.lag import lag_candidates, normalized_lag_ms
from poseintegrity.tracking.experiments.robustness import ten_metre_jump
from poseintegrity.tracking.experiments.success import success_rates, success_recording, success_runs, two_tools_success
from poseintegrity.tracking.simulation.simulate import run_filter, run_no_filter, simulate

from tracking.track_section import TINY


def test_lag_of_a_delayed_signal_is_recovered():
    t = np.arange(0, 10, 0.046)
    signal = np.sin(2 * np.pi * 0.3 * t) + 0.5 * np.sin(2 * np.pi * 0.7 * t + 1)
    delayed = np.sin(2 * np.pi * 0.3 * (t - 0.12)) + 0.5 * np.sin(2 * np.pi * 0.7 * (t - 0.12) + 1)
    assert abs(normalized_lag_ms(t, signal, t, delayed, 500) - 120) <= 2
    assert rms(np.array([3.0, -4.0, np.nan])) == np.sqrt(12.5)


def test_lag_candidates_hold_the_lag_that_every_exact_correlation_picks():
    rng = np.random.default_rng(5)
    for k in range(40):
        a = np.cumsum(rng.normal(size=int(rng.integers(50, 4000)))) * rng.choice([1e-3, 1.0, 1e3]) + rng.choice([0.0, 450.0])
        b = np.roll(a, int(rng.integers(0, 40))) + rng.normal(0.0, rng.choice([0.0, 0.01, 1.0]), len(a))
        if k % 8 == 0:
            b = np.round(b)  # plateaus: many nearly equal correlations
        n_lags = min(300, len(a) // 2)
        exact = []
        for lag in range(n_lags):  # normalized_lag_ms's correlation, at every lag (NaN where a window is flat)
            x, y = a[: len(a) - lag] - a[: len(a) - lag].mean(), b[lag:] - b[lag:].mean()
            with np.errstate(invalid="ignore"):
                exact.append((x @ y) / np.sqrt((x @ x) * (y @ y)))
        exact = np.where(np.isnan(exact), -np.inf, exact)  # NaN never wins in normalized_lag_ms
        assert int(np.argmax(exact)) in lag_candidates(a, b, n_lags)
        assert all(exact[lag] < max(exact) for lag in set(range(n_lags)) - set(lag_candidates(a, b, n_lags)))


def test_simulation_is_bit_identical_for_a_seed_and_the_filter_beats_no_filter_on_rotation():
    sims = [simulate(TINY, np.random.default_rng(11))[0] for _ in range(2)]
    tables = [run_no_filter(s, TINY) for s in sims]
    pd.testing.assert_frame_equal(tables[0], tables[1])
    filtered, _ = run_filter(sims[0], TINY, use_gyro=True)
    again, _ = run_filter(sims[1], TINY, use_gyro=True)
    pd.testing.assert_frame_equal(filtered, again)
    acc = summarize_accuracy(tables[0], {"ukf_gyro": filtered})
    assert tables[0].correct.mean() > 0.5
    assert 0.5 < acc["no_filter"]["norm_mm"] < 10  # the detection chain's error, not zero
    assert acc["no_filter"]["axis_mm"] < acc["no_filter"]["norm_mm"]  # per axis is the smaller number
    assert acc["ukf_gyro"]["geodesic_deg"] < acc["no_filter"]["geodesic_deg"]
    inside = filtered[filtered.in_occlusion]
    assert np.isfinite(inside.rot_err_deg).all()  # the gyro keeps the filter running through the occlusion


def success_tables(params):
    return {name: table for run in success_runs(params) for name, (table, _) in success_recording(params, run).items()}


def test_success_rates_cover_both_motions_and_the_split_variant():
    table, frames = success_rates(TINY, success_tables(TINY))
    assert len(table) == 9 and set(table.motion) == {"a", "b"}  # (a): 4 markers, 3 with each marker dropped; (b): 4, 3, split or not
    assert set(table.dropped[table.motion == "a"]) == {0, 1, 2, 3, 4}
    assert (table.frames == TINY.evaluation.success_frames).all()
    assert ((table.rate >= 0) & (table.rate <= table.possible)).all()  # a hidden marker cannot be found
    again, _ = success_rates(TINY, success_tables(TINY))
    pd.testing.assert_frame_equal(table, again)


def test_the_stress_recording_is_rendered_once_for_both_detectors():
    """With and without splitting touching blobs, (b) runs on the same frames: the same rendering and a detector
    run alone on it (simulate with one detector) gives the same points as with two."""
    run = next(r for r in success_runs(TINY) if r.motion == "b")
    both = success_recording(TINY, run, keep=True)
    split, unsplit = both[f"b_{run.label}"][1], both[f"b_{run.label}_no_split"][1]
    np.testing.assert_array_equal(split.T_true, unsplit.T_true)
    duration = split.trajectory.t[-1]
    [alone] = simulate(TINY, experiment_rng(TINY, f"stress_{run.label}"), np.array(TINY.markers_body), TINY.evaluation.success_omega_std,
                       duration, [TINY.detection.model_copy(update={"split_touching": False})], n_frames=TINY.evaluation.success_frames)
    assert all(np.array_equal(a, b) for a, b in zip(alone.points, unsplit.points)) and len(alone.points) == len(unsplit.points)


def test_a_recording_cut_to_its_first_frames_is_the_start_of_the_whole_one():
    """success_recording renders only the counted frames: the motion and timeline are drawn for the whole
    duration, so the frames, their detections and a filter run over them are the start of the uncut ones."""
    n = 30
    [whole] = simulate(TINY, np.random.default_rng(5), duration_s=2.5)
    [cut] = simulate(TINY, np.random.default_rng(5), duration_s=2.5, n_frames=n)
    assert len(cut.points) == n < len(whole.points)
    assert all(np.array_equal(a, b) for a, b in zip(cut.points, whole.points[:n]))
    np.testing.assert_array_equal(cut.T_true, whole.T_true[:n])
    last = cut.timeline.frame_index[-1]
    assert cut.timeline.gyro_index.max() == last  # the gyro samples up to the last frame and none after it
    np.testing.assert_array_equal(cut.timeline.gyro, whole.timeline.gyro[whole.timeline.gyro_index <= last])
    cut_run, _ = run_filter(cut, TINY, use_gyro=True)
    whole_run, _ = run_filter(whole, TINY, use_gyro=True)
    pd.testing.assert_frame_equal(cut_run, whole_run.iloc[: len(cut_run)])
    assert cut_run.frame.max() == n - 1 and (whole_run.iloc[len(cut_run) :].frame.max()) > n - 1


def test_each_filter_run_is_made_once_and_shared_by_the_experiments_that_need_it():
    params = TINY.model_copy(update={"evaluation": TINY.evaluation.model_copy(update={"sigma_scales": [0.5, 1.0, 2.0]})})
    runs = study_filter_runs(params)
    assert len(runs) == len(set(runs))
    assert sweep_runs(params)[1.0] == accuracy_runs(params)["ukf"]  # the sweep at scale 1 is the accuracy run
    sr, _ = agreement_runs(params)[f"alpha_{params.filter.alpha:g}"]
    assert sr == accuracy_runs(params)["ukf_gyro"] and isinstance(sr, FilterRun)
    assert set(pace_runs(params).values()) <= set(runs) and {run.recording for run in pace_runs(params).values()} == {"pace"}
    # 5 sigma variants on motion (a), the published sigmas and ours at the paper's pace, ukf and ukf_gyro, 2 new sweep
    # scales, and 3 new agreement runs
    assert len(runs) == 5 + 2 + 2 + 2 + 3


def test_small_blob_sweep_and_two_tools_and_jump_on_tiny_params():
    sweep = small_blob_sweep(TINY, experiment_rng(TINY, "small_blobs"))
    summary = sweep_summary(sweep)
    assert summary["marker_keep_rate"]["pixel"] >= summary["marker_keep_rate"]["contour"]
    assert set(sweep.measure) == {"contour", "pixel"} and set(sweep.kind) == {"marker", "phantom"}
    tools = two_tools_success(TINY, 6, "phantom_rich")
    assert set(tools.tool) == {"tool1", "tool2"} and tools.correct.mean() > 0.8
    [sim] = simulate(TINY, experiment_rng(TINY, "accuracy"))
    jump = ten_metre_jump(sim, TINY, jump_at_s=1.0, jump_m=10.0)
    assert jump["ok_while_off"] == 0 and jump["frames_to_restart"] == TINY.filter.restart_after_rejections - 1


def test_lag_and_agreement_are_nan_when_there_is_nothing_to_compare():
    t = np.arange(0, 2, 0.046)
    signal = np.sin(t)
    assert np.isnan(normalized_lag_ms(t, signal, t, np.full_like(t, np.nan), 300))  # the filter never ran
    assert np.isnan(normalized_lag_ms(t, signal, t + 10.0, signal, 300))  # no common stretch
    never = pd.DataFrame({"x_mm": [np.nan] * 3, "y_mm": [np.nan] * 3, "z_mm": [np.nan] * 3})
    ran = pd.DataFrame({"x_mm": [1.0, 2.0, 3.0], "y_mm": [0.0] * 3, "z_mm": [450.0] * 3})
    a, b = FilterRun("accuracy", True, TINY.filter), FilterRun("accuracy", False, TINY.filter)
    assert np.isnan(filter_agreement({a: (ran, None), b: (never, None)}, (a, b)))
    assert filter_agreement({a: (ran, None), b: (ran, None)}, (a, b)) == 0.0
