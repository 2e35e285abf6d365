"""Stage 02's figures of the envelopes: why each one ends, and how well the predicted error is calibrated before it.

    envelope_causes_figure    theta_a against the ground truth beside theta_a against the exact pose, arcs (deg)
                              and lines (mm) in panels of their own, each cause counted in its panel's legend
    error_calibration_figure  measured vs predicted E_t per stop before theta_a, the 1 and 2 sigma lines named, and
                              the share within 2 sigma of the same frames (``calibration_metrics``) written on it
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.lines import Line2D

from poseintegrity.localization.envelope_causes import CAUSES

CAUSE_COLOURS = {cause: f"C{i}" for i, cause in enumerate(CAUSES)}
LIMIT_MARKERS = {"translation": "o", "rotation": "P", "no_pose": "X", "censored": "s", "unmeasured": "D"}
TRAJECTORIES = {"arc": ("arcs", "theta_a", "deg"), "line": ("lines", "x_a", "mm")}  # panel name, symbol, unit
PREDICTIONS = {"sigma_t_pred_mm": "inlier-conditioned", "sigma_t_unconditioned_mm": "unconditioned"}
SIGMA_LINES = ((1.0, "-", "measured = predicted (1 sigma)"), (2.0, "--", "measured = 2 x predicted (2 sigma)"))


def envelope_causes_figure(causes: pd.DataFrame) -> plt.Figure:
    """Why each envelope ends (:func:`~.envelope_causes.envelope_causes` rows): a row of panels per world, a column per
    tolerance and trajectory type, so arcs (deg) and lines (mm) never share an axis. Each panel: theta_a against the
    ground truth (x) and against the exact pose (y) per dataset, coloured by cause, marked by the limit that ended
    it, the diagonal dashed; its legend counts the panel's envelopes per cause. An envelope without an exact pose
    (recorded data) is drawn on the diagonal."""
    if causes.empty:
        fig, ax = plt.subplots(figsize=(5, 3))
        ax.set(title="no envelope to explain", xlabel="theta_a against the ground truth (deg)",
               ylabel="theta_a against the exact pose (deg)")
        return fig
    worlds = list(dict.fromkeys(causes["world"]))
    columns = [(tolerance, trajectory) for tolerance in sorted(causes["tolerance"].unique())
               for trajectory in TRAJECTORIES if (causes["trajectory"] == trajectory).any()]
    fig, axes = plt.subplots(len(worlds), len(columns), figsize=(3.6 * len(columns), 3.4 * len(worlds)),
                             squeeze=False)
    for row, world in zip(axes, worlds):
        for ax, (tolerance, trajectory) in zip(row, columns):
            name, symbol, unit = TRAJECTORIES[trajectory]
            panel = causes[(causes["world"] == world) & (causes["tolerance"] == tolerance)
                           & (causes["trajectory"] == trajectory)]
            exact = panel["theta_a_exact"].fillna(panel["theta_a"])
            for (cause, limit), part in panel.groupby(["cause", "limit"], sort=False):
                ax.scatter(part["theta_a"], exact[part.index], s=22, color=CAUSE_COLOURS.get(cause, "0.5"),
                           marker=LIMIT_MARKERS.get(limit, "v"), alpha=0.8)
            known = pd.concat([panel["theta_a"], exact]).dropna()
            if len(known):
                low, high = float(known.min()), float(known.max())
                ax.plot([low, high], [low, high], color="grey", lw=0.8, ls="--")
            counts = panel["cause"].value_counts()
            if len(panel):
                ax.legend(handles=[Line2D([], [], ls="", marker="o", color=CAUSE_COLOURS[cause],
                                          label=f"{cause}: {counts[cause]}") for cause in CAUSES if cause in counts],
                          title="cause: envelopes", fontsize=7, title_fontsize=7, loc="upper left")
            ax.set(title=f"{world}, {tolerance}, {name} ({len(panel)})" if len(panel) else
                   f"{world}, {tolerance}: no {name}",
                   xlabel=f"{symbol} against the ground truth ({unit})",
                   ylabel=f"{symbol} against the exact pose ({unit})")
    fig.legend(handles=[Line2D([], [], ls="", marker=marker, color="0.3", label=limit)
                        for limit, marker in LIMIT_MARKERS.items() if (causes["limit"] == limit).any()],
               title="limit that ended it", loc="lower center", ncol=len(LIMIT_MARKERS), fontsize=8,
               bbox_to_anchor=(0.5, -0.02))
    fig.suptitle("Why each envelope ends: theta_a against the ground truth vs against the exact pose (dashed: "
                 "equal; no exact pose: on the diagonal)", y=1.0)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return fig


def error_calibration_figure(frames: pd.DataFrame, calibration: dict) -> plt.Figure:
    """The predicted error against the measured one, per stop before theta_a: ``frames`` are
    :func:`~.error_calibration.calibration_frames` rows (a frame per tolerance, at a position before its dataset's
    theta_a: the first failing stop and those after it left out), ``calibration`` their
    :func:`~.error_calibration.calibration_metrics`. A row of panels per tolerance, a column per prediction
    (inlier-conditioned; unconditioned); a point per world, dataset and stop: its mean measured E_t (mm) against its
    mean predicted RMS E_t (mm), log-log, with the lines measured = 1 x and 2 x predicted. Each panel states, per
    world, the share of those frames whose E_t lies within 2 predicted sigma (the metric), and of the stops drawn."""
    if frames.empty:
        fig, ax = plt.subplots(figsize=(5, 3))
        ax.set(title="no frame before theta_a with a predicted error", xlabel="predicted RMS E_t per stop (mm)",
               ylabel="measured mean E_t per stop (mm)")
        return fig
    tolerances = sorted(frames["tolerance"].unique())
    worlds = list(dict.fromkeys(frames["world"]))
    per_stop = (frames.groupby(["world", "tolerance", "trajectory", "dataset", "stop"], as_index=False)
                [["E_t_mm", *PREDICTIONS]].mean().dropna(subset=["E_t_mm"]))
    fig, axes = plt.subplots(len(tolerances), len(PREDICTIONS),
                             figsize=(5.6 * len(PREDICTIONS), 3.9 * len(tolerances)), squeeze=False)
    for row, tolerance in zip(axes, tolerances):
        for ax, (column, prediction) in zip(row, PREDICTIONS.items()):
            shares = []
            for i, world in enumerate(worlds):
                stops = per_stop[(per_stop["world"] == world) & (per_stop["tolerance"] == tolerance)]
                for trajectory, marker in (("arc", "o"), ("line", "x")):
                    part = stops[stops["trajectory"] == trajectory]
                    if len(part):
                        ax.scatter(part[column], part["E_t_mm"], s=12, color=f"C{i}", marker=marker, alpha=0.6,
                                   label=f"{world}, {trajectory}s")
                entry = calibration.get(str(world), {}).get(str(tolerance))
                if entry:
                    frames_share = (entry if column == "sigma_t_pred_mm" else entry["unconditioned"])["within_2sigma_t"]
                    drawn = stops.dropna(subset=[column])
                    stops_share = float((drawn["E_t_mm"] <= 2.0 * drawn[column]).mean()) if len(drawn) else np.nan
                    shares.append(f"{world}: {frames_share:.0%} of {entry['n_frames']} frames, "
                                  f"{stops_share:.0%} of {len(drawn)} stops")
            known = per_stop.loc[per_stop["tolerance"] == tolerance, [column, "E_t_mm"]].to_numpy(dtype=float)
            known = known[np.isfinite(known) & (known > 0)]
            low, high = (float(known.min()) / 2, float(known.max()) * 2) if known.size else (1e-2, 1e2)
            for factor, style, label in SIGMA_LINES:
                ax.plot([low, high], [factor * low, factor * high], color="grey", lw=0.9, ls=style, label=label)
            ax.set(xscale="log", yscale="log", title=f"{tolerance}, {prediction} prediction",
                   xlabel="predicted RMS E_t per stop (mm)", ylabel="measured mean E_t per stop (mm)")
            ax.text(0.98, 0.02, "within 2 sigma:\n" + "\n".join(shares), transform=ax.transAxes, ha="right",
                    va="bottom", fontsize=7, bbox=dict(facecolor="white", alpha=0.8, lw=0))
            ax.legend(fontsize=7, loc="upper left")
    fig.suptitle("Predicted vs measured localization error, stops before theta_a (the first failing stop and those "
                 "after it left out)", y=1.0)
    fig.tight_layout()
    return fig
