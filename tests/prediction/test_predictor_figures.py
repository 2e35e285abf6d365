"""Stage 04's figures on synthetic curves: SPL in the unit of its trajectories, the steps of R_i said, the ceiling's
y range on its data, its headlines apart and every predictor (error_combined too) drawn."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from figure_checks import assert_readable, legend_texts
from poseintegrity.prediction.predictor_figures import (ceiling_figure, curves_figure, headline_text,
                                                       r_i_steps)

TOLERANCES = ("2mm_3deg", "4mm_10deg")
PREDICTORS = ("static", "long_range", "mlp", "next_step", "error_long_range", "error_next_step",
              "error_next_step_observed", "error_combined")


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def curves(trajectory: str, n: int) -> pd.DataFrame:
    """SPL vs R_i curves (operating_curves' columns) of ``n`` datasets of one trajectory type in two worlds: static
    and long range, 12 operating points each, R_i in steps of 1 / n."""
    rows = []
    for world in ("main", "validation"):
        for tolerance in TOLERANCES:
            for predictor in ("static", "long_range"):
                for point in range(12):
                    incursions = min(point // 3, n)
                    rows.append(dict(predictor=predictor, method="usac", trajectory=trajectory, tolerance=tolerance,
                                     operating_point=float(point), mean_spl=10.0 * point + 5, n=n, n_flagged=0,
                                     incursion_rate=incursions / n, world=world))
    return pd.DataFrame(rows)


def test_fig7_names_mm_and_says_r_i_moves_in_quarters():
    fig = curves_figure(curves("line", 4), "predictor", "Straight-line datasets (cf. Fig. 7)", row="world")
    assert_readable(fig)
    assert all("(mm)" in ax.get_ylabel() for ax in fig.axes)
    title = fig._suptitle.get_text()
    assert "4 lines per world: R_i moves in steps of 1/4" in title


def test_arc_curves_name_deg_and_their_steps():
    fig = curves_figure(curves("arc", 21), "predictor", "Arcs (cf. Fig. 5)", row="world")
    assert_readable(fig)
    assert all("(deg)" in ax.get_ylabel() for ax in fig.axes)
    assert "21 arcs per world: R_i moves in steps of 1/21" in fig._suptitle.get_text()


def test_r_i_steps_per_world_where_the_worlds_differ():
    both = pd.concat([curves("line", 4).query("world == 'main'"), curves("line", 5).query("world == 'validation'")])
    assert r_i_steps(both) == "main: 4 lines, R_i in steps of 1/4; validation: 5 lines, R_i in steps of 1/5"


def test_curves_without_rows_say_so():
    fig = curves_figure(curves("line", 4).iloc[:0], "predictor", "Straight lines", row="world")
    assert "nothing to draw" in fig.axes[0].get_title()


def bands() -> tuple[pd.DataFrame, dict]:
    """rate_bands rows of two worlds and tolerances, every predictor at r = 0 .. 0.3, SPL 13-24 deg; the ceilings."""
    rng = np.random.default_rng(2)
    rows, limits = [], {}
    for world in ("main", "validation"):
        for tolerance in TOLERANCES:
            limits.setdefault(world, {})[tolerance] = {"mean_theta_a": 24.0, "min_theta_a": 13.0}
            for predictor in PREDICTORS:
                start = 13.0 if predictor == "static" else rng.uniform(13.5, 18)
                for i, rate in enumerate(np.arange(0, 0.31, 0.05)):
                    spl = start + i * 0.8
                    rows.append(dict(predictor=predictor, incursion_rate=rate, max_mean_spl=spl, low=spl - 1.5,
                                     high=spl + 1.5, world=world, tolerance=tolerance))
    return pd.DataFrame(rows), limits


def test_ceiling_spans_its_data_draws_every_predictor_and_keeps_the_headlines_apart():
    table, limits = bands()
    fig = ceiling_figure(table, limits, 0.9)
    assert_readable(fig)
    assert len(fig.axes) == 2 * len(TOLERANCES)  # a panel per world and tolerance
    for ax in fig.axes:
        world, tolerance = ax.get_title().split(", ")
        panel = table[(table.world == world) & (table.tolerance == tolerance)]
        drawn = np.concatenate([panel[["low", "high"]].to_numpy().ravel(), [24.0, 13.0]])  # and the ceiling's lines
        span = drawn.max() - drawn.min()
        low, high = ax.get_ylim()
        assert drawn.min() - 0.1 * span < low < drawn.min() and drawn.max() < high < drawn.max() + 0.1 * span
        series = {line.get_label().split(":")[0]: line for line in ax.lines if not line.get_label().startswith("_")}
        assert {p.replace("_", " ") for p in PREDICTORS} <= set(series)
        combined = series["error combined"]
        assert len(combined.get_xdata()) == 7 and np.isfinite(combined.get_ydata()).all()
        headline_x = [series[p.replace("_", " ")].get_xdata()[0] for p in PREDICTORS]
        assert len(set(np.round(headline_x, 9))) == len(PREDICTORS)  # dodged: no two headlines on one spot
        assert max(np.abs(headline_x)) < 0.025  # around r = 0, short of the next rate
        assert any(text.startswith("error combined: ") and "[" in text for text in legend_texts(ax))


@pytest.mark.parametrize(("point", "text"), [((15.44, 12.71, 18.66), "15.4 [12.7, 18.7]"),
                                             ((15.44, np.nan, np.nan), "15.4"), ((np.nan, np.nan, np.nan), "no point")])
def test_a_headline_reads_as_its_value_and_interval(point, text):
    assert headline_text(pd.Series(dict(zip(("max_mean_spl", "low", "high"), point)))) == text
