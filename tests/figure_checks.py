"""What every figure of the reports owes its reader, checked on a matplotlib Figure: each axes names the unit of both
its axes, and shows data (every line, collection and bar it holds has points)."""

from __future__ import annotations

import re

import matplotlib.pyplot as plt
from matplotlib.collections import Collection, LineCollection, PathCollection
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

UNIT = re.compile(r"\((deg|mm|px|s|%|count|fraction|1)\)")  # "(fraction)", "(1)": a ratio without a unit, said so


def points(artist) -> int:
    """How many data points a plotted series holds (line vertices, scatter offsets, segments, patch vertices)."""
    if isinstance(artist, Line2D):
        return len(artist.get_xdata())
    if isinstance(artist, PathCollection):
        return len(artist.get_offsets())
    if isinstance(artist, LineCollection):
        return len(artist.get_segments())
    if isinstance(artist, Collection):
        return len(artist.get_paths())
    if isinstance(artist, Patch):
        return len(artist.get_path().vertices)
    raise TypeError(f"not a series: {artist!r}")


def assert_readable(fig: plt.Figure) -> None:
    """Every axes of ``fig``: an x and a y label, each naming a unit (:data:`UNIT`), and at least one series drawn,
    none of them empty."""
    assert fig.axes, "a figure without axes"
    for ax in fig.axes:
        where = f"axes {ax.get_title()!r}"
        for name, label in (("x", ax.get_xlabel()), ("y", ax.get_ylabel())):
            assert UNIT.search(label), f"{where}: its {name} label {label!r} names no unit"
        series = [*ax.lines, *ax.collections, *ax.patches]
        assert series, f"{where}: nothing drawn"
        assert [artist for artist in series if points(artist) == 0] == [], f"{where}: an empty series"


def legend_texts(ax) -> list[str]:
    """The entries of ``ax``'s legend ([] without one)."""
    legend = ax.get_legend()
    return [text.get_text() for text in legend.get_texts()] if legend else []
