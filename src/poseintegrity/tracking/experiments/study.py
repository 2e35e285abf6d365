"""Section III on our simulation: one small function per experiment, each named after what it measures, and
:func:`run_study` that runs them all.

Each experiment draws from its own generator, ``keyed_rng(params.seed, name)`` (:mod:`poseintegrity.seeding`), so the
experiments do not depend on each other's order and the per-frame tables are bit-identical for one seed
(timings are the only non-deterministic outputs and are kept apart).  That lets :func:`run_study` run them as
independent tasks on :class:`~poseintegrity.parallel.Workers`: first the recordings (render + detect + the
no-filter chain) and the self-contained scenes, then every distinct filter run over those recordings once
(:class:`FilterRun`; an experiment that needs a run another already made reuses it), then the timings in the
calling process, alone on the machine.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd
import scipy.fft

from poseintegrity.seeding import keyed_rng
from poseintegrity.tracking.markers.correspondence import match_brute_force, match_markers_unchecked, match_voting
from poseintegrity.tracking.markers.detection import detect_markers, detect_markers_unchecked
from poseintegrity.tracking.experiments.small_blobs import small_blob_sweep, sweep_summary
from poseintegrity.tracking.simulation.errors import rms, rms_summary
from poseintegrity.tracking.simulation.frames import draw_phantoms, intrinsics, render_frame, unit_plane_lut
from poseintegrity.poses import pose_matrix
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M, transform_points
from poseintegrity.tracking.markers.kabsch import kabsch_unchecked, pose_from_points_unchecked
from poseintegrity.tracking.simulation.motion import sample_sensors, simulate_trajectory
from poseintegrity.parallel import Workers
from poseintegrity.paper_results import BLACK_RESULTS
from poseintegrity.tracking.params import PAPER_SIGMAS, FilterParams, TrackParams
from poseintegrity.tracking.experiments.peers import filter_speed, pykalman_time_update
from poseintegrity.tracking.io.recording import RecordingWriter, read_recording, track_recording
from poseintegrity.tracking.simulation.simulate import Simulation, T_world_cam, run_filter, run_no_filter, simulate, simulate_hand
from poseintegrity.tracking.filter.srukf import SquareRootUKF
from poseintegrity.tracking.filter.multi_tool import MultiToolTracker
from poseintegrity.tracking.filter.tracker import MarkerTracker
from poseintegrity.tracking.filter.ukf import UnscentedKalmanFilter
from poseintegrity.tracking.filter.unscented import UnscentedMarkerFilter


TIMING_METRICS = frozenset({"filter_step_ms", "speedup_vs_filterpy", "speedup_vs_pykalman", "timing_ms"})
"""The keys of tracking.json that are timings (machine-dependent): everything else is the same for one seed."""


def experiment_rng(params: TrackParams, name: str) -> np.random.Generator:
    """The generator of one experiment: keyed_rng(params.seed, name)."""
    return keyed_rng(params.seed, name)


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


def accuracy_frames(no_filter: pd.DataFrame) -> np.ndarray:
    """Frames on which accuracy is compared: correct unfiltered pose, outside deliberate occlusions."""
    return no_filter.frame[no_filter.correct & ~no_filter.in_occlusion].to_numpy()


def summarize_accuracy(no_filter: pd.DataFrame, runs: dict[str, pd.DataFrame]) -> dict[str, dict[str, float]]:
    """Per run (no_filter and every filter run) the RMS errors of :func:`~poseintegrity.tracking.simulation.errors.rms_summary`
    on the frames of :func:`accuracy_frames` (the filter rows of those marker frames)."""
    frames = accuracy_frames(no_filter)
    out = {"no_filter": rms_summary(no_filter[no_filter.frame.isin(frames)])}
    for name, df in runs.items():
        out[name] = rms_summary(df[(df.kind == "frame") & df.frame.isin(frames)])
    return out


def occlusion_summary(runs: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """Orientation held through the deliberate occlusions (Fig. 8): per run, the RMS rotation error inside
    the occlusion windows and the share of their events with a running filter."""
    rows = []
    for name, df in runs.items():
        inside = df[df.in_occlusion]
        share = float(np.isfinite(inside.rot_err_deg).mean()) if len(inside) else float("nan")
        rows.append({"run": name, "rms_deg": rms(inside.rot_err_deg), "share_tracked": share})
    return pd.DataFrame(rows)


@dataclass(frozen=True)
class FilterRun:
    """One run of the tracker over a recording (:func:`~poseintegrity.tracking.simulation.simulate.run_filter`).

    recording : "accuracy" (the accuracy recording) or "hand" (motion (a), 4 markers); settings : the filter's
    constants; filter_cls : the filter (SR-UKF of Alg. 5, or the plain UKF it is checked against).  Equal runs
    are equal keys: two experiments that need the same run share one.
    """

    recording: str
    use_gyro: bool
    settings: FilterParams
    filter_cls: type[UnscentedMarkerFilter] = SquareRootUKF


FilterResults = Mapping[FilterRun, tuple[pd.DataFrame, MarkerTracker]]


def accuracy_runs(params: TrackParams) -> dict[str, FilterRun]:
    """The filter runs of the accuracy recording: the UKF without and with the gyro."""
    return {"ukf": FilterRun("accuracy", False, params.filter), "ukf_gyro": FilterRun("accuracy", True, params.filter)}


def agreement_runs(params: TrackParams) -> dict[str, tuple[FilterRun, FilterRun]]:
    """SR-UKF against the plain UKF (gyro fused) on the accuracy recording, at alpha 1 and at params' alpha."""
    runs = {}
    for alpha in (1.0, params.filter.alpha):
        settings = params.filter.model_copy(update={"alpha": alpha})
        runs[f"alpha_{alpha:g}"] = (FilterRun("accuracy", True, settings), FilterRun("accuracy", True, settings, UnscentedKalmanFilter))
    return runs


