"""Per-method and ground-truth summaries of a stage-02/05 artifacts table (``artifacts.json``, ``pnp.json``)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.localization.pnp import FAILURES

FAILURE_STATUSES = ("no_keypoints", *FAILURES)  # no_keypoints: SIFT found nothing in the frame (frame_rows.localize)


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


def envelope_rule_summary(envelope_table: pd.DataFrame, table: pd.DataFrame, method: str) -> pd.DataFrame:
    """How the failed-frame rules of theta_a (localization/envelope.py) differ: per world, rule, trajectory and
    tolerance, for ``method``: datasets, censored ones, the smallest and mean theta_a, mean / smallest, and the
    share of the uncensored envelopes that end within 0.01 (deg or mm) of a stop (a rule that snaps to stops).

    table : the artifact rows the envelopes came from (their stop positions)
    """
    rows = table[table["method"] == method]
    positions = (rows.assign(position=rows["theta_deg"].where(rows["trajectory"] == "arc", rows["x_mm"]))
                 .groupby("dataset")["position"].unique())
    out = []
    keys = ["world", "rule", "trajectory", "tolerance"]
    for (world, rule, trajectory, tolerance), group in envelope_table[envelope_table["method"] == method].groupby(keys):
        uncensored = group[~group["censored"]]
        on_stop = [float(np.min(np.abs(positions[d] - a))) <= 0.01 for d, a in zip(uncensored["dataset"],
                                                                                   uncensored["theta_a"])]
        out.append(dict(world=world, rule=rule, trajectory=trajectory, tolerance=tolerance, n=len(group),
                        n_censored=int(group["censored"].sum()), min_theta_a=float(group["theta_a"].min()),
                        mean_theta_a=float(group["theta_a"].mean()),
                        mean_over_min=float(group["theta_a"].mean() / group["theta_a"].min())
                        if group["theta_a"].min() > 0 else np.nan,
                        share_on_stop=float(np.mean(on_stop)) if on_stop else np.nan))
    return pd.DataFrame(out)


def dataset_summary(table: pd.DataFrame, envelope_table: pd.DataFrame, method: str) -> pd.DataFrame:
    """What was measured on each dataset, for ``method`` (the paper's PnP path): world, trajectory, frames, stops,
    the last stop's position (deg for arcs, mm for lines), the share of frames localized (status ok), the share of
    frames whose ground truth judges them (``trusted_share``: a trusted board pose, or a recorded pose), the fewest
    board points (ChArUco corners, or marker corners of a grid) of the pose at any stop (``min_corners_in_view``: the
    median over the stop's images; 0 where the board was not found; NaN with pose ground truth), the mean n_i at the
    first stop, and per tolerance theta_a (deg or mm) and whether it is censored (the envelope reaches the end of the
    range, IV-E). ``table``: usable rows (the data flags left out); ``envelope_table``: one rule's rows
    (:func:`poseintegrity.localization.envelope.headline`). One row per dataset, by world and name."""
    rows = table[table["method"] == method]
    rows = rows.assign(position=rows["theta_deg"].where(rows["trajectory"] == "arc", rows["x_mm"]))
    first = rows[rows["stop"] == rows.groupby("dataset")["stop"].transform("min")]
    keys = ["world", "trajectory", "dataset"]
    summary = rows.groupby(keys).agg(
        n_frames=("status", "size"), n_stops=("stop", "nunique"), last_stop=("position", "max"),
        localized_share=("status", lambda status: float((status == "ok").mean())),
        trusted_share=("board_status", lambda status: float(status.isin(["ok", "no_board"]).mean())))
    board = rows[rows["board_status"] != "no_board"]
    summary["min_corners_in_view"] = (board.groupby([*keys, "stop"])["board_n_points"].median()
                                      .groupby(level=keys).min()).astype(float)
    summary["first_stop_mean_n_inliers"] = first.groupby(keys)["n_inliers"].mean()
    envelopes = envelope_table[envelope_table["method"] == method]
    for column in ("theta_a", "censored"):
        wide = envelopes.pivot_table(index=["world", "trajectory", "dataset"], columns="tolerance", values=column,
                                     aggfunc="first")
        summary = summary.join(wide.rename(columns=lambda tolerance: f"{column}_{tolerance}"))
    return summary.reset_index().sort_values(["world", "dataset"], ignore_index=True)


def failure_shares(table: pd.DataFrame) -> pd.DataFrame:
    """Per PnP method (rows) the share of its frames per status that is not "ok" (columns: every status of
    :data:`FAILURE_STATUSES`, 0 where none, then any other failed status found). Every failed row carries its reason
    in the artifacts table. table : usable rows (the data flags are not failures of a method)."""
    shares = pd.crosstab(table["method"], table["status"], normalize="index")
    others = [status for status in shares.columns if status != "ok" and status not in FAILURE_STATUSES]
    return shares.reindex(columns=[*FAILURE_STATUSES, *others], fill_value=0.0)
