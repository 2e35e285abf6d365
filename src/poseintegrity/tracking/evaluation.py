"""Section III on our simulation: frames, runs, errors, success rate, lag, sigma sweep, timing.

Every function takes its randomness from a ``numpy.random.Generator``; the per-frame tables are
bit-identical for the same seed (timings are the only non-deterministic outputs and are kept apart).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from poseintegrity.tracking.correspondence import match_brute_force, match_markers, match_voting
from poseintegrity.tracking.detection import detect_markers
from poseintegrity.tracking.frames import draw_phantoms, intrinsics, render_frame
from poseintegrity.tracking.geometry import MARKER_DIAMETER_M, pose_matrix, rotation_angle_deg, transform_points
from poseintegrity.tracking.kabsch import kabsch, pose_from_points
from poseintegrity.tracking.motion import SensorTimeline, Trajectory, sample_sensors, simulate_trajectory
from poseintegrity.tracking.params import FilterParams, TrackParams
from poseintegrity.tracking.srukf import SquareRootUKF
from poseintegrity.tracking.tracker import MarkerTracker
from poseintegrity.tracking.unscented import UnscentedMarkerFilter

# Black and Salcudean (IEEE TIM 2024), section III and Table I: the numbers ours are reported beside.
PAPER = {
    "rms_mm": {"no_filter": 3.01, "ukf": 1.77},
    "rms_deg": {"no_filter": 1.75, "ukf": 1.51},
    "success_rate": {"markers4": 0.9863, "markers3": 0.9604},
    "lag_ms": 199.5,
    "failed_downdate_share": 16 / 25000,
}


@dataclass(frozen=True)
class Simulation:
    """One simulated recording: ground truth, sensor timeline, and the detected points of every frame.

    t : (F,) s frame times; T_true : (F, 4, 4) T_world_body; points : list of (n_f, 3) detections, metres;
    in_occlusion : (F,) bool, inside a deliberate extended occlusion.
    """

    trajectory: Trajectory
    timeline: SensorTimeline
    markers_body: np.ndarray
    t: np.ndarray
    T_true: np.ndarray
    points: list[np.ndarray]
    in_occlusion: np.ndarray


def T_world_cam(params: TrackParams) -> np.ndarray:
    """Camera extrinsics (4, 4): the camera looks along world +z from params.camera.origin_m."""
    return pose_matrix(np.eye(3), np.array(params.camera.origin_m))


def simulate(params: TrackParams, rng: np.random.Generator, markers_body: np.ndarray | None = None,
             omega_std: float | None = None, duration_s: float | None = None) -> Simulation:
    """Simulate motion (II-F), render every marker frame (AHAT-like) and run the detector on it.

    markers_body : (m, 3) geometry (default params.markers_body); omega_std, duration_s override motion.
    The points of a frame come from detection on the rendered images, so their error is the detector's.
    """
    markers_body = np.array(params.markers_body) if markers_body is None else markers_body
    motion = params.motion if duration_s is None else params.motion.model_copy(update={"duration_s": duration_s})
    trajectory = simulate_trajectory(motion, rng, omega_std=omega_std)
    timeline = sample_sensors(trajectory, len(markers_body), motion, rng)
    idx = timeline.frame_index
    T_true = pose_matrix(trajectory.rotation(idx), trajectory.position[idx])
    T_wc = T_world_cam(params)
    T_cw = np.linalg.inv(T_wc)
    K = intrinsics(params.camera)
    detection = params.detection.model_dump()
    points = []
    for f in range(len(idx)):
        markers_cam = transform_points(T_cw, transform_points(T_true[f], markers_body))[~timeline.occluded[f]]
        phantoms = draw_phantoms(int(timeline.n_phantoms[f]), params.camera, params.frames, motion.phantom_round_fraction, rng)
        ir, depth_mm = render_frame(markers_cam, phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng)
        points.append(detect_markers(ir, depth_mm, K, T_world_cam=T_wc, **detection))
    t = trajectory.t[idx]
    in_occlusion = np.zeros(len(idx), dtype=bool)
    for start, duration in motion.occlusions:
        in_occlusion |= (t >= start) & (t < start + duration)
    return Simulation(trajectory, timeline, markers_body, t, T_true, points, in_occlusion)


def pose_errors(T_est: np.ndarray, T_true: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position error (k,) mm and rotation error (k,) deg (geodesic) of poses (k, 4, 4); NaN where T_est is NaN."""
    pos = np.linalg.norm(T_est[:, :3, 3] - T_true[:, :3, 3], axis=1) * 1000.0
    rot = rotation_angle_deg(np.nan_to_num(T_est[:, :3, :3]), T_true[:, :3, :3])
    return pos, np.where(np.isnan(pos), np.nan, rot)