def sweep_runs(params: TrackParams) -> dict[float, FilterRun]:
    """The noise-vs-lag runs (UKF, no gyro, accuracy recording): sigma_c and sigma_alpha times each of
    evaluation.sigma_scales."""
    fp = params.filter
    return {scale: FilterRun("accuracy", False, fp.model_copy(update={"sigma_c": fp.sigma_c * scale, "sigma_alpha": fp.sigma_alpha * scale}))
            for scale in params.evaluation.sigma_scales}


def sigma_variants(params: TrackParams) -> dict[str, FilterParams]:
    """The filter constants compared on motion (a) (:func:`published_against_our_sigmas`): the published sigmas,
    ours, the two halves swapped, and the published process sigmas read as per-second intensities."""
    process = ("sigma_c", "sigma_alpha")
    fp = params.filter
    return {
        "published": fp.model_copy(update=PAPER_SIGMAS),
        "ours": fp,
        "published_measurement_our_process": fp.model_copy(update={k: v for k, v in PAPER_SIGMAS.items() if k not in process}),
        "our_measurement_published_process": fp.model_copy(update={k: v for k, v in PAPER_SIGMAS.items() if k in process}),
        "published_per_second": fp.model_copy(update={**PAPER_SIGMAS, **{k: PAPER_SIGMAS[k] / np.sqrt(fp.dt) for k in process}}),
    }


def sigma_runs(params: TrackParams) -> dict[str, FilterRun]:
    """The runs of :func:`sigma_variants` on motion (a), 4 markers, UKF without gyro."""
    return {name: FilterRun("hand", False, settings) for name, settings in sigma_variants(params).items()}


def study_filter_runs(params: TrackParams) -> list[FilterRun]:
    """Every distinct filter run of the study, the long motion (a) runs first (they set the critical path)."""
    runs = [*sigma_runs(params).values(), *accuracy_runs(params).values(), *sweep_runs(params).values()]
    runs += [run for pair in agreement_runs(params).values() for run in pair]
    return list(dict.fromkeys(runs))


