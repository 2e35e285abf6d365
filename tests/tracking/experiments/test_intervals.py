"""The tracking headline's intervals (tracking/experiments/intervals.py, issue 49): blocks of the recording resampled,
checked on recordings whose answers are known."""

import numpy as np
import pandas as pd
import pytest

from poseintegrity.tracking.experiments.filter_runs import experiment_rng
from poseintegrity.tracking.experiments.intervals import block_weights, lag_interval, mean_rate_interval, rate_interval, rms_interval
from poseintegrity.tracking.experiments.lag import filter_lag_ms
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


def test_the_mean_rates_interval_is_the_mean_of_recordings_resampled_by_the_same_blocks():
    """Against the resampling done by hand: each draw's blocks (the draws cluster_weights makes from the experiment's
    generator) gather every recording's frames of those seconds; each recording's share, then their mean."""
    params = TRACK.model_copy(update={"evaluation": TRACK.evaluation.model_copy(update={"interval_draws": 300})})
    rng = np.random.default_rng(5)
    tables = [_frames(n, correct=rng.random(n) < p) for n, p in ((400, 0.9), (400, 0.7), (330, 0.95))]  # 4, 4 and 3 blocks
    low, high = mean_rate_interval(tables, params, "mean test")
    blocks = [np.floor(df.t.to_numpy() / params.evaluation.interval_block_s) for df in tables]
    names = np.unique(np.concatenate(blocks))
    drawn = experiment_rng(params, "interval mean test").integers(0, len(names), size=(300, len(names)))
    means = []
    for draw in drawn:
        shares = []
        for df, block in zip(tables, blocks):
            picked = np.concatenate([df.correct.to_numpy()[block == names[k]] for k in draw])
            shares.append(picked.mean())
        means.append(np.mean(shares))
    assert [low, high] == pytest.approx(list(np.quantile(means, [0.05, 0.95], method="inverted_cdf")), rel=1e-12)
    assert low < np.mean([df.correct.mean() for df in tables]) < high


def test_the_lag_interval_holds_a_known_lag():
    rng = np.random.default_rng(7)
    t = np.arange(0.0, 40.0, 0.046)
    truth = np.cumsum(rng.standard_normal((len(t), 3)), axis=0)  # mm, a random walk per axis
    no_filter = pd.DataFrame({"t": t, "correct": True, **{c: truth[:, i] for i, c in enumerate(("x_mm", "y_mm", "z_mm"))}})
    t_fine = np.arange(0.0, 40.0, 0.0025)
    filtered = pd.DataFrame({"t": t_fine, **{c: np.interp(t_fine - 0.150, t, truth[:, i]) for i, c in enumerate(("x_mm", "y_mm", "z_mm"))}})
    assert filter_lag_ms(no_filter, filtered, 400) == pytest.approx(150, abs=3)
    params = TRACK.model_copy(update={"evaluation": TRACK.evaluation.model_copy(update={"interval_draws": 200, "lag_max_ms": 400})})
    low, high = lag_interval(no_filter, filtered, params, "lag test")
    assert 140 <= low <= filter_lag_ms(no_filter, filtered, 400) <= high <= 160
    assert lag_interval(no_filter, filtered.assign(x_mm=np.nan, y_mm=np.nan, z_mm=np.nan), params, "none") == [None, None]
