"""``python -m poseintegrity.recorded validate`` and the reader behind it, on exported stage-01 datasets with one
thing broken at a time: every problem one line naming the file and field, exit status 2, no traceback; a good folder
exit 0 and one summary line. Known answers: theta and x computed from the poses are the synthetic scene's exact
stop positions."""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest

from poseintegrity.recorded.reader import RecordedFormatError, read_recorded
from recorded_tools import run


@pytest.fixture
def folder(exported, tmp_path) -> Path:
    """A fresh copy of the exported arc dataset."""
    return Path(shutil.copytree(exported / "arc_r", tmp_path / "arc_r"))


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


def test_a_good_folder_passes_with_one_summary_line(exported):
    status, out, err = run(["validate", str(exported / "arc_r"), str(exported / "line_r")])
    assert status == 0 and err == ""
    lines = out.strip().splitlines()
    assert len(lines) == 3 and "6 images at 3 stops" in lines[0] and "2 images at 2 stops" in lines[1]
    assert lines[2].startswith("range ends, tolerances and extract settings of ")  # ./params.yaml, or the published


def test_tables_saved_with_a_byte_order_mark_read_as_without(folder):
    """Excel's "CSV UTF-8" (and Notepad's UTF-8) start the file with a byte-order mark: it stuck to the first column's
    name and the table was refused for a "missing column" it has."""
    plain = read_recorded(folder)
    for name in ("stops.csv", "model.csv", "dataset.yaml", "board.yaml"):
        path = folder / name
        path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    marked = read_recorded(folder)
    rows = lambda recorded: [(f.file, f.stop, f.image, f.theta_deg, f.x_mm) for f in recorded.frames]  # noqa: E731
    assert rows(marked) == rows(plain) and marked.board == plain.board and marked.model_images == plain.model_images
    (folder / "stops.csv").write_bytes(b"\xef\xbb\xbf")
    with pytest.raises(RecordedFormatError, match="stops.csv: the table is empty"):
        read_recorded(folder)


def rewrite_csv(path: Path, transform) -> None:
    lines = path.read_text().splitlines()
    path.write_text("\n".join(transform(lines)) + "\n")


def drop_column(lines: list[str], column: str) -> list[str]:
    header = lines[0].split(",")
    index = header.index(column)
    return [",".join(cell for i, cell in enumerate(line.split(",")) if i != index) for line in lines]


@pytest.mark.parametrize("name, theta, x", [("arc_r", [10, 10, 25, 25, 40, 40], [0] * 6), ("line_r", [0, 0], [0, 60])])
def test_positions_computed_from_poses_are_the_scenes(exported, tmp_path, name, theta, x):
    """Without the columns, the positions come from the poses: the synthetic scene's exact ones (loc_synthetic's
    arc_pose / shifted). theta: the rotation angle from model image 0's pose; x of a line: the distance from its first
    position (the paper's x_i; loc_synthetic's own table counts from the model view: 20 and 80 mm)."""
    folder = Path(shutil.copytree(exported / name, tmp_path / name))
    rewrite_csv(folder / "stops.csv", lambda lines: drop_column(drop_column(lines, "theta_deg"), "x_mm"))
    frames = read_recorded(folder).frames
    assert np.allclose([frame.theta_deg for frame in frames], theta, atol=1e-9)
    assert np.allclose([frame.x_mm for frame in frames], x, atol=1e-9)


def empty_cell(lines: list[str], row: int, column: str) -> list[str]:
    """``lines`` of a table (no quoted commas) with the cell of ``column`` on line index ``row`` emptied."""
    index = lines[0].split(",").index(column)
    cells = lines[row].split(",")
    return [*lines[:row], ",".join(cells[:index] + [""] + cells[index + 1:]), *lines[row + 1:]]


def problems_of(folder: Path) -> list[str]:
    status, out, err = run(["validate", str(folder)])
    assert status == 2 and out == "" and "Traceback" not in err
    return err.strip().splitlines()