def run_filter_task(sim: Simulation, params: TrackParams, run: FilterRun) -> tuple[pd.DataFrame, MarkerTracker]:
    """:func:`~poseintegrity.tracking.simulation.simulate.run_filter` of one :class:`FilterRun` on its recording ``sim``."""
    return run_filter(sim, params, run.use_gyro, run.settings, run.filter_cls)


def filter_agreement(runs: FilterResults, pair: tuple[FilterRun, FilterRun]) -> float:
    """Largest relative difference of the filtered positions of the SR-UKF and another filter on the same
    recording: max |x_sr - x_other| / max |x_other| over the events where both run.  pair : (SR-UKF run, other)."""
    (a, _), (b, _) = runs[pair[0]], runs[pair[1]]
    xa, xb = a[["x_mm", "y_mm", "z_mm"]].to_numpy(), b[["x_mm", "y_mm", "z_mm"]].to_numpy()
    both = np.isfinite(xa).all(axis=1) & np.isfinite(xb).all(axis=1)
    if not both.any():  # the two never ran at the same event: nothing to compare
        return float("nan")
    return float(np.abs(xa[both] - xb[both]).max() / np.abs(xb[both]).max())


# -- experiments ---------------------------------------------------------------------------------------------


def accuracy_recording(params: TrackParams) -> tuple[Simulation, pd.DataFrame]:
    """The accuracy recording (params.motion, with its deliberate occlusion) and its no-filter table."""
    [sim] = simulate(params, experiment_rng(params, "accuracy"))
    return sim, run_no_filter(sim, params)


def accuracy_and_occlusion(sim: Simulation, no_filter: pd.DataFrame, params: TrackParams, runs: FilterResults) -> tuple[dict[str, pd.DataFrame], dict]:
    """On the accuracy recording: no filter, UKF, UKF + gyro; RMS errors both ways, lag, orientation through
    the occlusion, restarts, failed downdates, SR-UKF vs plain UKF.  runs : the results of :func:`accuracy_runs`
    and :func:`agreement_runs`."""
    named = {name: runs[run] for name, run in accuracy_runs(params).items()}
    frames, trackers = {name: df for name, (df, _) in named.items()}, {name: t for name, (_, t) in named.items()}
    occlusion = occlusion_summary(frames)
    metrics = {
        "rms": summarize_accuracy(no_filter, frames),
        "lag_ms": {name: filter_lag_ms(no_filter, df, params.evaluation.lag_max_ms) for name, df in frames.items()},
        "occlusion_rms_deg": dict(zip(occlusion.run, occlusion.rms_deg)),
        "occlusion_share_tracked": dict(zip(occlusion.run, occlusion.share_tracked)),
        "failed_downdates": int(sum(t.filter.failed_downdates for t in trackers.values())),
        "filter_steps": {name: int((df.flag == "ok").sum()) for name, df in frames.items()},
        "divergences": {name: t.filter.n_divergences for name, t in trackers.items()},
        "restarts": {name: t.n_restarts for name, t in trackers.items()},
        "gated_markers": {name: t.n_gated for name, t in trackers.items()},
        "srukf_vs_ukf_max_rel_diff": {name: filter_agreement(runs, pair) for name, pair in agreement_runs(params).items()},
        "n_frames": int(len(sim.t)),
    }
    return {"no_filter": no_filter, **frames, "occlusion": occlusion}, metrics


def noise_against_lag(no_filter: pd.DataFrame, params: TrackParams, runs: FilterResults) -> pd.DataFrame:
    """Noise-vs-lag trade-off (Figs. 6, 9) from the runs of :func:`sweep_runs`: sigma_c and sigma_alpha scaled
    by evaluation.sigma_scales.  One row per scale: RMS position (mm) and rotation (deg) error and lag (ms) of
    the UKF without gyro."""
    rows, frames = [], accuracy_frames(no_filter)
    for scale, run in sweep_runs(params).items():
        df, _ = runs[run]
        at_frames = df[(df.kind == "frame") & df.frame.isin(frames)]
        rows.append({"scale": scale, "rms_mm": rms(at_frames.pos_err_mm), "rms_deg": rms(at_frames.rot_err_deg),
                     "lag_ms": filter_lag_ms(no_filter, df, params.evaluation.lag_max_ms)})
    return pd.DataFrame(rows)


