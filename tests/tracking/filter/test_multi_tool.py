import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity.tracking.filter.multi_tool import MultiToolTracker
from poseintegrity.tracking.markers.geometry import transform_points
from poseintegrity.tracking.markers.kabsch import pose_from_points
from poseintegrity.tracking.markers.tools import ToolError

from tracking.track_section import GEOMETRY, SECOND, TRACK

TOOLS = {"probe": GEOMETRY, "needle": SECOND}
POINTS = GEOMETRY + [0.0, 0.0, 0.45]


def test_two_tools_with_phantoms_are_told_apart_one_filter_each():
    rng = np.random.default_rng(0)
    tracker = MultiToolTracker(TOOLS, TRACK.filter, TRACK.matching)
    for k in range(20):
        t = 0.046 * k
        poses = {name: pose_from_points(m @ Rotation.from_rotvec([0.4 * t, 0.1 * i, -0.3 * t]).as_matrix().T + [0.08 * (2 * i - 1), 0, 0.5], m)
                 for i, (name, m) in enumerate(TOOLS.items())}
        points = np.vstack([transform_points(poses[n], m) for n, m in TOOLS.items()] + [rng.uniform(-0.2, 0.2, (3, 3)) + [0, 0, 0.5]])
        points = points[rng.permutation(len(points))] + rng.normal(0, 0.0005, points.shape)
        results = tracker.frame(t, points)
        for name, result in results.items():
            assert result.flag in ("initialized", "ok")
            np.testing.assert_allclose(result.T_measured[:3, 3], poses[name][:3, 3], atol=0.003)
        used = np.concatenate([r.assignment[r.assignment >= 0] for r in results.values()])
        assert len(used) == len(set(used)) == 8  # every marker point used once, no phantom used


def test_multi_tool_tracker_refuses_empty_duplicated_and_unknown_tools():
    with pytest.raises(ToolError, match="no tools given"):
        MultiToolTracker({}, TRACK.filter, TRACK.matching)
    with pytest.raises(ToolError, match="tool name 'a' appears more than once"):
        MultiToolTracker([("a", GEOMETRY), ("a", SECOND)], TRACK.filter, TRACK.matching)
    with pytest.raises(ToolError, match=r"gyro_tool: 'nope' names no tool; the tools are \['probe'\]"):
        MultiToolTracker({"probe": GEOMETRY}, TRACK.filter, TRACK.matching, gyro_tool="nope")
    with pytest.raises(ToolError, match="needs at least 3 rows, got 2"):
        MultiToolTracker({"probe": GEOMETRY[:2]}, TRACK.filter, TRACK.matching)


def test_a_frame_without_detections_is_flagged_and_tracking_recovers():
    tracker = MultiToolTracker({"probe": GEOMETRY, "needle": SECOND}, TRACK.filter, TRACK.matching)
    both = np.vstack([POINTS, SECOND + [0.1, 0.0, 0.5]])
    assert {r.flag for r in tracker.frame(0.0, both).values()} == {"initialized"}
    for k, empty in enumerate([np.zeros((0, 3)), np.full((3, 3), np.nan)]):  # a hand over the tools
        results = tracker.frame(0.05 * (k + 1), empty)
        assert {r.flag for r in results.values()} <= {"no_points", "no_markers"}
        assert all(np.isfinite(r.T_filtered).all() for r in results.values())  # the filters keep predicting
    assert tracker.frame(0.15, POINTS)["needle"].flag == "no_points"  # probe took every point: no IndexError
    assert {r.flag for r in tracker.frame(0.2, both).values()} == {"ok"}
