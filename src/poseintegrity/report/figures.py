"""Figures shared by the notebooks (seaborn/matplotlib)."""

from __future__ import annotations

from pathlib import Path

import cv2
import matplotlib.pyplot as plt
import pandas as pd
import seaborn as sns


def _read(path: Path):
    return cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)


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