def run_no_filter(sim: Simulation, params: TrackParams) -> pd.DataFrame:
    """Kabsch per frame on the matched detections (no filter, no prediction): one row per frame.

    correct: at least min_markers markers matched and every matched point within correct_tolerance_m of
    its true marker (correspondence right and pose usable).
    """
    m, rows = params.matching, []
    for f, points in enumerate(sim.points):
        assignment = match_markers(points, sim.markers_body, None, tolerance_m=m.tolerance_m, gate_m=m.gate_m, min_markers=m.min_markers)
        matched = assignment >= 0
        true_markers = transform_points(sim.T_true[f], sim.markers_body)
        T = pose_from_points(points[assignment[matched]], sim.markers_body[matched]) if matched.sum() >= 3 else np.full((4, 4), np.nan)
        err = np.linalg.norm(points[assignment[matched]] - true_markers[matched], axis=1) if matched.any() else np.zeros(0)
        correct = matched.sum() >= m.min_markers and bool(np.all(err <= params.evaluation.correct_tolerance_m))
        rows.append({"frame": f, "t": sim.t[f], "n_detected": len(points), "n_matched": int(matched.sum()), "correct": correct, "T": T})
    df = pd.DataFrame(rows)
    poses = np.stack(df.pop("T").to_list())
    df["pos_err_mm"], df["rot_err_deg"] = pose_errors(poses, sim.T_true)
    df[["x_mm", "y_mm", "z_mm"]] = poses[:, :3, 3] * 1000.0
    df["in_occlusion"] = sim.in_occlusion
    return df


def run_filter(
    sim: Simulation,
    params: TrackParams,
    use_gyro: bool,
    filter_params: FilterParams | None = None,
    filter_cls: type[UnscentedMarkerFilter] = SquareRootUKF,
) -> tuple[pd.DataFrame, MarkerTracker]:
    """Run the tracker over the recording: one row per event (marker frame or gyro sample), in time order.

    Columns: t, kind ("frame"/"gyro"), frame (index or -1), flag, n_matched, pos_err_mm, rot_err_deg,
    x_mm / y_mm / z_mm (filtered position of the body origin), in_occlusion.
    """
    tracker = MarkerTracker(sim.markers_body, filter_params or params.filter, params.matching, use_gyro, filter_cls)
    tl, traj = sim.timeline, sim.trajectory
    events = sorted([(i, 1, g) for g, i in enumerate(tl.gyro_index)] + [(i, 0, f) for f, i in enumerate(tl.frame_index)])
    occlusion_t = [(s, s + d) for s, d in params.motion.occlusions]
    rows, poses, truth = [], [], []
    for grid_index, is_gyro, k in events:
        t = traj.t[grid_index]
        if is_gyro:
            flag, n_matched, T = tracker.gyro(t, tl.gyro[k]), -1, tracker.pose()
        else:
            result = tracker.frame(t, sim.points[k])
            flag, n_matched, T = result.flag, int((result.assignment >= 0).sum()), result.T_filtered
        rows.append({"t": t, "kind": "gyro" if is_gyro else "frame", "frame": -1 if is_gyro else k, "flag": flag, "n_matched": n_matched,
                     "in_occlusion": any(a <= t < b for a, b in occlusion_t)})
        poses.append(T)
        truth.append(pose_matrix(traj.rotation(np.array([grid_index]))[0], traj.position[grid_index]))
    df = pd.DataFrame(rows)
    poses = np.stack(poses)
    df["pos_err_mm"], df["rot_err_deg"] = pose_errors(poses, np.stack(truth))
    df[["x_mm", "y_mm", "z_mm"]] = poses[:, :3, 3] * 1000.0
    return df, tracker


