"""The tracking headline's intervals (tracking/experiments/intervals.py, issue 49): blocks of the recording resampled,
checked on recordings whose answers are known."""

import numpy as np
import pandas as pd
import pytest

from poseintegrity.tracking.experiments.intervals import block_weights, rate_interval, rms_interval
from tracking.track_section import TRACK


def _frames(n: int, dt: float = 0.046, **columns) -> pd.DataFrame:
    return pd.DataFrame({"t": np.arange(n) * dt, **columns})


def test_frames_of_one_block_are_drawn_together():
    t = np.arange(400) * 0.046  # 18.4 s: blocks 0-3 of 5 s
    weights = block_weights(t, TRACK, "test")
    assert weights.shape == (TRACK.evaluation.interval_draws, 400)
    block = np.floor(t / TRACK.evaluation.interval_block_s)
    for b in np.unique(block):
        assert (weights[:, block == b] == weights[:, block == b][:, :1]).all()
    np.testing.assert_array_equal(weights, block_weights(t, TRACK, "test"))  # seeded by the experiment's name


def test_a_recording_without_a_failure_has_a_zero_width_interval():
    assert rate_interval(_frames(500, correct=np.ones(500, bool)), TRACK, "all") == [1.0, 1.0]
    errors = _frames(500, **{c: np.full(500, 2.0) for c in ("dx_mm", "dy_mm", "dz_mm")})
    assert rms_interval(errors, "axis_mm", TRACK, "constant") == pytest.approx([2.0, 2.0])


def test_failures_in_one_block_widen_the_interval_as_that_block_is_drawn_or_not():
    correct = np.ones(1000, bool)  # 46 s: 10 blocks; the failures all in the second
    correct[120:200] = False
    low, high = rate_interval(_frames(1000, correct=correct), TRACK, "one bad block")
    assert low < 0.92 < high  # the point value, 0.92, inside; with the bad block drawn twice, or not at all
    assert high == pytest.approx(1.0, abs=0.02) and low < 0.86
    dz = np.ones(1000)
    dz[::2] = np.nan  # left out, as rms_summary leaves them out
    per_axis = _frames(1000, dx_mm=np.where(correct, 1.0, 5.0), dy_mm=np.ones(1000), dz_mm=dz)
    low, high = rms_interval(per_axis, "axis_mm", TRACK, "errors")
    point = (np.sqrt(np.mean(np.where(correct, 1.0, 25.0))) + 2.0) / 3  # the mean of the three per-axis RMS
    assert 1.0 <= low < point < high