def success_frames_duration(params: TrackParams) -> float:
    """Seconds of recording that give at least evaluation.success_frames marker frames."""
    return params.evaluation.success_frames * params.motion.frame_interval_s * 1.2 + 1.0


@dataclass(frozen=True)
class SuccessRun:
    """One success-rate recording: motion "a" (paper-like) or "b" (stress); label markers4 / markers3 /
    markers3_drop<k>; dropped : index of the removed marker, -1 for none.  On (b) the frames are detected
    with and without splitting touching blobs (the same frames)."""

    motion: str
    label: str
    dropped: int


def success_runs(params: TrackParams) -> list[SuccessRun]:
    """(a) with 4 markers and with each marker removed (params.drop_marker's run is ``markers3``); (b) with 4
    markers and without params.drop_marker."""
    n = len(params.markers_body)
    three = {"markers3" if i == params.drop_marker else f"markers3_drop{i + 1}": i for i in range(n)}
    runs = [SuccessRun("a", "markers4", -1)] + [SuccessRun("a", label, i) for label, i in three.items()]
    return runs + [SuccessRun("b", "markers4", -1), SuccessRun("b", "markers3", params.drop_marker)]


def success_recording(params: TrackParams, run: SuccessRun, keep: bool = False) -> dict[str, tuple[pd.DataFrame, Simulation | None]]:
    """The recording of one :class:`SuccessRun` and its no-filter tables, by run name (``a_markers4``,
    ``b_markers3_no_split``, ...): {name: (no-filter table, recording if keep else None)} (a recording of motion
    (a) holds ~50 MB of ground truth: only the one filtered later is kept).  The motion and its timeline are
    drawn for success_frames_duration seconds, and only the evaluation.success_frames frames that are counted
    are rendered (and filtered later, for the kept one)."""
    geometry = np.array(params.markers_body)
    body = geometry if run.dropped < 0 else np.delete(geometry, run.dropped, axis=0)
    duration, n_frames = success_frames_duration(params), params.evaluation.success_frames
    if run.motion == "a":
        sims = {f"a_{run.label}": simulate_hand(params, experiment_rng(params, f"hand_{run.label}"), body, duration, n_frames)}
    else:
        no_split = params.detection.model_copy(update={"split_touching": False})
        split, unsplit = simulate(params, experiment_rng(params, f"stress_{run.label}"), body, params.evaluation.success_omega_std,
                                  duration, [params.detection, no_split], n_frames=n_frames)
        sims = {f"b_{run.label}": split, f"b_{run.label}_no_split": unsplit}
    return {name: (run_no_filter(sim, params), sim if keep else None) for name, sim in sims.items()}


def success_rates(params: TrackParams, no_filter: Mapping[str, pd.DataFrame]) -> tuple[pd.DataFrame, dict[str, pd.DataFrame]]:
    """Share of evaluation.success_frames frames with a correct pose (section III) on motion (a), paper-like, and
    motion (b), the stress test, with 4 and with 3 markers (params.drop_marker removed; the paper does not say
    which one it removed, so on (a) every other choice is run too, ``markers3_drop<k>``); on (b) also without
    splitting touching blobs (the same frames).  no_filter : the tables of :func:`success_recording` by run name.
    Returns (table motion/markers/dropped/split/rate/possible, per-frame tables ``success_<run>``).  ``possible``:
    share of frames with >= 3 markers not hidden by an occlusion (a marker hidden behind another still counts)."""
    n = params.evaluation.success_frames
    rows, tables = [], {}
    for run in success_runs(params):
        for split in (True,) if run.motion == "a" else (True, False):
            name = f"{run.motion}_{run.label}" + ("" if split else "_no_split")
            df = no_filter[name].iloc[:n]
            tables[f"success_{name}"] = df
            rows.append({"run": name, "motion": run.motion, "markers": run.label, "dropped": run.dropped + 1, "split_touching": split,
                         "rate": float(df.correct.mean()), "possible": float((df.n_visible >= 3).mean()), "frames": len(df)})
    return pd.DataFrame(rows), tables


