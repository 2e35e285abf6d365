"""Several tracked tools at once (beyond the paper; HoloLens IR trackers such as STTAR and HoloLens2-IRTracking
track several, docs/references.md): tool geometries from a file, a check that every inter-marker distance is
distinct across all tools (Alg. 2 votes by distance, so a shared distance lets one tool's pair vote for
another's), and one filter per tool.

Tool file formats (metres, body frame):
- JSON: ``{"tools": [{"name": "probe", "markers_body": [[x, y, z], ...]}, ...]}``
- CSV: a header ``tool,x,y,z`` and one row per marker, rows of a tool in marker order.
"""

from __future__ import annotations

import io
import json
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from poseintegrity.defaults import published
from poseintegrity.errors import ArgumentError, PoseIntegrityError, check_array, read_text_file
from poseintegrity.tracking.geometry import pairwise_distances, tool_geometry_problem
from poseintegrity.tracking.params import FilterParams, MatchingParams
from poseintegrity.tracking.tracker import FrameResult, MarkerTracker, check_points, check_rates, check_timestamp


class ToolError(PoseIntegrityError):
    """A tool file or tool set that cannot be used: unreadable, too few markers, or distances that are not distinct."""


def check_distinct_distances(tools: dict[str, np.ndarray], distinct_m: float, source: str = "tools") -> None:
    """Raise :class:`ToolError` saying why the tools (name -> (m, 3) metres) cannot be told apart or posed:
    fewer than 3 markers, markers on one line, or two inter-marker distances (within a tool or across tools)
    within distinct_m (m) of each other (:func:`~poseintegrity.tracking.geometry.tool_geometry_problem`).
    source (a file name, or "tools") begins the message."""
    problem = tool_geometry_problem(tools, distinct_m)
    if problem:
        raise ToolError(f"{source}: {problem}")


def check_tools(tools: object, distinct_m: float, source: str = "tools") -> dict[str, np.ndarray]:
    """Tools as {name: float (m, 3) array}, checked: a non-empty mapping (or sequence of (name, markers) pairs
    with distinct names), each tool's markers finite (m, 3) metres with m >= 3 and no two markers at one place,
    then :func:`check_distinct_distances`.  Raises :class:`ToolError` naming ``source`` and the tool."""
    if isinstance(tools, Mapping):
        pairs = list(tools.items())
    elif isinstance(tools, (list, tuple)) and all(isinstance(p, (list, tuple)) and len(p) == 2 for p in tools):
        pairs = [tuple(p) for p in tools]
    else:
        raise ToolError(f"{source}: expected a mapping of tool name to (m, 3) marker positions, got {type(tools).__name__}")
    if not pairs:
        raise ToolError(f"{source}: no tools given; at least one tool is needed")
    checked: dict[str, np.ndarray] = {}
    for name, markers in pairs:
        if not isinstance(name, str) or not name:
            raise ToolError(f"{source}: a tool name must be non-empty text, got {name!r}")
        if name in checked:
            raise ToolError(f"{source}: tool name {name!r} appears more than once; each tool needs its own name")
        try:
            markers = check_array(f"markers_body of tool {name!r}", markers, shape=(None, 3), min_rows=3)
        except ArgumentError as error:
            raise ToolError(f"{source}: {error}") from None
        D = pairwise_distances(markers) + np.eye(len(markers))
        if (D <= distinct_m).any():
            i, j = np.argwhere(D <= distinct_m)[0]
            raise ToolError(f"{source}: tool {name!r} has markers {i + 1} and {j + 1} at the same place "
                            f"({D[i, j] * 1000:.3g} mm apart, at most {distinct_m * 1000:g} mm)")
        checked[name] = markers
    check_distinct_distances(checked, distinct_m, source)
    return checked


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


class MultiToolTracker:
    """One :class:`MarkerTracker` per tool fed by the same frames.

    Tools are matched in turn; the points a tool matched are withheld from the tools after it, so one
    reflection is never two tools' marker.  gyro_tool : the tool that carries the gyro (None: no gyro).
    The tools are checked once by :func:`check_tools` (ToolError: none, duplicated names, < 3 markers, ...);
    a gyro_tool that names no tool raises ToolError.  filter_params, matching : ``track.filter`` /
    ``track.matching``; None takes the published defaults (params.yaml).  A frame with no point left for a tool (nothing detected,
    or every point taken by the tools before it) gives that tool a flagged result ("no_points"), never an error.
    """

    def __init__(self, tools: dict[str, np.ndarray], filter_params: FilterParams | None = None,
                 matching: MatchingParams | None = None, gyro_tool: str | None = None):
        filter_params = published("track.filter") if filter_params is None else filter_params
        matching = published("track.matching") if matching is None else matching
        tools = check_tools(tools, matching.distinct_m)
        if gyro_tool is not None and gyro_tool not in tools:
            raise ToolError(f"gyro_tool: {gyro_tool!r} names no tool; the tools are {list(tools)}")
        self.trackers = {
            name: MarkerTracker(markers, filter_params, matching, use_gyro=name == gyro_tool) for name, markers in tools.items()
        }
        self.gyro_tool = gyro_tool

    def frame(self, t: float, points: np.ndarray) -> dict[str, FrameResult]:
        """Results per tool for one frame of points (n, 3), metres, world frame; ArgumentError for a bad
        timestamp or points that are not (n, 3) (checked once here for all tools)."""
        return self._frame(check_timestamp(t), check_points(points))

    def _frame(self, t: float, points: np.ndarray) -> dict[str, FrameResult]:
        free = np.ones(len(points), dtype=bool)
        results = {}
        for name, tracker in self.trackers.items():
            index = np.flatnonzero(free)
            result = tracker._frame(t, points[index])
            assignment = result.assignment.copy()
            hit = assignment >= 0
            assignment[hit] = index[assignment[hit]]  # back to rows of points (no hit: nothing to index)
            free[assignment[hit]] = False
            results[name] = FrameResult(assignment, result.T_measured, result.T_filtered, result.flag)
        return results

    def gyro(self, t: float, omega_body: np.ndarray) -> dict[str, str]:
        """A gyro sample (rad/s, body frame of gyro_tool): fused by that tool's filter; the others only advance."""
        return self._gyro(check_timestamp(t), check_rates(omega_body))

    def _gyro(self, t: float, omega_body: np.ndarray) -> dict[str, str]:
        return {name: tracker._gyro(t, omega_body) for name, tracker in self.trackers.items()}
