"""The rows of ``tracking.json`` (stage 06, Black & Salcudean, IEEE TIM 2024, section III): RMS position (mm) and
orientation (deg) errors without and with the UKF, the share of frames with the correct pose per motion and marker
removal, the runs at the paper's pace, the lag (ms) and the robustness checks."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.sections import Headline

BLACK = paper.BLACK_RESULTS  # Black and Salcudean, section III


def _removal_rows() -> list[Headline]:
    """The 3-marker rate on motion (a) with each of the four markers removed and their mean (the claim's figure: the
    paper does not say which it removed), each with its interval over 5-s blocks."""
    removals = {"a_markers3_drop1": "m1", "a_markers3": "m2 (track.drop_marker)", "a_markers3_drop3": "m3",
                "a_markers3_drop4": "m4", "a_markers3_mean": "mean of the four removals"}
    rows = []
    for key, name in removals.items():
        rows += [Headline("tracking", f"success_rates.{key}", f"correct pose, 3 markers, motion (a), {name} removed"
                          if "mean" not in name else f"correct pose, 3 markers, motion (a), {name}",
                          f"{BLACK['success_rate']['markers3']:.2%}" if "mean" in name else "-", fmt="{:.2%}"),
                 Headline("tracking", f"intervals.success_rates.{key}", "... its 90 % interval", fmt="{:.2%}")]
    return rows


def _pace_rows() -> list[Headline]:
    """Motion (c), at the pace the paper's lag and errors imply (tracking.json ``paper_pace``): the truth's rates, and
    per run the paper's two errors with their intervals, the position's lag and the orientation's."""
    at = "paper_pace"
    rows = [Headline("tracking", f"{at}.pace.euler_rad_s.mean", "motion (c), the paper's pace: the truth's RMS Euler "
                     "rate, mean of the three angles (rad/s)", "0.132 (1.51 deg / 199.5 ms)"),
            Headline("tracking", f"{at}.pace.velocity_mm_s.mean", "... its RMS velocity, mean of the three axes (mm/s)",
                     "8.87 (1.77 mm / 199.5 ms)")]
    for run, name, theirs in (("published", "published sigmas", True), ("ours", "our sigmas", False),
                              ("no_filter", "no filter", False)):
        rows += [Headline("tracking", f"{at}.{run}.axis_mm", f"motion (c), {name}: RMS position error per axis (mm)",
                          f"{BLACK['rms_mm']['ukf']:g}" if theirs else "-"),
                 Headline("tracking", f"{at}.{run}.intervals.axis_mm", "... its 90 % interval (mm)"),
                 Headline("tracking", f"{at}.{run}.euler_deg", "... RMS Euler-angle error (deg)",
                          f"{BLACK['rms_deg']['ukf']:g}" if theirs else "-"),
                 Headline("tracking", f"{at}.{run}.intervals.euler_deg", "... its 90 % interval (deg)")]
        if run != "no_filter":
            rows += [Headline("tracking", f"{at}.{run}.lag_ms", "... lag of the position behind the no-filter chain "
                              "(ms)", f"{BLACK['lag_ms']:g}" if theirs else "-"),
                     Headline("tracking", f"{at}.{run}.euler_lag_ms", "... lag of the orientation (ms)")]
    return rows


TRACKING_ROWS: list[Headline] = [
    Headline("tracking", "rms_axis_mm.no_filter", "RMS position error per axis, no filter (mm; paper's metric)",
             f"{BLACK['rms_mm']['no_filter']:g}"),
    Headline("tracking", "rms_axis_mm.ukf", "RMS position error per axis, UKF (mm; paper's metric)",
             f"{BLACK['rms_mm']['ukf']:g}"),
    Headline("tracking", "rms_axis_mm.ukf_gyro", "RMS position error per axis, UKF + gyro (mm; paper's metric)"),
    Headline("tracking", "rms_euler_deg.no_filter", "RMS Euler-angle error, no filter (deg; paper's metric, Unity YXZ)",
             f"{BLACK['rms_deg']['no_filter']:g}"),
    Headline("tracking", "rms_euler_deg.ukf", "RMS Euler-angle error, UKF (deg; paper's metric, Unity YXZ)",
             f"{BLACK['rms_deg']['ukf']:g}"),
    Headline("tracking", "rms_euler_deg.ukf_gyro", "RMS Euler-angle error, UKF + gyro (deg; paper's metric, Unity YXZ)"),
    Headline("tracking", "rms_mm.no_filter", "RMS position error norm, no filter (mm; ours)"),
    Headline("tracking", "rms_mm.ukf", "RMS position error norm, UKF (mm; ours)"),
    Headline("tracking", "rms_mm.ukf_gyro", "RMS position error norm, UKF + gyro (mm; ours)"),
    Headline("tracking", "rms_deg.no_filter", "RMS geodesic rotation error, no filter (deg; ours)"),
    Headline("tracking", "rms_deg.ukf", "RMS geodesic rotation error, UKF (deg; ours)"),
    Headline("tracking", "rms_deg.ukf_gyro", "RMS geodesic rotation error, UKF + gyro (deg; ours)"),
    Headline("tracking", "success_rates.a_markers4", "correct pose, 4 markers, motion (a) paper-like",
             f"{BLACK['success_rate']['markers4']:.2%}", fmt="{:.2%}"),
    *_removal_rows(),
    *_pace_rows(),
    Headline("tracking", "success_rates.b_markers4", "correct pose, 4 markers, motion (b) stress test", fmt="{:.2%}"),
    Headline("tracking", "success_rates.b_markers3", "correct pose, 3 markers, motion (b) stress test", fmt="{:.2%}"),
    Headline("tracking", "success_rates.b_markers4_no_split", "correct pose, 4 markers, motion (b), touching blobs not split", fmt="{:.2%}"),
    Headline("tracking", "lag_ms.ukf", "lag of the filtered signal, our sigmas (ms)", f"{BLACK['lag_ms']:g}"),
    Headline("tracking", "sigmas_motion_a.published.lag_ms", "lag on motion (a), published sigmas (ms)",
             f"{BLACK['lag_ms']:g}"),
    Headline("tracking", "sigmas_motion_a.published.axis_mm",
             "RMS position error per axis on motion (a), published sigmas (mm)", f"{BLACK['rms_mm']['ukf']:g}"),
    Headline("tracking", "sigmas_motion_a.ours.axis_mm", "RMS position error per axis on motion (a), our sigmas (mm)"),
    Headline("tracking", "small_blobs.marker_keep_rate.pixel", "small blobs (0.4-0.9 m, f 250 px) kept, pixel shape measure", "-", ">= 0.99"),
    Headline("tracking", "small_blobs.marker_keep_rate.contour", "small blobs kept, published contour shape measure"),
    Headline("tracking", "ten_metre_jump.ok_while_off", "frames reported ok while > 0.1 m off after a 10 m jump", "-", "0"),
    Headline("tracking", "failed_downdates", "failed Cholesky downdates",
             f"16 in 25 000 ({BLACK['failed_downdate_share']:.2%})"),
]