def published_against_our_sigmas(no_filter: pd.DataFrame, params: TrackParams, runs: FilterResults) -> tuple[pd.DataFrame, dict]:
    """On motion (a) (4 markers; no_filter : its no-filter table): the UKF with the published sigmas and with
    ours, no gyro; the two halves swapped (published measurement sigma_r with our process sigmas, and the
    reverse) to see which half makes the difference; and the published process sigmas read as per-second
    intensities (:func:`sigma_variants`, run as :func:`sigma_runs`).  Eq. 30 adds dt^2 sigma^2 to omega's
    variance at every filter step, so over one second the variance grows by dt sigma^2: the published
    sigma_alpha = 0.71 rad/s^2 at the 400 Hz clock lets omega drift 0.035 rad/s in a second.  Read as a
    per-second intensity (variance sigma^2 per second, clock-independent) it is sigma / sqrt(dt / 1 s) per
    step.  RMS both ways on the correct no-filter frames, lag behind the no-filter signal, and how often the
    filter was gated or restarted."""
    frames = accuracy_frames(no_filter)
    rows, metrics = [], {}
    for name, run in sigma_runs(params).items():
        df, tracker = runs[run]
        summary = rms_summary(df[(df.kind == "frame") & df.frame.isin(frames)])
        lag = filter_lag_ms(no_filter, df, params.evaluation.lag_max_ms)
        frames_df = df[df.kind == "frame"]
        metrics[name] = {**summary, "lag_ms": lag, "restarts": tracker.n_restarts, "gated_markers": tracker.n_gated,
                         "share_ok": float((frames_df.flag == "ok").mean()), **{k: getattr(run.settings, k) for k in PAPER_SIGMAS}}
        rows.append({"sigmas": name, **metrics[name]})
    metrics["no_filter"] = rms_summary(no_filter[no_filter.frame.isin(frames)])
    return pd.DataFrame(rows), metrics


def two_tools_success(params: TrackParams, phantom_max: int, name: str) -> pd.DataFrame:
    """Two tools in view (params.markers_body and evaluation.second_tool), each on its own hand-like trajectory
    (the second 0.12 m to the side), one filter per tool (:class:`MultiToolTracker`), no gyro; phantoms
    binomial(phantom_max, p_phantom) per frame.  One row per frame and tool: correct (>= 3 markers matched and
    every matched point within correct_tolerance_m of its own marker)."""
    rng = experiment_rng(params, name)
    tools = {"tool1": np.array(params.markers_body), "tool2": np.array(params.evaluation.second_tool)}
    duration = params.evaluation.multi_tool_frames * params.motion.frame_interval_s * 1.2 + 1.0
    motion = params.motion.model_copy(update={"duration_s": duration, "occlusions": [], "max_phantoms": phantom_max})
    homes = {"tool1": np.array(motion.home_m) + [-0.06, 0.0, 0.0], "tool2": np.array(motion.home_m) + [0.06, 0.0, 0.0]}
    trajectories = {k: simulate_trajectory(motion.model_copy(update={"home_m": tuple(homes[k])}), rng) for k in tools}
    timeline = sample_sensors(trajectories["tool1"], 8, motion, rng)
    idx = timeline.frame_index[: params.evaluation.multi_tool_frames]
    K, T_wc = intrinsics(params.camera), T_world_cam(params)
    tracker = MultiToolTracker(tools, params.filter, params.matching)
    rows = []
    for f, i in enumerate(idx):
        T = {k: pose_matrix(tr.rotation(np.array([i]))[0], tr.position[i]) for k, tr in trajectories.items()}
        true = {k: transform_points(T[k], tools[k]) for k in tools}
        markers = np.vstack([true["tool1"], true["tool2"]])[~timeline.occluded[f]]
        phantoms = draw_phantoms(int(timeline.n_phantoms[f]), params.camera, params.frames, motion.phantom_round_fraction, rng)
        ir, depth = render_frame(transform_points(np.linalg.inv(T_wc), markers), phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng)
        points = detect_markers_unchecked(ir, depth, K, params.detection, T_world_cam=T_wc)  # rendered here: a usable frame
        for tool, result in tracker.frame(trajectories["tool1"].t[i], points).items():
            matched = result.assignment >= 0
            err = np.linalg.norm(points[result.assignment[matched]] - true[tool][matched], axis=1)
            rows.append({"scene": name, "frame": f, "tool": tool, "flag": result.flag, "n_points": len(points), "n_matched": int(matched.sum()),
                         "correct": bool(matched.sum() >= 3 and np.all(err <= params.evaluation.correct_tolerance_m))})
    return pd.DataFrame(rows)


