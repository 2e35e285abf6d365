"""Stage 04's figures of the SPL vs R_i curves (Windsor et al. Figs. 5-8) and of the ceiling (ours, issue 38).

    curves_figure    SPL vs R_i curves of :func:`~.metrics.operating_curves`, SPL in the unit of the trajectories
                     drawn (deg for arcs, mm for lines), the title saying in which steps R_i moves (1/n of n datasets)
    ceiling_figure   per world and tolerance every predictor's max mean SPL at R_i <= r with its interval, dodged so
                     that the headlines at r = 0 stand apart, each headline in the legend, beside the ceiling
    tail_figure      the artifact model's tail on the arcs whose long range theta_p overshoots theta_a (:mod:`.tails`)
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import seaborn as sns

from poseintegrity.prediction.tails import TailFit
from poseintegrity.report.figures import nothing_to_draw

SPL_UNITS = {"arc": "deg", "line": "mm"}  # theta_a, theta_p and SPL of an arc are angles; of a line, distances
DATASET_WORDS = {"arc": "arcs", "line": "lines"}
R_I_LABEL = "incursion rate R_i, eq. 4 (fraction)"
COLOURS = ("C0", "C1", "C2", "C3", "C4", "C5", "C6", "C8", "C9")  # tab10 without its grey (C7): static's colour
MARKERS = ("o", "s", "^", "v", "D", "P", "X", "*", "h")
STATIC_COLOUR = "0.45"
DODGE_SHARE = 0.6  # of the spacing of the incursion rates: the width the predictors' points are spread over


def r_i_steps(curves: pd.DataFrame) -> str:
    """"4 lines per world: R_i moves in steps of 1/4": R_i = I / n (eq. 4) of n datasets (the most of any operating
    point: a flagged dataset is not counted) moves in steps of 1 / n; per world where the worlds differ."""
    kinds = curves["trajectory"].unique()
    word = DATASET_WORDS[kinds[0]] if len(kinds) == 1 else "datasets"
    counts = (curves.groupby("world")["n"].max() if "world" in curves else pd.Series({"": curves["n"].max()}))
    counts = counts.astype(int)
    if counts.nunique() == 1:
        n = int(counts.iloc[0])
        return f"{n} {word}{' per world' if len(counts) > 1 else ''}: R_i moves in steps of 1/{n}"
    return "; ".join(f"{world}: {n} {word}, R_i in steps of 1/{n}" for world, n in counts.items())


def curves_figure(curves: pd.DataFrame, hue: str, title: str, col: str = "tolerance", col_wrap: int | None = None,
                  row: str | None = None) -> plt.Figure:
    """The SPL vs R_i curves of ``curves`` (rows of :func:`~.metrics.operating_curves`, a ``world`` column where there
    are several), one line per ``hue`` value in operating-point order, faceted by ``col`` (and ``row``). Every panel
    names its axes' units: SPL in deg for arcs, mm for lines (eq. 3); R_i a fraction of the datasets (eq. 4), whose
    steps the title states. Without rows, a titled empty figure (e.g. recorded data without lines)."""
    if curves.empty:
        return nothing_to_draw(f"{title}: nothing to draw (no such datasets)")
    units = sorted({SPL_UNITS[kind] for kind in curves["trajectory"].unique()})
    grid = sns.relplot(data=curves.sort_values("operating_point"), x="incursion_rate", y="mean_spl", hue=hue, col=col,
                       col_wrap=col_wrap, row=row, kind="line", sort=False, estimator=None, marker="o", markersize=3,
                       height=3.6, aspect=1.2, facet_kws={"sharey": False})
    for ax in grid.axes.flat:
        ax.set_xlabel(R_I_LABEL)
        ax.set_ylabel(f"mean SPL, eq. 3 ({' or '.join(units)})")
        for proxy in [line for line in ax.lines if len(line.get_xdata()) == 0]:
            proxy.remove()  # seaborn's legend entries, copied into its legend: no curve of the panel
    grid.figure.suptitle(f"{title}\n{r_i_steps(curves)}", y=1.06)
    return grid.figure


def headline_text(point: pd.Series) -> str:
    """"15.4 [12.7, 18.7]": a rate_bands row's max mean SPL and its interval; "no point" where no operating point is
    that safe, the SPL alone where no draw gave an interval."""
    if not np.isfinite(point["max_mean_spl"]):
        return "no point"
    interval = f" [{point['low']:.1f}, {point['high']:.1f}]" if np.isfinite([point["low"], point["high"]]).all() else ""
    return f"{point['max_mean_spl']:.1f}{interval}"


def ceiling_figure(bands: pd.DataFrame, limits: dict[str, dict[str, dict]], level: float) -> plt.Figure:
    """The SPL vs R_i figure with bands (issue 49): a panel per world and tolerance, every predictor of ``bands`` in
    it (static grey): its max mean SPL at R_i <= r (deg) against r (:func:`~.intervals.rate_bands`; at r = 0 the
    headline) as markers joined by steps, its interval over scene-resampled draws as a vertical bar at each r, the
    predictors dodged sideways around each r so that no point hides another; the legend gives each predictor's
    headline and interval. Dashed: the ceiling (mean theta_a); dotted: the smallest theta_a. The y axis spans the
    data. bands : rows of rate_bands with columns world and tolerance; limits : world -> tolerance ->
    :func:`~.ceiling.ceiling` entry; level : the intervals' coverage."""
    panels = list(dict.fromkeys(zip(bands["world"], bands["tolerance"])))
    predictors = list(dict.fromkeys(bands["predictor"]))
    rates = np.sort(bands["incursion_rate"].unique())
    spacing = float(np.diff(rates).min()) if len(rates) > 1 else 0.05
    step = DODGE_SHARE * spacing / len(predictors)
    others = iter(zip(COLOURS * len(predictors), MARKERS * len(predictors)))
    styles = {p: (STATIC_COLOUR, "o") if p == "static" else next(others) for p in predictors}
    fig, axes = plt.subplots(len(panels), 1, figsize=(11, 3.6 * len(panels)), squeeze=False)
    for ax, (world, tolerance) in zip(axes[:, 0], panels):
        entry, rows = limits[world][tolerance], bands[(bands["world"] == world) & (bands["tolerance"] == tolerance)]
        for i, predictor in enumerate(predictors):
            ours = rows[rows["predictor"] == predictor].sort_values("incursion_rate")
            if ours.empty:
                continue
            colour, marker = styles[predictor]
            x = ours["incursion_rate"].to_numpy() + (i - (len(predictors) - 1) / 2) * step
            ax.vlines(x, ours["low"], ours["high"], color=colour, lw=1.2, alpha=0.6)
            head = ours.iloc[0]  # the smallest r: 0, the headline
            ax.plot(x, ours["max_mean_spl"], color=colour, marker=marker, markersize=5, lw=1, drawstyle="steps-post",
                    label=f"{predictor.replace('_', ' ')}: {headline_text(head)}")
        ax.axhline(entry["mean_theta_a"], color="black", ls="--", lw=1,
                   label=f"ceiling, mean theta_a: {entry['mean_theta_a']:.1f}")
        ax.axhline(entry["min_theta_a"], color="black", ls=":", lw=1,
                   label=f"smallest theta_a: {entry['min_theta_a']:.1f}")
        values = np.concatenate([rows[["max_mean_spl", "low", "high"]].to_numpy(dtype=float).ravel(),
                                 [entry["mean_theta_a"], entry["min_theta_a"]]])
        values = values[np.isfinite(values)]
        if values.size:
            pad = max(0.06 * float(np.ptp(values)), 0.5)
            ax.set_ylim(float(values.min()) - pad, float(values.max()) + pad)
        ax.set_xticks(rates)
        ax.set(title=f"{world}, {tolerance}", xlabel="r, the largest incursion rate R_i allowed (fraction)",
               ylabel="max mean SPL at R_i <= r (deg)")
        ax.legend(title=f"at r = 0, the headline [{level:.0%} interval] (deg)", fontsize=7, title_fontsize=7,
                  loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.suptitle(f"Max mean SPL at R_i <= r, arcs (at r = 0: the headline). Bars: {level:.0%} of draws resampling the "
                 f"scenes, the operating point chosen again in each; predictors side by side around each r",
                 fontsize=9, y=1.0)
    fig.tight_layout()
    return fig


TAIL_STYLES = {"long_range": ("eq. 1 (EMG, sigma = 1)", "C0", "-"),
               "long_range_free_width": ("free-width EMG (ours)", "C3", "--")}  # label, colour, line of each fit


def tail_figure(tails: list[TailFit], n_t_max: int, n_cols: int = 3) -> plt.Figure:
    """The artifact model's tail (:mod:`.tails`): per arc, every image's n_i (grey), the first n_sampled_stops stops
    fitted (black), the long range predictor's fitted curves (eq. 1 and the free-width EMG) over the whole arc,
    theta_a per tolerance (vertical lines). ``n_t_max`` : the diagnosis' largest n_t (titles). Without arcs, a
    titled empty figure."""
    if not tails:
        return nothing_to_draw(f"no arc overshoots its theta_a at every n_t <= {n_t_max}")
    n_rows = -(-len(tails) // n_cols)
    fig, axes = plt.subplots(n_rows, min(n_cols, len(tails)), figsize=(4.6 * min(n_cols, len(tails)), 3.4 * n_rows),
                             squeeze=False)  # fmt: skip
    for ax in axes.ravel()[len(tails):]:
        ax.axis("off")
    for ax, tail in zip(axes.ravel(), tails):
        series = tail.series
        theta_first, n_first = series.first_stops(tail.n_sampled_stops)
        theta = np.linspace(0.0, series.theta_end, 300)
        ax.scatter(series.theta, series.n_inliers, s=6, color="0.7", label="all images")
        ax.scatter(theta_first, n_first, s=8, color="k", label=f"first {tail.n_sampled_stops} stops")
        for predictor, fitted in tail.fits.items():
            if fitted is None:
                continue
            label, colour, line = TAIL_STYLES.get(predictor, (predictor, "C2", ":"))
            status = "" if fitted.status == "ok" else f" ({fitted.status})"
            ax.plot(theta, fitted.predict(theta), color=colour, linestyle=line, label=label + status)
        for (tolerance, theta_a), shade in zip(sorted(tail.theta_a.items()), ("0.2", "0.5")):
            ax.axvline(theta_a, color=shade, linewidth=1, linestyle=":", label=f"theta_a {tolerance}")
        top = max(float(np.nanmax(series.n_inliers)), 1.0)
        ax.set(title=series.dataset, xlabel="theta (deg)", ylabel="n_inliers", ylim=(-0.05 * top, 1.3 * top))
        ax.legend(fontsize=6)
    fig.suptitle(f"Arcs whose long range theta_p overshoots theta_a at every n_t <= {n_t_max}", y=1.0)
    fig.tight_layout()
    return fig
