"""Several tracked tools at once (beyond the paper; HoloLens IR trackers such as STTAR and HoloLens2-IRTracking
track several, docs/references.md): tool geometries from a file, a check that every inter-marker distance is
distinct across all tools (Alg. 2 votes by distance, so a shared distance lets one tool's pair vote for
another's), and one filter per tool.

Tool file formats (metres, body frame):
- JSON: ``{"tools": [{"name": "probe", "markers_body": [[x, y, z], ...]}, ...]}``
- CSV: a header ``tool,x,y,z`` and one row per marker, rows of a tool in marker order.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.tracking.geometry import tool_geometry_problem
from poseintegrity.tracking.params import FilterParams, MatchingParams
from poseintegrity.tracking.tracker import FrameResult, MarkerTracker


class ToolError(PoseIntegrityError):
    """A tool file that cannot be used: unreadable, too few markers, or distances that are not distinct."""


def check_distinct_distances(tools: dict[str, np.ndarray], distinct_m: float) -> None:
    """Raise :class:`ToolError` saying why the tools (name -> (m, 3) metres) cannot be told apart or posed:
    fewer than 3 markers, markers on one line, or two inter-marker distances (within a tool or across tools)
    within distinct_m (m) of each other (:func:`~poseintegrity.tracking.geometry.tool_geometry_problem`)."""
    problem = tool_geometry_problem(tools, distinct_m)
    if problem:
        raise ToolError(problem)


def read_tools(path: str | Path, distinct_m: float) -> dict[str, np.ndarray]:
    """Tool geometries {name: (m, 3) metres} from a JSON or CSV file (module docstring), checked by
    :func:`check_distinct_distances`."""
    path = Path(path)
    try:
        if path.suffix.lower() == ".json":
            raw = json.loads(path.read_text())
            tools = {str(t["name"]): np.asarray(t["markers_body"], dtype=float) for t in raw["tools"]}
        elif path.suffix.lower() == ".csv":
            table = pd.read_csv(path)
            tools = {str(name): rows[["x", "y", "z"]].to_numpy(float) for name, rows in table.groupby("tool", sort=False)}
        else:
            raise ToolError(f"{path}: tool files are .json or .csv, got {path.suffix!r}")
    except (OSError, KeyError, TypeError, ValueError) as error:
        if isinstance(error, ToolError):
            raise
        raise ToolError(f"{path}: cannot read tool geometries ({type(error).__name__}: {error})") from None
    for name, markers in tools.items():
        if markers.ndim != 2 or markers.shape[1] != 3 or not np.all(np.isfinite(markers)):
            raise ToolError(f"{path}: tool {name!r} needs finite (m, 3) marker positions, got shape {markers.shape}")
    check_distinct_distances(tools, distinct_m)
    return tools


def write_tools(path: str | Path, tools: dict[str, np.ndarray]) -> None:
    """Write tool geometries as JSON (the format :func:`read_tools` reads)."""
    payload = {"tools": [{"name": name, "markers_body": np.asarray(m).tolist()} for name, m in tools.items()]}
    Path(path).write_text(json.dumps(payload, indent=2))


class MultiToolTracker:
    """One :class:`MarkerTracker` per tool fed by the same frames.

    Tools are matched in turn; the points a tool matched are withheld from the tools after it, so one
    reflection is never two tools' marker.  gyro_tool : the tool that carries the gyro (None: no gyro).
    """

    def __init__(self, tools: dict[str, np.ndarray], filter_params: FilterParams, matching: MatchingParams, gyro_tool: str | None = None):
        check_distinct_distances(tools, matching.distinct_m)
        self.trackers = {
            name: MarkerTracker(markers, filter_params, matching, use_gyro=name == gyro_tool) for name, markers in tools.items()
        }
        self.gyro_tool = gyro_tool

    def frame(self, t: float, points: np.ndarray) -> dict[str, FrameResult]:
        """Results per tool for one frame of points (n, 3), metres, world frame."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        free = np.ones(len(points), dtype=bool)
        results = {}
        for name, tracker in self.trackers.items():
            index = np.flatnonzero(free)
            result = tracker.frame(t, points[index])
            assignment = np.where(result.assignment >= 0, index[np.maximum(result.assignment, 0)], -1)
            free[assignment[assignment >= 0]] = False
            results[name] = FrameResult(assignment, result.T_measured, result.T_filtered, result.flag)
        return results

    def gyro(self, t: float, omega_body: np.ndarray) -> dict[str, str]:
        """A gyro sample (rad/s, body frame of gyro_tool): fused by that tool's filter; the others only advance."""
        return {name: tracker.gyro(t, omega_body) for name, tracker in self.trackers.items()}