def ten_metre_jump(sim: Simulation, params: TrackParams, jump_at_s: float = 2.0, jump_m: float = 10.0) -> dict:
    """The innovation gate on a persistent jump of every measured point by jump_m (m) along x at jump_at_s:
    the true markers of the accuracy recording (2 mm noise) are fed to the tracker, the jump persists.
    Returns how many frames after the jump were reported "ok" while more than 0.1 m off (must be 0), the flags
    seen, the frames until the restart, and the error after it."""
    rng = experiment_rng(params, "jump")
    tracker = MarkerTracker(sim.markers_body, params.filter, params.matching, use_gyro=False)
    flags, errors = [], []
    for f in range(len(sim.t)):
        t = sim.t[f]
        if t > jump_at_s + 2.0:
            break
        shift = np.array([jump_m, 0.0, 0.0]) if t >= jump_at_s else np.zeros(3)
        points = transform_points(sim.T_true[f], sim.markers_body) + rng.normal(0.0, 0.002, (len(sim.markers_body), 3))
        result = tracker.frame(t, points + shift)
        if t >= jump_at_s:
            flags.append(result.flag)
            errors.append(float(np.linalg.norm(result.T_filtered[:3, 3] - sim.T_true[f, :3, 3] - shift)))
    errors = np.array(errors)
    restart = flags.index("restart") if "restart" in flags else -1
    return {"frames_after_jump": len(flags), "ok_while_off": int(sum(fl == "ok" and e > 0.1 for fl, e in zip(flags, errors))),
            "flags": {fl: flags.count(fl) for fl in sorted(set(flags))}, "frames_to_restart": restart,
            "error_after_restart_mm": float(np.nanmax(errors[restart + 1 :]) * 1000) if 0 <= restart < len(errors) - 1 else float("nan")}


def recording_replay(params: TrackParams, folder: Path) -> tuple[pd.DataFrame, dict]:
    """Write evaluation.replay_s seconds of a simulated recording as a recording folder (16-bit PNG frames,
    gyro.csv, the unit-plane LUT) and replay it from disk with :func:`track_recording`; the in-memory run of the
    same recording (:func:`run_filter`, gyro fused) must give the same poses.  Returns (pose table, agreement)."""
    writer = RecordingWriter(folder, unit_plane_lut(intrinsics(params.camera), params.camera.width, params.camera.height), overwrite=True)
    [sim] = simulate(params, experiment_rng(params, "replay"), duration_s=params.evaluation.replay_s, sink=writer.add_frame)
    writer.close(sim.trajectory.t[sim.timeline.gyro_index], sim.timeline.gyro)
    table = track_recording(read_recording(folder), {"tool": sim.markers_body}, params, gyro_tool="tool")
    direct, _ = run_filter(sim, params, use_gyro=True)
    direct = direct[direct.kind == "frame"]
    diff = np.abs(table[["x_mm", "y_mm", "z_mm"]].to_numpy() - direct[["x_mm", "y_mm", "z_mm"]].to_numpy())
    same_nan = np.array_equal(np.isnan(diff), np.isnan(direct[["x_mm", "y_mm", "z_mm"]].to_numpy()))
    return table, {"frames": len(table), "max_position_diff_mm": float(np.nanmax(diff)) if np.isfinite(diff).any() else float("nan"),
                   "same_flags": bool((table.flag.to_numpy() == direct.flag.to_numpy()).all()) and same_nan}


