"""Per-method and ground-truth summaries of a stage-02/05 artifacts table (``artifacts.json``, ``pnp.json``)."""

from __future__ import annotations

import pandas as pd


def method_summary(table: pd.DataFrame, envelope_table: pd.DataFrame) -> pd.DataFrame:
    """One row per PnP method: frames, failure rate, n_i at the first stop, median errors, mean theta_a per
    tolerance and trajectory type, and how many envelopes are censored (stage 05, paper Fig. 6)."""
    first_stop = table[table["stop"] == 0]
    summary = table.groupby("method").agg(
        n_frames=("status", "size"),
        failure_rate=("status", lambda status: float((status != "ok").mean())),
        median_n_inliers=("n_inliers", "median"),
        median_E_t_mm=("E_t_mm", "median"),
        median_E_r_deg=("E_r_deg", "median"),
    )
    summary["mean_n_inliers_first_stop"] = first_stop.groupby("method")["n_inliers"].mean()
    theta_a = envelope_table.pivot_table(
        index="method", columns=["trajectory", "tolerance"], values="theta_a", aggfunc="mean"
    )
    theta_a.columns = [f"mean_theta_a_{trajectory}_{tolerance}" for trajectory, tolerance in theta_a.columns]
    censored = envelope_table.groupby("method")["censored"].sum().rename("n_censored")
    return summary.join(theta_a).join(censored).reset_index()


def board_summary(table: pd.DataFrame) -> dict[str, float]:
    """How far the ArUco ground truth is from the exact renderer pose (one row per frame is enough)."""
    frames = table.drop_duplicates(["dataset", "stop", "image"])
    detected = frames[frames["board_status"] == "ok"]
    return dict(
        detection_rate=float(len(detected) / len(frames)) if len(frames) else float("nan"),
        median_E_t_mm=float(detected["E_t_board_exact_mm"].median()),
        p95_E_t_mm=float(detected["E_t_board_exact_mm"].quantile(0.95)),
        median_E_r_deg=float(detected["E_r_board_exact_deg"].median()),
        p95_E_r_deg=float(detected["E_r_board_exact_deg"].quantile(0.95)),
    )
