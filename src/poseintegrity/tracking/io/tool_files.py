"""Tool files: the geometries of the tracked tools (metres, body frame), checked on read
(:func:`~poseintegrity.tracking.markers.tools.check_tools`).

Formats:
- JSON: ``{"tools": [{"name": "probe", "markers_body": [[x, y, z], ...]}, ...]}``
- CSV: a header ``tool,x,y,z`` and one row per marker, rows of a tool in marker order.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pandas as pd

from poseintegrity.errors import read_text_file
from poseintegrity.tracking.markers.tools import ToolError, check_tools


def _tool_pairs_json(path: Path, text: str) -> list:
    raw = json.loads(text)
    if not isinstance(raw, dict) or not isinstance(raw.get("tools"), list):
        raise ToolError(f'{path}: expected {{"tools": [{{"name": ..., "markers_body": [[x, y, z], ...]}}, ...]}}, '
                        f"got {type(raw).__name__} {str(raw)[:60]}")
    pairs = []
    for k, tool in enumerate(raw["tools"]):
        if not isinstance(tool, dict) or "name" not in tool or "markers_body" not in tool:
            raise ToolError(f"{path}: tools[{k}] needs the fields name and markers_body, got {str(tool)[:60]}")
        pairs.append((str(tool["name"]), tool["markers_body"]))
    return pairs


def _tool_pairs_csv(path: Path, text: str) -> list:
    table = pd.read_csv(io.StringIO(text), dtype={"tool": str})
    missing = [c for c in ("tool", "x", "y", "z") if c not in table.columns]
    if missing:
        raise ToolError(f"{path}: lacks the column(s) {missing}; expected a header tool,x,y,z")
    for column in ("x", "y", "z"):
        values = pd.to_numeric(table[column], errors="coerce")
        bad = np.flatnonzero(values.isna() & table[column].notna())
        if bad.size:
            raise ToolError(f"{path}: {column} of row {bad[0] + 1} is not a number ({table[column].iloc[bad[0]]!r})")
        table[column] = values
    names = table["tool"].to_numpy()
    starts = [k for k in range(len(names)) if k == 0 or names[k] != names[k - 1]]
    seen = set()
    for k in starts:  # the rows of a tool are consecutive; a name that comes back is a second tool of that name
        if names[k] in seen:
            raise ToolError(f"{path}: tool name {names[k]!r} appears again at row {k + 1} after other tools; "
                            f"each tool needs its own name and its rows together")
        seen.add(names[k])
    return [(str(name), rows[["x", "y", "z"]].to_numpy(float)) for name, rows in table.groupby("tool", sort=False)]


def read_tools(path: str | Path, distinct_m: float) -> dict[str, np.ndarray]:
    """Tool geometries {name: (m, 3) metres} from a JSON or CSV file (module docstring), checked by
    :func:`check_tools`.  Every problem (missing, empty, binary or non-UTF-8 file, malformed content, a field
    missing or not numbers, fewer than 3 markers, markers at one place, duplicated names, distances that are
    not distinct) raises :class:`ToolError` beginning with the file name."""
    path = Path(path)
    if path.suffix.lower() not in (".json", ".csv"):
        raise ToolError(f"{path}: tool files are .json or .csv, got {path.suffix!r}")
    text = read_text_file(path, ToolError, "tool file")
    try:
        pairs = _tool_pairs_json(path, text) if path.suffix.lower() == ".json" else _tool_pairs_csv(path, text)
    except ToolError:
        raise
    except (KeyError, TypeError, ValueError) as error:  # json / pandas parse errors are ValueErrors
        raise ToolError(f"{path}: cannot parse the tool geometries ({type(error).__name__}: {error})") from None
    return check_tools(pairs, distinct_m, str(path))


def write_tools(path: str | Path, tools: dict[str, np.ndarray]) -> None:
    """Write tool geometries as JSON (the format :func:`read_tools` reads)."""
    payload = {"tools": [{"name": name, "markers_body": np.asarray(m).tolist()} for name, m in tools.items()]}
    Path(path).write_text(json.dumps(payload, indent=2), encoding="utf-8")
