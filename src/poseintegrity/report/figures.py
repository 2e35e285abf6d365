"""Figures shared by the notebooks (seaborn/matplotlib)."""

from __future__ import annotations

from pathlib import Path

import cv2
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import seaborn as sns

def _read(path: Path):
    return cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)


def nothing_to_draw(title: str) -> plt.Figure:
    """A small figure whose title says why it is empty (e.g. recorded data without straight lines): a declared
    output that exists and says so, never a stale figure of another run."""
    fig, ax = plt.subplots(figsize=(6, 1.2))
    ax.axis("off")
    ax.set_title(title, fontsize=10)
    return fig


def scene_gallery(root: Path, index: pd.DataFrame, n_cols: int = 4) -> plt.Figure:
    """Like Fig. 4 of Windsor et al.: the first model image of every scene."""
    scenes = index.drop_duplicates("scene")
    n_rows = -(-len(scenes) // n_cols)
    fig, axes = plt.subplots(n_rows, n_cols, figsize=(3.6 * n_cols, 2.5 * n_rows), squeeze=False)
    for ax in axes.ravel():
        ax.axis("off")
    for ax, (_, row) in zip(axes.ravel(), scenes.iterrows()):
        ax.imshow(_read(Path(root) / row["dataset"] / "model" / "model_0.png"), cmap="gray", vmin=0, vmax=255)
        ax.set_title(row["scene"], fontsize=9)
    fig.tight_layout()
    return fig


def trajectory_strip(root: Path, dataset: str, frames: pd.DataFrame, n_views: int = 5) -> plt.Figure:
    """Views along one trajectory (image 0 of evenly spaced stops), titled with theta and x."""
    stops = sorted(frames["stop"].unique())
    picks = [stops[round(i * (len(stops) - 1) / max(n_views - 1, 1))] for i in range(min(n_views, len(stops)))]
    fig, axes = plt.subplots(1, len(picks), figsize=(3.2 * len(picks), 2.3), squeeze=False)
    for ax, stop in zip(axes[0], picks):
        row = frames[(frames["stop"] == stop) & (frames["image"] == 0)].iloc[0]
        ax.imshow(_read(Path(root) / dataset / row["file"]), cmap="gray", vmin=0, vmax=255)
        ax.set_title(f"stop {stop}: theta {row['theta_deg']:.2f} deg, x {row['x_mm']:.0f} mm", fontsize=8)
        ax.axis("off")
    fig.suptitle(dataset, fontsize=10)
    fig.tight_layout()
    return fig


def appearance_bars(table: pd.DataFrame) -> plt.Figure:
    """SIFT keypoints on the target without and with CLAHE, per scene."""
    long = table.melt(id_vars=["scene", "targets"], value_vars=["keypoints_raw", "keypoints_clahe"],
                      var_name="preprocessing", value_name="keypoints on target")
    long["preprocessing"] = long["preprocessing"].map({"keypoints_raw": "raw", "keypoints_clahe": "CLAHE"})
    long["scene"] = long["scene"] + "\n" + long["targets"]
    fig, ax = plt.subplots(figsize=(9, 3.2))
    sns.barplot(long, x="scene", y="keypoints on target", hue="preprocessing", ax=ax)
    ax.set_xlabel("")
    ax.tick_params(axis="x", labelsize=7)
    fig.tight_layout()
    return fig


POINT_KINDS = {"own": "its own point", "main": "the main world's point", "others": "the other worlds' point"}


def population_figure(judged: pd.DataFrame, predictors: list[str]) -> plt.Figure:
    """Each predictor's share of the world's ceiling over the population's worlds (issue 49), a column per tolerance:
    a dot per world at each kind of operating point (:data:`POINT_KINDS`), filled where the world had no incursion
    there and hollow where it had (its SPL then counts what the robot got past its envelope), a bar at the median.
    judged : rows of :func:`~poseintegrity.population.judge.judge_population` (world, tolerance, predictor, point,
    share, incursion_rate)."""
    tolerances = sorted(judged["tolerance"].unique())
    fig, axes = plt.subplots(1, len(tolerances), figsize=(6.5 * len(tolerances), 0.55 * len(predictors) + 1.6),
                             squeeze=False, sharey=True)
    colours = dict(zip(POINT_KINDS, sns.color_palette("tab10", len(POINT_KINDS))))
    for ax, tolerance in zip(axes[0], tolerances):
        for i, predictor in enumerate(predictors):
            for j, (kind, label) in enumerate(POINT_KINDS.items()):
                rows = judged[(judged["tolerance"] == tolerance) & (judged["predictor"] == predictor)
                              & (judged["point"] == kind)]
                y = i + (j - 1) * 0.25
                safe = rows["incursion_rate"] == 0
                share = rows["share"].clip(-1.0, 1.0)
                ax.scatter(share[safe], np.full(safe.sum(), y), s=22, color=colours[kind],
                           label=label if i == 0 else None)
                ax.scatter(share[~safe], np.full((~safe).sum(), y), s=22, facecolors="none",
                           edgecolors=colours[kind],
                           label=f"{label}, with incursions" if i == 0 and kind != "own" else None)  # own: never
                if len(rows):
                    ax.plot([rows["share"].median()] * 2, [y - 0.1, y + 0.1], color="black", lw=2)
        ax.axvline(0.0, color="grey", ls=":", lw=1)
        ax.set(title=tolerance, xlim=(-1.05, 1.05), xlabel="share of the world's ceiling (0: its static; 1: knew every "
                                                              "envelope)")
        ax.set_yticks(range(len(predictors)), [p.replace("_", " ") for p in predictors])
    axes[0, 0].invert_yaxis()
    axes[0, -1].legend(fontsize=7, loc="lower right")
    fig.suptitle(f"Each predictor over {judged['world'].nunique()} worlds of the population (bars: medians; shares "
                 f"below -1 drawn at -1)", y=1.0)
    fig.tight_layout()
    return fig


def hazard_figure(reliability: pd.DataFrame, importance: pd.DataFrame, top: int = 8) -> plt.Figure:
    """The failure hazard on held-out worlds (issue 50), a row per tolerance: the reliability diagram of the next-step
    hazard beside the one-column hazards (the predicted error alone, n_i alone; marker area: rows in the bin), and
    the ``top`` evidence columns by permutation importance (mean rise of the Brier score, bars over the worlds' spread).
    reliability : population.hazard.reliability_table; importance : its ``importance`` table."""
    tolerances = sorted(reliability["tolerance"].unique())
    fig, axes = plt.subplots(len(tolerances), 2, figsize=(11, 4.2 * len(tolerances)), squeeze=False)
    for row, tolerance in zip(axes, tolerances):
        shown = reliability[(reliability["tolerance"] == tolerance) & (reliability["predictor"] == "hazard_next_step")]
        for (label, part), color in zip(shown.groupby("hazard_of", sort=False), sns.color_palette("deep")):
            part = part[part["n"] > 0]
            row[0].plot(part["mean_hazard"], part["failure_rate"], "-", color=color, alpha=0.7)
            row[0].scatter(part["mean_hazard"], part["failure_rate"], s=8 + 60 * part["n"] / max(part["n"].max(), 1),
                           color=color, label=label.replace("_", " "))
        row[0].plot([0, 1], [0, 1], ":", color="grey")
        row[0].set(xlabel="predicted hazard of the next stop", ylabel="share of those stops that failed",
                   title=f"{tolerance}: calibration on held-out worlds", xlim=(0, 1), ylim=(0, 1))
        row[0].legend(fontsize=8)
        ranked = importance[(importance["tolerance"] == tolerance) & (importance["predictor"] == "hazard_next_step")]
        ranked = ranked.groupby("feature")["importance"].agg(["mean", "std"]).sort_values("mean").tail(top)
        row[1].barh(ranked.index, ranked["mean"], xerr=ranked["std"], color=sns.color_palette("deep")[0])
        row[1].set(xlabel="rise of the Brier score when shuffled", title=f"{tolerance}: what the next-step hazard reads")
    fig.tight_layout()
    return fig
