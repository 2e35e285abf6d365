import numpy as np
import pytest

from poseintegrity.tracking.experiments.lag import block_lag_sums, lag_candidates, lag_from_ncc, ncc_from_sums, normalized_lag_ms


def test_lag_of_a_delayed_signal_is_recovered():
    t = np.arange(0, 10, 0.046)
    signal = np.sin(2 * np.pi * 0.3 * t) + 0.5 * np.sin(2 * np.pi * 0.7 * t + 1)
    delayed = np.sin(2 * np.pi * 0.3 * (t - 0.12)) + 0.5 * np.sin(2 * np.pi * 0.7 * (t - 0.12) + 1)
    assert abs(normalized_lag_ms(t, signal, t, delayed, 500) - 120) <= 2


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


def test_block_sums_give_the_lag_and_correlation_of_the_whole_recording():
    rng = np.random.default_rng(6)
    t = np.arange(0.0, 23.0, 0.001)
    signal = np.convolve(rng.standard_normal(len(t)), np.ones(300) / 300, mode="same")
    delayed = np.interp(t - 0.120, t, signal) + 0.002 * rng.standard_normal(len(t))
    sums = block_lag_sums(signal, delayed, np.floor(t / 5.0).astype(int), 300)
    ncc = ncc_from_sums(sums.sum(axis=0))
    for lag in (0, 77, 120, 299):  # Pearson's correlation of a[:L - lag] and b[lag:], computed directly
        assert ncc[lag] == pytest.approx(np.corrcoef(signal[: len(t) - lag], delayed[lag:])[0, 1], rel=1e-9)
    assert lag_from_ncc(ncc) == normalized_lag_ms(t, signal, t, delayed, 300) == 120


def test_the_lag_is_nan_when_there_is_nothing_to_compare():
    t = np.arange(0, 2, 0.046)
    signal = np.sin(t)
    assert np.isnan(normalized_lag_ms(t, signal, t, np.full_like(t, np.nan), 300))  # the filter never ran
    assert np.isnan(normalized_lag_ms(t, signal, t + 10.0, signal, 300))  # no common stretch