def _mean_time_ms(fn, repeats: int) -> float:
    fn()
    start = time.perf_counter()
    for _ in range(repeats):
        fn()
    return (time.perf_counter() - start) / repeats * 1000.0


def detect_match_kabsch(ir: np.ndarray, depth_mm: np.ndarray, K: np.ndarray, params: TrackParams, geometry: np.ndarray) -> np.ndarray:
    """The no-filter chain on one frame: detection, correspondence, Kabsch.  Returns T_world_body (4, 4),
    NaN if fewer than 3 markers were matched."""
    points = detect_markers(ir, depth_mm, K, params.detection)
    assignment = match_markers_unchecked(points, geometry, None, params.matching)
    matched = assignment >= 0
    if matched.sum() < 3:
        return np.full((4, 4), np.nan)
    return pose_from_points_unchecked(points[assignment[matched]], geometry[matched])


def timing_table(sim: Simulation, params: TrackParams) -> pd.DataFrame:
    """Mean time (ms) of the subroutines, like Table I, on one frame of the recording with a round phantom."""
    rng = experiment_rng(params, "timing")
    K = intrinsics(params.camera)
    T_cw = np.linalg.inv(T_world_cam(params))
    geometry = sim.markers_body
    markers_cam = transform_points(T_cw, transform_points(sim.T_true[0], geometry))
    phantoms = draw_phantoms(1, params.camera, params.frames, 1.0, rng)
    ir, depth_mm = render_frame(markers_cam, phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng)
    points = detect_markers(ir, depth_mm, K, params.detection)
    tol, repeats = params.matching.tolerance_m, params.evaluation.timing_repeats
    tracker = MarkerTracker(geometry, params.filter, params.matching)
    tracker.frame(0.0, points)
    filt = tracker.filter
    z = filt.markers().ravel()
    observed = np.ones(len(geometry), dtype=bool)
    rows = {
        "Frame synthesis (ours)": lambda: render_frame(markers_cam, phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng),
        "Contour detection": lambda: detect_markers(ir, depth_mm, K, params.detection),
        "Euclidean matching": lambda: match_voting(points, geometry, tolerance_m=tol),
        "Brute force matching": lambda: match_brute_force(points, geometry, tolerance_m=tol, min_markers=params.matching.min_markers),
        "Kabsch algorithm": lambda: kabsch_unchecked(z.reshape(-1, 3), geometry),
        "Detection + correspondence + Kabsch": lambda: detect_match_kabsch(ir, depth_mm, K, params, geometry),
        "UKF state update (one dt step)": lambda: filt.predict(params.filter.dt),
        "UKF measurement update (markers + gyro)": lambda: filt.update(np.r_[z, np.zeros(3)], observed, True),
    }
    return pd.DataFrame([{"subroutine": name, "time_ms": _mean_time_ms(fn, repeats)} for name, fn in rows.items()])


@dataclass(frozen=True)
class Study:
    """Everything section III reports, on our simulation (see :func:`run_study`).

    tables : per-frame / per-event results to write as parquet (bit-identical for one seed);
    timing : Table I-like timings (ms, machine-dependent); metrics : the tracking.json content.
    """

    tables: dict[str, pd.DataFrame]
    timing: pd.DataFrame
    metrics: dict


def call(task: Callable[[], object]) -> object:
    """task(): what :meth:`~poseintegrity.parallel.Workers.map` runs for a list of heterogeneous tasks
    (``functools.partial`` of module-level functions)."""
    return task()


