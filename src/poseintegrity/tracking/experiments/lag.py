"""The filter's lag behind the unfiltered chain (II-F: noise against lag): the delay that best aligns the filtered
track with the unfiltered one, by normalized cross-correlation."""

from __future__ import annotations

import numpy as np
import pandas as pd
import scipy.fft
import scipy.signal
from scipy.spatial.transform import Rotation

from poseintegrity.tracking.simulation.errors import EULER_SEQUENCE
from poseintegrity.tracking.simulation.motion import Trajectory


def common_grid(t_ref: np.ndarray, ref: np.ndarray, t_sig: np.ndarray, sig: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(grid (L,) s, ref (L,), sig (L,)): both signals (k,) at times t_ref, t_sig (s) linearly interpolated over their
    finite samples on a 1 ms grid spanning their common stretch; None if either has fewer than two finite samples."""
    ok_r, ok_s = np.isfinite(ref), np.isfinite(sig)
    if ok_r.sum() < 2 or ok_s.sum() < 2:
        return None
    start, stop = max(t_ref[ok_r][0], t_sig[ok_s][0]), min(t_ref[ok_r][-1], t_sig[ok_s][-1])
    grid = np.arange(start, stop, 0.001)
    return grid, np.interp(grid, t_ref[ok_r], ref[ok_r]), np.interp(grid, t_sig[ok_s], sig[ok_s])


def normalized_lag_ms(t_ref: np.ndarray, ref: np.ndarray, t_sig: np.ndarray, sig: np.ndarray, lag_max_ms: float) -> float:
    """Delay (ms) of sig behind ref: the lag maximising their normalized cross-correlation (section II-F).

    Both signals (k,) are resampled on a common 1 ms grid (linear interpolation over their finite samples);
    lags 0..lag_max_ms are searched.  NaN when there is nothing to correlate: fewer than two finite samples
    of either signal, no common stretch of at least 2 ms, or no lag at which both vary.
    """
    common = common_grid(t_ref, ref, t_sig, sig)
    if common is None:
        return float("nan")
    grid, a, b = common
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


def lag_signals(no_filter: pd.DataFrame, filtered: pd.DataFrame) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """(t_ref, ref, t_sig, sig) per position axis x, y, z (mm): the correct unfiltered frames as the reference, the
    filtered position at every event as the signal."""
    ref = no_filter[no_filter.correct]
    return [(ref.t.to_numpy(), ref[col].to_numpy(), filtered.t.to_numpy(), filtered[col].to_numpy()) for col in ["x_mm", "y_mm", "z_mm"]]


def filter_lag_ms(no_filter: pd.DataFrame, filtered: pd.DataFrame, lag_max_ms: float) -> float:
    """Mean over x, y, z of the lag (ms) of the filtered position behind the unfiltered one (Fig. 9).

    Only correct unfiltered frames are used as the reference; the filtered signal is taken at every event.
    """
    return float(np.mean([normalized_lag_ms(*signals, lag_max_ms) for signals in lag_signals(no_filter, filtered)]))


def euler_lag_ms(trajectory: Trajectory, no_filter: pd.DataFrame, filtered: pd.DataFrame, lag_max_ms: float) -> float:
    """Mean over the three Unity Euler angles of the lag (ms) of the filtered orientation behind the unfiltered one,
    as :func:`filter_lag_ms` for position (ours: a simulated recording's, whose truth gives the angles).  Each
    table's angle is the truth's (unwrapped along ``trajectory``, whose grid times the tables' t are) plus its
    wrapped error column (dyaw_deg, dpitch_deg, droll_deg)."""
    truth = np.unwrap(Rotation.from_quat(trajectory.quat).as_euler(EULER_SEQUENCE, degrees=True), period=360.0, axis=0)
    ref = no_filter[no_filter.correct]
    at_ref, at_sig = np.searchsorted(trajectory.t, ref.t.to_numpy()), np.searchsorted(trajectory.t, filtered.t.to_numpy())
    return float(np.mean([normalized_lag_ms(ref.t.to_numpy(), truth[at_ref, i] + ref[column].to_numpy(), filtered.t.to_numpy(),
                                            truth[at_sig, i] + filtered[column].to_numpy(), lag_max_ms)
                          for i, column in enumerate(("dyaw_deg", "dpitch_deg", "droll_deg"))]))


SUMS = ("n", "a", "b", "aa", "bb", "ab")  # the per-block sums of :func:`block_lag_sums`


def block_lag_sums(a: np.ndarray, b: np.ndarray, block: np.ndarray, n_lags: int) -> np.ndarray:
    """(k, 6, n_lags) sums over the pairs (a[i], b[i + lag]), i < L - lag, that block k holds, for lags 0..n_lags-1:
    the count and the sums of :data:`SUMS`.  a, b (L,) on one grid; block (L,) int, the block 0..k-1 of each
    reference sample a[i], non-decreasing.  A pair belongs to the block of its reference sample, so a resampled block
    carries its pairs whole and the weighted sums give the correlation :func:`normalized_lag_ms` computes on the
    resampled recording (:func:`ncc_from_sums`).  Both signals are centred first (the correlation does not change;
    the sums lose less to rounding)."""
    L, lags = len(a), np.arange(n_lags)
    a, b = a - a.mean(), b - b.mean()
    b_padded = np.concatenate([b, np.zeros(n_lags)])
    sums = np.zeros((int(block[-1]) + 1, len(SUMS), n_lags))
    cum = {name: np.concatenate([[0.0], np.cumsum(x)]) for name, x in (("a", a), ("aa", a * a), ("b", b), ("bb", b * b))}
    for k, (s, e) in enumerate(zip(np.searchsorted(block, np.arange(len(sums))), np.searchsorted(block, np.arange(len(sums)), "right"))):
        m = np.maximum(np.minimum(e, L - lags), s)  # pairs i in [s, m) of each lag
        sums[k, 0] = m - s
        sums[k, 1], sums[k, 3] = cum["a"][m] - cum["a"][s], cum["aa"][m] - cum["aa"][s]
        top, bottom = np.minimum(m + lags, L), np.minimum(s + lags, L)
        sums[k, 2], sums[k, 4] = cum["b"][top] - cum["b"][bottom], cum["bb"][top] - cum["bb"][bottom]
        if e > s:  # sum_i a[i] b[i + lag], b zero beyond L
            sums[k, 5] = scipy.signal.correlate(b_padded[s : e + n_lags - 1], a[s:e], mode="valid")
    return sums


def ncc_from_sums(sums: np.ndarray) -> np.ndarray:
    """(..., n_lags) normalized cross-correlation (Pearson's) of the pairs whose sums (..., 6, n_lags) are given
    (:func:`block_lag_sums`, weighted and added over blocks); NaN where a window does not vary."""
    n, sa, sb, saa, sbb, sab = np.moveaxis(sums, -2, 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return (sab - sa * sb / n) / np.sqrt((saa - sa * sa / n) * (sbb - sb * sb / n))


def lag_from_ncc(ncc: np.ndarray) -> np.ndarray:
    """(...) lag (ms, on the 1 ms grid) of the largest correlation of ncc (..., n_lags), its first one; NaN where
    no lag has a finite correlation (as :func:`normalized_lag_ms`)."""
    finite = np.isfinite(ncc)
    best = np.argmax(np.where(finite, ncc, -np.inf), axis=-1).astype(float)
    return np.where(finite.any(axis=-1), best, np.nan)
