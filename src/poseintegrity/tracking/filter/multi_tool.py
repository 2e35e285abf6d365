"""Several tools at once (ours): one :class:`~poseintegrity.tracking.filter.tracker.MarkerTracker` per tool, fed by
the same frames, the tool set checked once (:func:`~poseintegrity.tracking.markers.tools.check_tools`)."""

from __future__ import annotations

import numpy as np

from poseintegrity.config import published
from poseintegrity.params.track import FilterParams, MatchingParams
from poseintegrity.tracking.filter.tracker import FrameResult, MarkerTracker, check_points, check_rates
from poseintegrity.tracking.io.timestamps import check_timestamp
from poseintegrity.tracking.markers.tools import ToolError, check_tools


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
        return self.frame_unchecked(check_timestamp(t), check_points(points))

    def frame_unchecked(self, t: float, points: np.ndarray) -> dict[str, FrameResult]:
        """:meth:`frame` on checked arguments (t as :func:`check_timestamp` returns it, points float (n, 3) metres)."""
        free = np.ones(len(points), dtype=bool)
        results = {}
        for name, tracker in self.trackers.items():
            index = np.flatnonzero(free)
            result = tracker.frame_unchecked(t, points[index])
            assignment = result.assignment.copy()
            hit = assignment >= 0
            assignment[hit] = index[assignment[hit]]  # back to rows of points (no hit: nothing to index)
            free[assignment[hit]] = False
            results[name] = FrameResult(assignment, result.T_measured, result.T_filtered, result.flag)
        return results

    def gyro(self, t: float, omega_body: np.ndarray) -> dict[str, str]:
        """A gyro sample (rad/s, body frame of gyro_tool): fused by that tool's filter; the others only advance."""
        return self.gyro_unchecked(check_timestamp(t), check_rates(omega_body))

    def gyro_unchecked(self, t: float, omega_body: np.ndarray) -> dict[str, str]:
        """:meth:`gyro` on checked arguments (t as :func:`check_timestamp` returns it, omega_body float (3,) rad/s)."""
        return {name: tracker.gyro_unchecked(t, omega_body) for name, tracker in self.trackers.items()}