def rms(values: np.ndarray) -> float:
    """Root mean square over the finite values (NaN if none)."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    return float(np.sqrt(np.mean(values**2))) if values.size else float("nan")


def normalized_lag_ms(t_ref: np.ndarray, ref: np.ndarray, t_sig: np.ndarray, sig: np.ndarray, lag_max_ms: float) -> float:
    """Delay (ms) of sig behind ref: the lag maximising their normalized cross-correlation (section II-F).

    Both signals (k,) are resampled on a common 1 ms grid (linear interpolation over their finite samples);
    lags 0..lag_max_ms are searched.
    """
    ok_r, ok_s = np.isfinite(ref), np.isfinite(sig)
    start, stop = max(t_ref[ok_r][0], t_sig[ok_s][0]), min(t_ref[ok_r][-1], t_sig[ok_s][-1])
    grid = np.arange(start, stop, 0.001)
    a = np.interp(grid, t_ref[ok_r], ref[ok_r])
    b = np.interp(grid, t_sig[ok_s], sig[ok_s])
    best, best_ncc = 0, -np.inf
    for lag in range(0, min(int(lag_max_ms), len(grid) // 2)):
        x, y = a[: len(a) - lag], b[lag:]
        x, y = x - x.mean(), y - y.mean()
        ncc = (x @ y) / np.sqrt((x @ x) * (y @ y))
        if ncc > best_ncc:
            best, best_ncc = lag, ncc
    return float(best)


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


def success_rate(params: TrackParams, rng: np.random.Generator, markers_body: np.ndarray) -> tuple[float, pd.DataFrame]:
    """Share of ``evaluation.success_frames`` frames of large motion with a correct pose (section III).

    Large motion: angular velocity spread evaluation.success_omega_std (full turns about every axis);
    random occlusions (P_o) and phantoms (P_p) as in the params, no deliberate extended occlusion.
    Returns (share, per-frame table of :func:`run_no_filter`).
    """
    duration = params.evaluation.success_frames * params.motion.frame_interval_s * 1.2 + 1.0
    no_deliberate = params.model_copy(update={"motion": params.motion.model_copy(update={"occlusions": []})})
    sim = simulate(no_deliberate, rng, markers_body=markers_body, omega_std=params.evaluation.success_omega_std, duration_s=duration)
    df = run_no_filter(sim, params).iloc[: params.evaluation.success_frames]
    return float(df.correct.mean()), df


def accuracy_frames(no_filter: pd.DataFrame) -> np.ndarray:
    """Frames on which accuracy is compared: correct unfiltered pose, outside deliberate occlusions."""
    return no_filter.frame[no_filter.correct & ~no_filter.in_occlusion].to_numpy()


def summarize_accuracy(no_filter: pd.DataFrame, runs: dict[str, pd.DataFrame]) -> dict[str, dict[str, float]]:
    """RMS position (mm) and rotation (deg) error of the no-filter poses and of every filter run,
    on the frames of :func:`accuracy_frames` (the filter rows of those marker frames)."""
    frames = accuracy_frames(no_filter)
    rms_mm = {"no_filter": rms(no_filter.pos_err_mm[frames])}
    rms_deg = {"no_filter": rms(no_filter.rot_err_deg[frames])}
    for name, df in runs.items():
        rows = df[(df.kind == "frame") & df.frame.isin(frames)]
        rms_mm[name], rms_deg[name] = rms(rows.pos_err_mm), rms(rows.rot_err_deg)
    return {"rms_mm": rms_mm, "rms_deg": rms_deg}


def occlusion_summary(runs: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """Orientation held through the deliberate occlusions (Fig. 8): per run, the RMS rotation error inside
    the occlusion windows and the share of their events with a running filter."""
    rows = []
    for name, df in runs.items():
        inside = df[df.in_occlusion]
        share = float(np.isfinite(inside.rot_err_deg).mean()) if len(inside) else float("nan")
        rows.append({"run": name, "rms_deg": rms(inside.rot_err_deg), "share_tracked": share})
    return pd.DataFrame(rows)


def sigma_sweep(sim: Simulation, params: TrackParams, no_filter: pd.DataFrame) -> pd.DataFrame:
    """Noise-vs-lag trade-off (Figs. 6, 9): sigma_c and sigma_alpha scaled by evaluation.sigma_scales.

    One row per scale: RMS position (mm) and rotation (deg) error and lag (ms) of the UKF without gyro.
    """
    rows, frames = [], accuracy_frames(no_filter)
    for scale in params.evaluation.sigma_scales:
        fp = params.filter.model_copy(update={"sigma_c": params.filter.sigma_c * scale, "sigma_alpha": params.filter.sigma_alpha * scale})
        df, _ = run_filter(sim, params, use_gyro=False, filter_params=fp)
        at_frames = df[(df.kind == "frame") & df.frame.isin(frames)]
        rows.append({"scale": scale, "rms_mm": rms(at_frames.pos_err_mm), "rms_deg": rms(at_frames.rot_err_deg),
                     "lag_ms": filter_lag_ms(no_filter, df, params.evaluation.lag_max_ms)})
    return pd.DataFrame(rows)


def filter_agreement(sim: Simulation, params: TrackParams, alpha: float, other_cls: type[UnscentedMarkerFilter]) -> float:
    """Largest relative difference of the filtered positions of the SR-UKF and another filter class on the
    same recording (gyro fused) at the given alpha: max |x_sr - x_other| / max |x_other|."""
    fp = params.filter.model_copy(update={"alpha": alpha})
    a, _ = run_filter(sim, params, use_gyro=True, filter_params=fp)
    b, _ = run_filter(sim, params, use_gyro=True, filter_params=fp, filter_cls=other_cls)
    xa, xb = a[["x_mm", "y_mm", "z_mm"]].to_numpy(), b[["x_mm", "y_mm", "z_mm"]].to_numpy()
    both = np.isfinite(xa).all(axis=1) & np.isfinite(xb).all(axis=1)
    return float(np.abs(xa[both] - xb[both]).max() / np.abs(xb[both]).max())


def _mean_time_ms(fn, repeats: int) -> float:
    start = time.perf_counter()
    for _ in range(repeats):
        fn()
    return (time.perf_counter() - start) / repeats * 1000.0


def filterpy_filter(markers_body: np.ndarray, fp: FilterParams):
    """filterpy's UnscentedKalmanFilter on the same model: eq. 10 per sigma point with the SVD Kabsch of
    Alg. 4, P_proc of eq. 30 set before every predict, all markers and the gyro measured.

    Returns (ukf, step) where step(z, dt) runs one predict + update.
    """
    from filterpy.kalman import MerweScaledSigmaPoints
    from filterpy.kalman import UnscentedKalmanFilter as FilterpyUKF

    from poseintegrity.tracking.model import centred, process_model_reference, process_noise_sqrt, state_dim

    n = len(markers_body)
    N = state_dim(n)
    kappa = 3.0 - N if fp.kappa is None else fp.kappa
    points = MerweScaledSigmaPoints(N, fp.alpha, fp.beta, kappa)
    ukf = FilterpyUKF(N, 3 * n + 3, fp.dt, lambda x: x[: 3 * n + 3], lambda x, dt: process_model_reference(x, dt, markers_body), points)
    ukf.R = np.diag(np.r_[np.full(3 * n, fp.sigma_r**2), np.full(3, fp.sigma_omega**2)])
    ell = centred(markers_body)

    def step(z: np.ndarray, dt: float) -> None:
        B = process_noise_sqrt(ukf.x, dt, ell, fp.sigma_c, fp.sigma_alpha)
        ukf.Q = B @ B.T
        ukf.predict(dt=dt)
        ukf.update(z)

    return ukf, step


def filter_speed(markers_body: np.ndarray, fp: FilterParams, repeats: int, rng: np.random.Generator) -> dict[str, float]:
    """Mean time (ms) of one predict + update (all markers + gyro) of the SR-UKF, the plain UKF and
    filterpy on the same model, measured in the same run, and the SR-UKF's speed-up over filterpy."""
    from poseintegrity.tracking.ukf import UnscentedKalmanFilter

    n = len(markers_body)
    markers = markers_body + np.array([0.0, 0.0, 0.45])
    z = np.r_[(markers + rng.normal(0, 0.001, markers.shape)).ravel(), rng.normal(0, 0.5, 3)]
    observed = np.ones(n, dtype=bool)
    times = {}
    for name, cls in [("srukf", SquareRootUKF), ("ukf", UnscentedKalmanFilter)]:
        f = cls(markers_body, fp)
        f.initialize(markers)
        f.predict(fp.dt)  # warm-up (numba compilation)
        times[name] = _mean_time_ms(lambda f=f: (f.predict(fp.dt), f.update(z, observed, True)), repeats)
    ukf, step = filterpy_filter(markers_body, fp)
    ukf.x = np.r_[markers.ravel(), np.zeros(6)]
    ukf.P = np.diag(np.r_[np.full(3 * n, fp.sigma_r**2), np.full(3, fp.init_std_omega**2), np.full(3, fp.init_std_velocity**2)])
    times["filterpy"] = _mean_time_ms(lambda: step(z, fp.dt), max(repeats // 5, 1))
    times["speedup_vs_filterpy"] = times["filterpy"] / times["srukf"]
    return times


def detect_match_kabsch(ir: np.ndarray, depth_mm: np.ndarray, K: np.ndarray, params: TrackParams, geometry: np.ndarray) -> np.ndarray:
    """The no-filter chain on one frame: detection, correspondence, Kabsch.  Returns T_world_body (4, 4),
    NaN if fewer than 3 markers were matched."""
    points = detect_markers(ir, depth_mm, K, **params.detection.model_dump())
    assignment = match_markers(points, geometry, tolerance_m=params.matching.tolerance_m, min_markers=params.matching.min_markers)
    matched = assignment >= 0
    if matched.sum() < 3:
        return np.full((4, 4), np.nan)
    return pose_from_points(points[assignment[matched]], geometry[matched])


def timing_table(sim: Simulation, params: TrackParams, rng: np.random.Generator) -> pd.DataFrame:
    """Mean time (ms) of the subroutines, like Table I, on one frame of the recording with a round phantom."""
    K = intrinsics(params.camera)
    T_cw = np.linalg.inv(T_world_cam(params))
    geometry = sim.markers_body
    markers_cam = transform_points(T_cw, transform_points(sim.T_true[0], geometry))
    phantoms = draw_phantoms(1, params.camera, params.frames, 1.0, rng)
    ir, depth_mm = render_frame(markers_cam, phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng)
    points = detect_markers(ir, depth_mm, K, **params.detection.model_dump())
    tol, repeats = params.matching.tolerance_m, params.evaluation.timing_repeats
    tracker = MarkerTracker(geometry, params.filter, params.matching)
    tracker.frame(0.0, points)
    filt = tracker.filter
    z = filt.markers().ravel()
    observed = np.ones(len(geometry), dtype=bool)
    rows = {
        "Frame synthesis (ours)": lambda: render_frame(markers_cam, phantoms, params.camera, params.frames, MARKER_DIAMETER_M / 2, rng),
        "Contour detection": lambda: detect_markers(ir, depth_mm, K, **params.detection.model_dump()),
        "Euclidean matching": lambda: match_voting(points, geometry, tolerance_m=tol),
        "Brute force matching": lambda: match_brute_force(points, geometry, tolerance_m=tol),
        "Kabsch algorithm": lambda: kabsch(z.reshape(-1, 3), geometry),
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


def run_study(params: TrackParams) -> Study:
    """Section III on our simulation, all randomness from ``numpy.random.default_rng(params.seed)``.

    Runs: no filter, UKF, UKF + gyro (and the UKF with the paper's sigmas) on one recording with a
    deliberate extended occlusion; success rate on large-motion recordings with 4 and with 3 markers;
    lag by normalized cross-correlation and the sigma sweep; SR-UKF vs plain UKF agreement at alpha 1 and
    at params.filter.alpha; failed downdates; timings and the speed-up over filterpy.
    """
    from poseintegrity.tracking.ukf import UnscentedKalmanFilter

    rng = np.random.default_rng(params.seed)
    geometry = np.array(params.markers_body)
    sim = simulate(params, rng)
    no_filter = run_no_filter(sim, params)
    ukf, t_ukf = run_filter(sim, params, use_gyro=False)
    ukf_gyro, t_gyro = run_filter(sim, params, use_gyro=True)
    paper_sigmas = FilterParams(alpha=params.filter.alpha, dt=params.filter.dt, restart_after_s=params.filter.restart_after_s)
    ukf_paper, t_paper = run_filter(sim, params, use_gyro=False, filter_params=paper_sigmas)
    runs = {"ukf": ukf, "ukf_gyro": ukf_gyro, "ukf_paper_sigmas": ukf_paper}
    accuracy = summarize_accuracy(no_filter, runs)
    occlusion = occlusion_summary({"ukf": ukf, "ukf_gyro": ukf_gyro})
    sweep = sigma_sweep(sim, params, no_filter)
    rate4, success4 = success_rate(params, rng, geometry)
    rate3, success3 = success_rate(params, rng, np.delete(geometry, params.drop_marker, axis=0))
    lag = {name: filter_lag_ms(no_filter, df, params.evaluation.lag_max_ms) for name, df in runs.items()}
    agreement = {f"alpha_{a:g}": filter_agreement(sim, params, a, UnscentedKalmanFilter) for a in (1.0, params.filter.alpha)}
    trackers = {"ukf": t_ukf, "ukf_gyro": t_gyro, "ukf_paper_sigmas": t_paper}
    n_updates = {name: int((df.flag == "ok").sum()) for name, df in runs.items()}
    speed = filter_speed(geometry, params.filter, params.evaluation.timing_repeats, rng)
    timing = timing_table(sim, params, rng)
    metrics = {
        **accuracy,
        "success_rate": {"markers4": rate4, "markers3": rate3},
        "lag_ms": lag["ukf"],
        "lag_ms_all": lag,
        "failed_downdates": int(sum(t.filter.failed_downdates for t in trackers.values())),
        "filter_steps": n_updates,
        "divergences": {name: t.filter.n_divergences for name, t in trackers.items()},
        "restarts": {name: t.n_restarts for name, t in trackers.items()},
        "occlusion_rms_deg": dict(zip(occlusion.run, occlusion.rms_deg)),
        "occlusion_share_tracked": dict(zip(occlusion.run, occlusion.share_tracked)),
        "srukf_vs_ukf_max_rel_diff": agreement,
        "speedup_vs_filterpy": speed["speedup_vs_filterpy"],
        "filter_step_ms": {k: v for k, v in speed.items() if k != "speedup_vs_filterpy"},
        "n_frames": int(len(sim.t)),
        "paper": PAPER,
    }
    tables = {
        "no_filter": no_filter,
        "ukf": ukf,
        "ukf_gyro": ukf_gyro,
        "ukf_paper_sigmas": ukf_paper,
        "sigma_sweep": sweep,
        "success_markers4": success4,
        "success_markers3": success3,
        "occlusion": occlusion,
    }
    return Study(tables=tables, timing=timing, metrics=metrics)
