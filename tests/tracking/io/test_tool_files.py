import json

import numpy as np
import pandas as pd
import pytest

from poseintegrity.tracking.io.tool_files import read_tools, write_tools
from poseintegrity.tracking.markers.tools import ToolError

from tracking.track_section import GEOMETRY, SECOND

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


def _write_tool(path, content):
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    return path


@pytest.mark.parametrize("name, content, message", [
    ("few.json", json.dumps({"tools": [{"name": "a", "markers_body": GEOMETRY[:2].tolist()}]}), "tool 'a'.* at least 3 rows, got 2"),
    ("dup.json", json.dumps({"tools": [{"name": "a", "markers_body": [GEOMETRY[0].tolist()] + GEOMETRY.tolist()}]}), "markers 1 and 2 at the same place"),
    ("nan.json", json.dumps({"tools": [{"name": "a", "markers_body": (GEOMETRY * [1, 1, np.nan]).tolist()}]}), "tool 'a'.* must be finite"),
    ("names.json", json.dumps({"tools": [{"name": "a", "markers_body": GEOMETRY.tolist()}, {"name": "a", "markers_body": SECOND.tolist()}]}), "'a' appears more than once"),
    ("none.json", json.dumps({"tools": []}), "no tools given"),
    ("zero.json", b"", "the tool file is empty"),
    ("zero.csv", b"", "the tool file is empty"),
    ("binary.json", bytes(range(256)) * 4, "not UTF-8 text"),
    ("binary.csv", b"tool,x,y,z\x00\x01\x02\n", "NUL bytes"),
    ("latin1.csv", "tool,x,y,z\n\xe9,0,0,0\n".encode("latin-1"), "not UTF-8 text"),
    ("few.csv", "tool,x,y,z\na,0,0,0\na,0.01,0,0\n", "at least 3 rows, got 2"),
    ("text.csv", "tool,x,y,z\na,0,0,0\na,0.01,0,0\na,abc,0.02,0\n", "x of row 3 is not a number"),
    ("split.csv", "tool,x,y,z\n" + "".join(f"a,{x},{y},{z}\n" for x, y, z in GEOMETRY[:3]) + "b,0,0,0\na,0.1,0.1,0.1\n", "'a' appears again at row 5"),
])
def test_bad_tool_files_are_refused_naming_the_file(tmp_path, name, content, message):
    path = _write_tool(tmp_path / name, content)
    with pytest.raises(ToolError, match=f"{name}: .*{message}"):
        read_tools(path, 0.001)


def test_a_missing_tool_file_is_refused_naming_it(tmp_path):
    with pytest.raises(ToolError, match="nope.json: cannot read the tool file"):
        read_tools(tmp_path / "nope.json", 0.001)
