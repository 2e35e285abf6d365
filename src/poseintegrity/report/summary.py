"""``reports/summary.md``: every stage's headline figures beside the papers' numbers.

Each stage writes ``reports/metrics/<stage>.json``; :data:`HEADLINES` says which keys are headline figures,
what the papers reported for them (``../shared/papers/README.md``) and the project's target where there is one.
A stage that has not run yet shows "not run" rather than a stale or invented number.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Headline:
    """One row: ``key`` is a dotted path into ``metrics/<stage>.json``."""

    stage: str
    key: str
    label: str
    paper: str = "-"
    target: str = "-"


SECTIONS = {
    "generate": "Stage 01 · rendered robot datasets (Windsor et al. IV-D)",
    "artifacts": "Stage 02 · artifact extraction and the realism of the rendered world (Windsor et al. III-B, IV-C)",
    "pnp": "Stage 05 · PnP variants (Windsor et al. V-A, Fig. 6)",
    "fits": "Stage 03 · artifact models, mean RMSE over the whole dataset from the first 4 stops (Fig. 2)",
    "predictors": "Stage 04 · localization-envelope predictors (Windsor et al. V, Tables I-III)",
    "tracking": "Stage 06 · marker tracking (Black & Salcudean, section III)",
}

HEADLINES: list[Headline] = [
    Headline("generate", "n_viewing_angle_datasets", "viewing-angle datasets", "21 (7 scenes x 3 azimuths)"),
    Headline("generate", "n_straight_line_datasets", "straight-line datasets", "4"),
    Headline("generate", "n_images", "images (incl. model pairs)", "~4 850"),
    Headline("generate", "image_width_px", "image width (px)", "1936 (full sensor)"),
    Headline("generate", "focal_px", "focal length (px)", "not published"),
    Headline("generate", "clahe_keypoint_gain_bone", "SIFT keypoints on bone targets, CLAHE / raw",
             "CLAHE used 'to improve feature detection on low texture bone phantoms'"),
    Headline("generate", "disk_gb", "disk (GB)", "-", "<= 3"),
    Headline("generate", "wall_time_s", "stage wall time (s, n_jobs 2)", "-", "<= 480"),
    Headline("fits", "rmse_k4.emg", "EMG (eq. 1)", "lowest of the least-squares fits"),
    Headline("fits", "rmse_k4.exponential", "exponential"),
    Headline("fits", "rmse_k4.gaussian", "Gaussian"),
    Headline("fits", "rmse_k4.logistic", "logistic"),
    Headline("fits", "rmse_k4.power_law", "power law"),
    Headline("fits", "rmse_k4.mlp_scratch", "MLP, samples only", "'very high RMSE'"),
    Headline("fits", "rmse_k4.mlp_pretrained", "MLP, EMG-pretrained + fine-tuned", "competitive with least squares"),
    Headline("fits", "converged.emg", "share of EMG fits that converged", "-", ">= 0.99"),
    Headline("predictors", "long_range.2mm_3deg.max_mean_spl_zero_incursion",
             "long range, 2 mm/3 deg: max mean SPL at zero incursion (deg)", "12.9"),
    Headline("predictors", "mlp.2mm_3deg.max_mean_spl_zero_incursion", "MLP, 2 mm/3 deg (deg)",
             "12.0 (long range is +7.4 %)"),
    Headline("predictors", "static.2mm_3deg.max_mean_spl_zero_incursion", "static baseline, 2 mm/3 deg (deg)", "7.0"),
    Headline("predictors", "next_step.2mm_3deg.max_mean_spl_zero_incursion", "next step, 2 mm/3 deg (deg)", "14.2"),
    Headline("predictors", "long_range.2mm_3deg.best_n_t", "long range, 2 mm/3 deg: threshold n_t", "23"),
    Headline("predictors", "long_range.4mm_10deg.best_n_t", "long range, 4 mm/10 deg: threshold n_t", "28"),
    Headline("predictors", "next_step.2mm_3deg.best_n_t", "next step, 2 mm/3 deg: threshold n_t", "12"),
    Headline("predictors", "next_step.4mm_10deg.best_n_t", "next step, 4 mm/10 deg: threshold n_t", "15"),
    Headline("predictors", "long_range.4mm_10deg.max_mean_spl_zero_incursion",
             "long range, 4 mm/10 deg: max mean SPL at zero incursion (deg)"),
    Headline("predictors", "static.4mm_10deg.max_mean_spl_zero_incursion", "static baseline, 4 mm/10 deg (deg)"),
    Headline("predictors", "straight_line.relative_improvement", "straight lines: long range over static",
             "+46.2 %"),
    Headline("tracking", "rms_mm.no_filter", "RMS position error, no filter (mm)", "3.01"),
    Headline("tracking", "rms_mm.ukf", "RMS position error, UKF (mm)", "1.77"),
    Headline("tracking", "rms_mm.ukf_gyro", "RMS position error, UKF + gyro (mm)"),
    Headline("tracking", "rms_deg.no_filter", "RMS rotation error, no filter (deg)", "1.75"),
    Headline("tracking", "rms_deg.ukf", "RMS rotation error, UKF (deg)", "1.51"),
    Headline("tracking", "rms_deg.ukf_gyro", "RMS rotation error, UKF + gyro (deg)"),
    Headline("tracking", "success_rate.markers4", "correct pose, 4 markers", "98.63 %"),
    Headline("tracking", "success_rate.markers3", "correct pose, 3 markers", "96.04 %"),
    Headline("tracking", "lag_ms", "lag of the filtered signal (ms)", "199.5"),
    Headline("tracking", "failed_downdates", "failed Cholesky downdates", "16 in 25 000 (0.06 %)"),
    Headline("tracking", "speedup_vs_filterpy", "SR-UKF step speed-up over filterpy", "-", ">= 10"),
]


def read_metrics(metrics_dir: Path) -> dict[str, dict]:
    """All ``<stage>.json`` files of ``metrics_dir`` by stage name."""
    return {p.stem: json.loads(p.read_text()) for p in sorted(Path(metrics_dir).glob("*.json"))}


def lookup(metrics: dict[str, dict], stage: str, key: str):
    """The value at dotted ``key`` of a stage's metrics, or None when the stage or key is missing."""
    value = metrics.get(stage)
    for part in key.split("."):
        if not isinstance(value, dict) or part not in value:
            return None
        value = value[part]
    return value


def _fmt(value) -> str:
    if value is None:
        return "not run"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def render_summary(metrics: dict[str, dict]) -> str:
    """Markdown: one table per stage, ours beside the paper's and the target."""
    lines = ["# Summary of the latest run", "",
             "Generated by stage 07 from `reports/metrics/*.json`. Paper figures: Windsor et al. (RA-L 2024) and",
             "Black & Salcudean (2023), see `../shared/papers/README.md`.", ""]
    for stage, title in SECTIONS.items():
        lines += [f"## {title}", "", "| figure | ours | paper | target |", "| --- | --- | --- | --- |"]
        for h in (h for h in HEADLINES if h.stage == stage):
            lines.append(f"| {h.label} | {_fmt(lookup(metrics, stage, h.key))} | {h.paper} | {h.target} |")
        lines.append("")
    return "\n".join(lines)
