import numpy as np
import pandas as pd

from poseintegrity.tracking.experiments.accuracy import summarize_accuracy
from poseintegrity.tracking.simulation.simulate import run_filter, run_no_filter, simulate

from tracking.track_section import TINY


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
