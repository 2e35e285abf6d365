import numpy as np
import pandas as pd

from poseintegrity.tracking.evaluation import normalized_lag_ms, rms, run_filter, run_no_filter, simulate, summarize_accuracy
from poseintegrity.tracking.params import TrackParams

TINY = TrackParams.model_validate(
    {
        "motion": {"duration_s": 3.0, "occlusions": [(1.5, 0.4)]},
        "filter": {"sigma_r": 0.003, "sigma_c": 3.0, "sigma_alpha": 30.0},
    }
)


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
    assert 0.5 < acc["rms_mm"]["no_filter"] < 10  # the detection chain's error, not zero
    assert acc["rms_deg"]["ukf_gyro"] < acc["rms_deg"]["no_filter"]
    inside = filtered[filtered.in_occlusion]
    assert np.isfinite(inside.rot_err_deg).all()  # the gyro keeps the filter running through the occlusion