def test_missing_image(folder):
    (folder / "images" / "s01_i00.png").unlink()
    [line] = problems_of(folder)
    assert "stops.csv, line 4, field file" in line and "s01_i00.png is missing" in line


def test_extra_image(folder):
    shutil.copyfile(folder / "images" / "s00_i00.png", folder / "images" / "stray.png")
    [line] = problems_of(folder)
    assert "stray.png" in line and "extra image" in line


@pytest.mark.parametrize("old, new, field", [
    ("- 600.0\n  - 0.0\n  - 320.0", "- -600.0\n  - 0.0\n  - 320.0", "camera_matrix"),
    ("- 600.0\n  - 0.0\n  - 320.0", "- 0.0\n  - 0.0\n  - 320.0", "camera_matrix"),
    ("distortion_model: plumb_bob", "distortion_model: equidistant", "distortion_model"),
])
def test_bad_camera_yaml(folder, old, new, field):
    edit(folder / "camera.yaml", old, new)
    [line] = problems_of(folder)
    assert "camera.yaml" in line and f"field {field}" in line


def test_a_rational_polynomial_camera_is_accepted(folder):
    edit(folder / "camera.yaml", "distortion_model: plumb_bob", "distortion_model: rational_polynomial")
    edit(folder / "camera.yaml", "cols: 5", "cols: 8")
    edit(folder / "camera.yaml", "  - 0.0\n  - 0.0\n  - 0.0\n  - 0.0\n  - 0.0\n",
         "  - 0.0\n  - 0.0\n  - 0.0\n  - 0.0\n  - 0.0\n  - 0.0\n  - 0.0\n  - 0.0\n")
    assert len(read_recorded(folder).camera.dist) == 8


def test_stops_not_monotonic(folder):
    """Rows of stop 0 after stop 1 (stop indices go back), and a stop whose theta does not lie beyond the last."""
    rewrite_csv(folder / "stops.csv", lambda lines: [lines[0], *lines[3:5], *lines[1:3], *lines[5:]])
    lines = problems_of(folder)
    assert any("line 4: field stop: stops not monotonic" in line for line in lines)
    rewrite_csv(folder / "stops.csv", lambda lines: [lines[0], *lines[3:5], *lines[1:3], *lines[5:]])  # restored
    edit(folder / "stops.csv", ",40.0,", ",20.0,")
    edit(folder / "stops.csv", ",40.0,", ",20.0,")
    [line] = problems_of(folder)
    assert "stops.csv: field theta_deg: stops not monotonic, stop 2" in line


def test_a_board_that_never_appears(folder):
    """board.yaml naming markers 20..25: OpenCV's ArUco detector finds none of them in model image 0."""
    edit(folder / "board.yaml", "first_id: 0", "first_id: 20")
    [line] = problems_of(folder)
    assert "board.yaml" in line and "not found in model image model/image_0.png" in line


def test_an_image_of_another_size(folder):
    image = cv2.imread(str(folder / "images" / "s02_i01.png"), cv2.IMREAD_UNCHANGED)
    cv2.imwrite(str(folder / "images" / "s02_i01.png"), image[:-10])
    [line] = problems_of(folder)
    assert "line 7, field file" in line and "640 x 390 px, camera.yaml says 640 x 400 px" in line


@pytest.mark.parametrize("content, words", [(b"", "empty (0 bytes)"), (b"\x89PNG\r\n\x1a\n" + bytes(100), "damaged")])
def test_a_damaged_or_empty_image(folder, content, words):
    (folder / "model" / "mask_1.png").write_bytes(content)
    [line] = problems_of(folder)
    assert "model.csv, line 3, field mask" in line and words in line


def test_every_problem_is_listed_at_once(folder):
    (folder / "images" / "s01_i00.png").unlink()
    edit(folder / "camera.yaml", "distortion_model: plumb_bob", "distortion_model: fisheye")
    edit(folder / "dataset.yaml", "trajectory: arc", "trajectory: circle")
    lines = problems_of(folder)
    assert len(lines) == 3
    assert any("dataset.yaml: field trajectory" in line for line in lines)
    with pytest.raises(RecordedFormatError) as info:
        read_recorded(folder)
    assert info.value.problems == lines and isinstance(info.value, ValueError)


