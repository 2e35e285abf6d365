"""The tests' own reading of what the report shows, not through the report's code: a section's lines, the first
section's table of claims, the numbers a cell shows within their rounding; and of the metrics: a dotted key, an
interval's two ends."""

import re

from poseintegrity.report.claims import TITLE


def section(summary: str, title: str = TITLE) -> list[str]:
    """A section's lines (the first section's by default), from its heading to the next heading."""
    start = summary.index(f"## {title}")
    return summary[start:].split("\n## ", 1)[0].splitlines()


def table(summary: str) -> dict[str, list[str]]:
    """The first section's table of claims (its first table; the population's follows it): claim -> its cells
    (paper, ours per world, verdict, why)."""
    lines = section(summary)
    start = next(i for i, line in enumerate(lines) if line.startswith("| claim"))
    end = next((i for i in range(start, len(lines)) if not lines[i].startswith("| ")), len(lines))
    rows = [line.strip("|").split(" | ") for line in lines[start:end] if "---" not in line]
    return {cells[0].strip(): [c.strip() for c in cells[1:]] for cells in rows[1:]}


def get(metrics: dict, stage: str, key: str):
    """The value at a dotted key, KeyError when absent (the test's own reading)."""
    value = metrics[stage]
    for part in key.split("."):
        value = value[part]
    return value


def numbers(cell: str) -> list[tuple[float, float]]:
    """Each number shown in a cell as (value, half of its last digit), percentages as fractions; the tolerances' and
    the markers' names are labels, not values."""
    cell = re.sub(r"\d mm/\d+ deg|\(\w\)", "", cell.split("](")[0])
    found = []
    for sign, digits, decimals, percent in re.findall(r"(?<![\w.])([+-]?)(\d+)(?:\.(\d+))?(%?)(?![\w])", cell):
        value = float(f"{sign}{digits}.{decimals or 0}")
        half = 0.5 * 10.0 ** -len(decimals)
        found.append((value / 100, half / 100) if percent else (value, half))
    return found


def assert_shows(cell: str, values: list, where: str):
    """The numbers of ``cell`` are ``values`` in order (None: not shown, "none"), each within its rounding."""
    shown, expected = numbers(cell), [v for v in values if v is not None]
    assert len(shown) == len(expected), f"{where}: {cell!r} shows {shown}, expected {expected}"
    for (value, half), want in zip(shown, expected):
        assert abs(value - want) <= half * (1 + 1e-9) + 1e-12, f"{where}: {cell!r}: {value} is not {want}"


def ends(entry: dict, key: str) -> list:
    """An interval's two ends as a cell shows them (None: "none", not a number), nothing when the metrics hold none."""
    interval = entry.get("interval", {}).get(key) if isinstance(entry, dict) else None
    return list(interval) if isinstance(interval, list) else []
