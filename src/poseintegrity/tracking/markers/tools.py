"""Several tools tracked at once (beyond the paper; HoloLens IR trackers such as STTAR and HoloLens2-IRTracking
track several, docs/references.md): the check that a tool set can be tracked. Every inter-marker distance must be
distinct across all tools, since Alg. 2 votes by distance (a shared distance lets one tool's pair vote for
another's); each tool needs 3 or more markers not on one line.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from poseintegrity.errors import ArgumentError, PoseIntegrityError, check_array
from poseintegrity.params.track import tool_geometry_problem
from poseintegrity.tracking.markers.geometry import pairwise_distances


class ToolError(PoseIntegrityError):
    """A tool file or tool set that cannot be used: unreadable, too few markers, or distances that are not distinct."""


def check_distinct_distances(tools: dict[str, np.ndarray], distinct_m: float, source: str = "tools") -> None:
    """Raise :class:`ToolError` saying why the tools (name -> (m, 3) metres) cannot be told apart or posed:
    fewer than 3 markers, markers on one line, or two inter-marker distances (within a tool or across tools)
    within distinct_m (m) of each other (:func:`~poseintegrity.params.track.tool_geometry_problem`).
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
