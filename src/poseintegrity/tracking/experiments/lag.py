"""The filter's lag behind the unfiltered chain (II-F: noise against lag): the delay that best aligns the filtered
track with the unfiltered one, by normalized cross-correlation."""

from __future__ import annotations

import numpy as np
import pandas as pd
import scipy.fft



def normalized_lag_ms(t_ref: np.ndarray, ref: np.ndarray, t_sig: np.ndarray, sig: np.ndarray, lag_max_ms: float) -> float:
    """Delay (ms) of sig behind ref: the lag maximising their normalized cross-correlation (section II-F).

    Both signals (k,) are resampled on a common 1 ms grid (linear interpolation over their finite samples);
    lags 0..lag_max_ms are searched.  NaN when there is nothing to correlate: fewer than two finite samples
    of either signal, no common stretch of at least 2 ms, or no lag at which both vary.
    """
    ok_r, ok_s = np.isfinite(ref), np.isfinite(sig)
    if ok_r.sum() < 2 or ok_s.sum() < 2:
        return float("nan")
    start, stop = max(t_ref[ok_r][0], t_sig[ok_s][0]), min(t_ref[ok_r][-1], t_sig[ok_s][-1])
    grid = np.arange(start, stop, 0.001)
    a = np.interp(grid, t_ref[ok_r], ref[ok_r])
    b = np.interp(grid, t_sig[ok_s], sig[ok_s])
    best, best_ncc = float("nan"), -np.inf
    for lag in lag_candidates(a, b, min(int(lag_max_ms), len(grid) // 2)):  # increasing lags, as range(n_lags) would
        x, y = a[: len(a) - lag], b[lag:]
        x, y = x - x.mean(), y - y.mean()
        ncc = (x @ y) / np.sqrt((x @ x) * (y @ y))
        if ncc > best_ncc:
            best, best_ncc = float(lag), ncc
    return best


LAG_MARGIN = 1e-6  # candidates lie this close to the estimated best correlation; the estimate is ~1e-10 off


LAG_MIN_SPREAD = 1e-2  # the estimate is trusted while each window's spread is >= this share of its sum of squares


def lag_candidates(a: np.ndarray, b: np.ndarray, n_lags: int) -> np.ndarray:
    """The lags 0..n_lags-1 at which the normalized cross-correlation of a[:L - lag] and b[lag:] (a, b (L,)) may be
    the largest: those whose estimate is within LAG_MARGIN of the best estimate, in increasing order.

    :func:`normalized_lag_ms` computes the correlation of these lags exactly as before and keeps the first
    largest one, so its lag is the one every lag's exact correlation gives, at a few lags' cost instead of
    n_lags full passes over a 460 000-sample recording.  The estimate centres both signals and takes every
    lag's sums at once (cross sums by FFT, window sums by cumulative sums; O(L log L)); it is off by ~1e-10,
    far below LAG_MARGIN.  Where it cannot be trusted (non-finite, or a window whose spread is below
    LAG_MIN_SPREAD of its sum of squares, which would amplify its rounding) every lag is a candidate.
    """
    if n_lags <= 0:
        return np.arange(0)
    L, lags = len(a), np.arange(n_lags)
    a0, b0 = a - a.mean(), b - b.mean()
    size = scipy.fft.next_fast_len(2 * L, real=True)
    cross = scipy.fft.irfft(np.conj(scipy.fft.rfft(a0, size)) * scipy.fft.rfft(b0, size), size)[:n_lags]  # sum_i a0[i] b0[i + lag]
    n = L - lags
    sa, saa = np.cumsum(a0)[n - 1], np.cumsum(a0 * a0)[n - 1]  # over a0[:L - lag]
    sb, sbb = np.cumsum(b0[::-1])[::-1][lags], np.cumsum((b0 * b0)[::-1])[::-1][lags]  # over b0[lag:]
    var_a, var_b = saa - sa * sa / n, sbb - sb * sb / n
    with np.errstate(divide="ignore", invalid="ignore"):
        ncc = (cross - sa * sb / n) / np.sqrt(var_a * var_b)
    trusted = np.all(np.isfinite(ncc)) and np.all(var_a >= LAG_MIN_SPREAD * saa) and np.all(var_b >= LAG_MIN_SPREAD * sbb)
    return np.flatnonzero(ncc >= ncc.max() - LAG_MARGIN) if trusted else lags


def filter_lag_ms(no_filter: pd.DataFrame, filtered: pd.DataFrame, lag_max_ms: float) -> float:
    """Mean over x, y, z of the lag (ms) of the filtered position behind the unfiltered one (Fig. 9).

    Only correct unfiltered frames are used as the reference; the filtered signal is taken at every event.
    """
    ref = no_filter[no_filter.correct]
    lags = [
        normalized_lag_ms(ref.t.to_numpy(), ref[col].to_numpy(), filtered.t.to_numpy(), filtered[col].to_numpy(), lag_max_ms)
        for col in ["x_mm", "y_mm", "z_mm"]
    ]
    return float(np.mean(lags))