def test_pose_ground_truth_needs_poses_on_every_row(folder):
    edit(folder / "dataset.yaml", "ground_truth: board", "ground_truth: poses")
    (folder / "board.yaml").unlink()
    rewrite_csv(folder / "stops.csv", lambda lines: empty_cell(lines, 2, "T_cam_ref"))
    [line] = problems_of(folder)
    assert "stops.csv, line 3: field T_cam_ref is empty" in line


@pytest.mark.parametrize("file, old, new, words", [
    ("stops.csv", "images/s00_i01.png,0,", "images/s00_i01.png,0,1.0,", "stops.csv, line 3: 1 cell(s) more than"),
    ("stops.csv", "images/s00_i01.png,0,", "images/s00_i01.png,zero,", "stops.csv, line 3: field stop: expected"),
    ("stops.csv", "images/s01_i00.png,1,25.0,", "images/s01_i00.png,1,nan,", "line 4: field theta_deg: expected a fin"),
    ("dataset.yaml", "T_cam1_cam0:", "T_cam1_cam0: [[1, 2], [3]]\nunused:", "dataset.yaml: unknown field(s) unused"),
    ("dataset.yaml", "world: main", "world: main\ncolour: red", "dataset.yaml: unknown field(s) colour"),
    ("board.yaml", "markers_x: 3", "markers_x: 0", "board.yaml: field markers_x"),
    ("board.yaml", "dictionary: DICT_4X4_50", "dictionary: DICT_9X9_1", "board.yaml: field dictionary"),
])
def test_bad_table_and_yaml_fields(folder, file, old, new, words):
    edit(folder / file, old, new)
    assert any(words in line for line in problems_of(folder))


def test_ragged_model_baseline_is_refused_naming_the_field(folder):
    text = (folder / "dataset.yaml").read_text()
    (folder / "dataset.yaml").write_text(text.split("T_cam1_cam0:")[0] + "T_cam1_cam0: [[1, 2], [3]]\n")
    [line] = problems_of(folder)
    assert "dataset.yaml: field T_cam1_cam0 is not 16 numbers" in line


def test_export_command(rendered_dir, tmp_path):
    status, out, _ = run(["export", str(rendered_dir), "--out", str(tmp_path / "out")])
    assert status == 0 and "exported 2 dataset(s)" in out
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["arc_r", "line_r"]
    status, out, err = run(["export", str(tmp_path / "nothing"), "--out", str(tmp_path / "out2")])
    assert status == 2 and len(err.strip().splitlines()) == 1 and "index.parquet is missing" in err


def test_not_a_folder(tmp_path):
    [line] = problems_of(tmp_path / "nothing")
    assert "nothing: not a folder" in line


def test_the_robots_poses_go_in_both_tables_or_in_neither(folder):
    """The export of a rendered dataset carries the robot's log (T_base_cam); without model.csv's, model image 0
    cannot place the target in the robot's base frame; a damaged cell is named by line and field."""
    assert "T_base_cam" in (folder / "model.csv").read_text().splitlines()[0]
    rewrite_csv(folder / "model.csv", lambda lines: drop_column(lines, "T_base_cam"))
    [line] = problems_of(folder)
    assert "model.csv: column T_base_cam is needed too" in line
    rewrite_csv(folder / "stops.csv", lambda lines: drop_column(lines, "T_base_cam"))
    assert read_recorded(folder).model_T_base_cam is None  # neither: a recording without the robot's poses


def test_a_damaged_robot_pose_is_named(folder):
    rewrite_csv(folder / "stops.csv", lambda lines: [*lines[:3], lines[3].rsplit(",", 1)[0] + ",1 2 3", *lines[4:]])
    assert (folder / "stops.csv").read_text().splitlines()[0].endswith(",T_base_cam")  # the cell replaced is its
    [line] = problems_of(folder)
    assert "stops.csv, line 4: field T_base_cam" in line
