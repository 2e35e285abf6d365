"""The recorded-data command lines check their destination before any work and leave nothing half-written:
`--out` an existing file or a folder with anything in it is refused naming it, and what is there stays as it was;
`export` is all or nothing; no staging folder survives an error. And camera.yaml of a ROS bag keeps the bag's P."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
import yaml

from poseintegrity.atomic_write import DestinationError
from poseintegrity.lens import read_camera_yaml
from poseintegrity.recorded.export import export_all
from recorded_tools import bag_inputs, run, write_bag


def user_folder(tmp_path):
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "notes.txt").write_text("the user's own file")
    return folder


def left_over(tmp_path) -> list[str]:
    return sorted(path.name for path in tmp_path.rglob(".*.partial"))


@pytest.fixture
def bag(exported, tmp_path):
    folder = exported / "line_r"
    files, stops = bag_inputs(folder, tmp_path)
    return write_bag(tmp_path / "run", 2, [f.read_bytes() for f in files], read_camera_yaml(folder / "camera.yaml")), stops


def import_argv(bag, stops, out) -> list[str]:
    return ["import-rosbag", str(bag), "--image-topic", "/camera/image", "--info-topic", "/camera/camera_info",
            "--stops", str(stops), "--out", str(out), "--trajectory", "line"]


def test_import_rosbag_refuses_a_folder_with_the_users_files_and_keeps_them(bag, tmp_path):
    mine = user_folder(tmp_path)
    status, _, err = run(import_argv(*bag, mine))
    assert status == 2 and err.strip() == (f"--out {mine}: the folder is not empty (1 entries: notes.txt); give a new "
                                           f"or empty folder (nothing of it is replaced)")
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"] and not left_over(tmp_path)
    empty = tmp_path / "empty"
    empty.mkdir()
    assert run(import_argv(*bag, empty))[0] == 0 and (empty / "stops.csv").is_file()  # an empty folder is fine


def test_import_rosbag_refuses_a_file_in_one_line_and_leaves_no_staging_folder(bag, tmp_path):
    target = tmp_path / "a_file"
    target.write_text("mine")
    status, _, err = run(import_argv(*bag, target))
    assert status == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert f"--out {target}: exists and is not a folder" in err
    assert target.read_text() == "mine" and not left_over(tmp_path)


def test_an_info_topic_without_a_message_is_named(exported, tmp_path):
    folder = exported / "line_r"
    files, stops = bag_inputs(folder, tmp_path)
    silent = write_bag(tmp_path / "silent", 2, [f.read_bytes() for f in files], read_camera_yaml(folder / "camera.yaml"),
                       with_info=False)
    status, _, err = run(import_argv(silent, stops, tmp_path / "out"))
    assert status == 2 and "topic '/camera/camera_info' holds no message" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists() and not left_over(tmp_path)


def test_camera_yaml_keeps_the_bags_projection_matrix(exported, tmp_path):
    """A rectified camera's P is not [K|0]: a stereo right camera's carries -fx * baseline in P[0, 3]."""
    folder = exported / "line_r"
    files, stops = bag_inputs(folder, tmp_path)
    camera = read_camera_yaml(folder / "camera.yaml")
    P = np.hstack([camera.K * [[0.98], [0.98], [1.0]], [[-0.98 * camera.K[0, 0] * 0.12], [0.0], [0.0]]])
    bag = write_bag(tmp_path / "stereo", 2, [f.read_bytes() for f in files], camera, projection=P)
    assert run(import_argv(bag, stops, tmp_path / "out"))[0] == 0
    info = yaml.safe_load((tmp_path / "out" / "camera.yaml").read_text())
    assert info["projection_matrix"] == {"rows": 3, "cols": 4, "data": P.ravel().tolist()}
    assert info["camera_matrix"]["data"] == camera.K.ravel().tolist()


def test_export_refuses_a_used_folder_and_is_all_or_nothing(rendered_dir, tmp_path):
    mine = user_folder(tmp_path)
    status, _, err = run(["export", str(rendered_dir), "--out", str(mine)])
    assert status == 2 and f"--out {mine}: the folder is not empty" in err
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]
    broken = tmp_path / "data"
    shutil.copytree(rendered_dir, broken)
    (broken / "datasets" / "line_r" / "meta.json").write_text("{")  # the second dataset of the index is damaged
    with pytest.raises(Exception, match="meta.json"):
        export_all(broken, tmp_path / "out")
    assert not (tmp_path / "out").exists() and not left_over(tmp_path)  # not even the first dataset
    with pytest.raises(DestinationError, match="exists and is not a folder"):
        export_all(rendered_dir, tmp_path / "mine" / "notes.txt")
