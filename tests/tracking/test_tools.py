import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity.tracking.markers.geometry import transform_points
from poseintegrity.tracking.markers.kabsch import pose_from_points
from poseintegrity.tracking.filter.multi_tool import MultiToolTracker
from poseintegrity.tracking.io.tool_files import read_tools, write_tools
from poseintegrity.tracking.markers.tools import ToolError

from tracking.track_section import GEOMETRY, TRACK

SECOND = np.array(TRACK.evaluation.second_tool)
TOOLS = {"probe": GEOMETRY, "needle": SECOND}


def test_json_and_csv_tool_files_round_trip(tmp_path):
    write_tools(tmp_path / "tools.json", TOOLS)
    rows = [{"tool": name, "x": p[0], "y": p[1], "z": p[2]} for name, m in TOOLS.items() for p in m]
    pd.DataFrame(rows).to_csv(tmp_path / "tools.csv", index=False)
    for path in (tmp_path / "tools.json", tmp_path / "tools.csv"):
        tools = read_tools(path, 0.001)
        assert list(tools) == ["probe", "needle"]
        np.testing.assert_array_equal(tools["needle"], SECOND)


def test_duplicate_distances_are_refused_naming_the_pairs(tmp_path):
    square = np.array([[0, 0, 0], [0.05, 0, 0], [0.05, 0.05, 0], [0, 0.05, 0]], float)  # four sides of 50 mm
    write_tools(tmp_path / "square.json", {"square": square})
    with pytest.raises(ToolError, match="square markers 1-2 = 50.00 mm and square markers"):
        read_tools(tmp_path / "square.json", 0.001)
    shifted = GEOMETRY * (62.6 + 0.5) / 62.6  # its 1-3 distance lands 0.5 mm from the probe's
    write_tools(tmp_path / "two.json", {"probe": GEOMETRY, "copy": shifted})
    with pytest.raises(ToolError, match="probe markers .* and copy markers"):
        read_tools(tmp_path / "two.json", 0.001)
    (tmp_path / "bad.json").write_text('{"tools": [{"name": "a"}]}')
    with pytest.raises(ToolError, match="bad.json: tools\\[0\\] needs the fields name and markers_body"):
        read_tools(tmp_path / "bad.json", 0.001)


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
