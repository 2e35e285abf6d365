from pathlib import Path

import numpy as np
import pandas as pd

from poseintegrity.config import load_section
from poseintegrity.tracking.detection_sweep import small_blob_sweep, sweep_summary
from poseintegrity.tracking.errors import rms
from poseintegrity.tracking.evaluation import (
    experiment_rng,
    normalized_lag_ms,
    success_rates,
    summarize_accuracy,
    ten_metre_jump,
    two_tools_success,
)
from poseintegrity.tracking.simulation import run_filter, run_no_filter, simulate

TINY = load_section(Path(__file__).resolve().parents[1] / "params_tiny.yaml", "track")


def test_lag_of_a_delayed_signal_is_recovered():
    t = np.arange(0, 10, 0.046)
    signal = np.sin(2 * np.pi * 0.3 * t) + 0.5 * np.sin(2 * np.pi * 0.7 * t + 1)
    delayed = np.sin(2 * np.pi * 0.3 * (t - 0.12)) + 0.5 * np.sin(2 * np.pi * 0.7 * (t - 0.12) + 1)
    assert abs(normalized_lag_ms(t, signal, t, delayed, 500) - 120) <= 2
    assert rms(np.array([3.0, -4.0, np.nan])) == np.sqrt(12.5)


def test_simulation_is_bit_identical_for_a_seed_and_the_filter_beats_no_filter_on_rotation():
    sims = [simulate(TINY, np.random.default_rng(11)) for _ in range(2)]
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


def test_success_rates_cover_both_motions_and_the_split_variant():
    table, sims, frames = success_rates(TINY)
    assert len(table) == 9 and set(table.motion) == {"a", "b"}  # (a): 4 markers, 3 with each marker dropped; (b): 4, 3, split or not
    assert set(table.dropped[table.motion == "a"]) == {0, 1, 2, 3, 4}
    assert (table.frames == TINY.evaluation.success_frames).all()
    assert ((table.rate >= 0) & (table.rate <= table.possible)).all()  # a hidden marker cannot be found
    again, _, _ = success_rates(TINY)
    pd.testing.assert_frame_equal(table, again)


def test_small_blob_sweep_and_two_tools_and_jump_on_tiny_params():
    sweep = small_blob_sweep(TINY, experiment_rng(TINY, "small_blobs"))
    summary = sweep_summary(sweep)
    assert summary["marker_keep_rate"]["pixel"] >= summary["marker_keep_rate"]["contour"]
    assert set(sweep.measure) == {"contour", "pixel"} and set(sweep.kind) == {"marker", "phantom"}
    tools = two_tools_success(TINY, 6, "phantom_rich")
    assert set(tools.tool) == {"tool1", "tool2"} and tools.correct.mean() > 0.8
    sim = simulate(TINY, experiment_rng(TINY, "accuracy"))
    jump = ten_metre_jump(sim, TINY, jump_at_s=1.0, jump_m=10.0)
    assert jump["ok_while_off"] == 0 and jump["frames_to_restart"] == TINY.filter.restart_after_rejections - 1