def run_study(params: TrackParams, recording_folder: Path, workers: Workers) -> Study:
    """Section III on our simulation: every experiment above, their tables and the metrics of tracking.json.

    recording_folder : where :func:`recording_replay` writes the replayed recording.  workers : where the
    recordings, scenes and filter runs run (tasks of their own generators, so the tables do not depend on
    the number of workers); the timings run in this process afterwards, with no task of ours beside them.
    Two rounds of tasks, each listed longest first so that the workers finish together: first the recordings
    the filter runs need (accuracy; motion (a), 4 markers) beside one stress recording (rendered once,
    detected twice: the longest) and the small scenes; then the filter runs beside the other recordings.
    """
    ev, hand = params.evaluation, SuccessRun("a", "markers4", -1)
    others = sorted((run for run in success_runs(params) if run != hand), key=lambda run: run.motion != "b")  # (b) first
    first = [partial(success_recording, params, others[0]), partial(success_recording, params, hand, True), partial(accuracy_recording, params),
             partial(two_tools_success, params, params.motion.max_phantoms, "two_tools"),
             partial(two_tools_success, params, ev.phantom_rich_max, "two_tools_phantom_rich"),
             partial(small_blob_sweep, params, experiment_rng(params, "small_blobs")),
             partial(recording_replay, params, Path(recording_folder).resolve())]
    stress, motion_a, (sim, no_filter), tools, rich_tools, blobs, (replay, replay_metrics) = workers.map(call, first, desc="tracking recordings")
    recordings = {"accuracy": sim, "hand": motion_a["a_markers4"][1]}
    filter_runs = study_filter_runs(params)
    second = [partial(success_recording, params, run) for run in others[1:]]
    second += [partial(run_filter_task, recordings[run.recording], params, run) for run in filter_runs]
    results = workers.map(call, second, desc="tracking recordings and filter runs")
    runs = dict(zip(filter_runs, results[len(others) - 1 :]))
    success_tables = {name: table for recorded in [stress, motion_a, *results[: len(others) - 1]] for name, (table, _) in recorded.items()}

    tables, accuracy = accuracy_and_occlusion(sim, no_filter, params, runs)
    success, success_frames = success_rates(params, success_tables)
    sigmas, sigma_metrics = published_against_our_sigmas(success_tables["a_markers4"], params, runs)
    multi_tool = pd.concat([tools, rich_tools], ignore_index=True)
    geometry = np.array(params.markers_body)
    speed = filter_speed(geometry, params.filter, ev.timing_repeats, experiment_rng(params, "speed"))
    rate = dict(zip(success.run, success.rate))
    metrics = {
        **accuracy,
        "rms_mm": {run: v["norm_mm"] for run, v in accuracy["rms"].items()},
        "rms_deg": {run: v["geodesic_deg"] for run, v in accuracy["rms"].items()},
        "rms_axis_mm": {run: v["axis_mm"] for run, v in accuracy["rms"].items()},
        "rms_euler_deg": {run: v["euler_deg"] for run, v in accuracy["rms"].items()},
        "euler_convention": "Unity: R = R_y R_x R_z (scipy intrinsic 'YXZ'); mean over the three angles of the RMS wrapped difference",
        "success_rate": {"markers4": rate["a_markers4"], "markers3": rate["a_markers3"]},
        "success_rates": rate,
        "success_possible": dict(zip(success.run, success.possible)),
        "sigmas_motion_a": sigma_metrics,
        "small_blobs": sweep_summary(blobs),
        "multi_tool_success": multi_tool.groupby(["scene", "tool"]).correct.mean().unstack().to_dict(orient="index"),
        "ten_metre_jump": ten_metre_jump(sim, params),
        "recording_replay": replay_metrics,
        "pykalman_time_update_max_diff": pykalman_time_update(geometry, params.filter, experiment_rng(params, "pykalman")),
        "speedup_vs_filterpy": speed["speedup_vs_filterpy"],
        "speedup_vs_pykalman": speed["speedup_vs_pykalman"],
        "filter_step_ms": {k: v for k, v in speed.items() if not k.startswith("speedup")},
        "paper": BLACK_RESULTS,
    }
    tables = {**tables, "sigma_sweep": noise_against_lag(no_filter, params, runs), "success": success, **success_frames,
              "sigmas_motion_a": sigmas, "small_blobs": blobs, "multi_tool": multi_tool, "replay_poses": replay}
    return Study(tables=tables, timing=timing_table(sim, params), metrics=metrics)
