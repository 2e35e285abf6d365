"""The published defaults: the packaged copy of params.yaml, and the public functions that take it by default."""

import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from poseintegrity.config import PACKAGED_PARAMS, default_params, load_params
from poseintegrity.config import published
from poseintegrity.localization.features import detect_features
from poseintegrity.localization.matching import match_ratio_test
from poseintegrity.tracking.filter.multi_tool import MultiToolTracker
from poseintegrity.tracking.filter.tracker import MarkerTracker
from poseintegrity.tracking.markers.correspondence import match_markers
from poseintegrity.tracking.markers.detection import detect_markers
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M
from poseintegrity.tracking.simulation.frames import intrinsics, render_frame, unit_plane_lut

from tracking.track_section import GEOMETRY

ROOT = Path(__file__).resolve().parents[1]


def test_packaged_copy_is_the_repository_params_yaml_byte_for_byte():
    assert PACKAGED_PARAMS.read_bytes() == (ROOT / "params.yaml").read_bytes(), (
        "src/poseintegrity/params.yaml must be a copy of params.yaml: cp params.yaml src/poseintegrity/params.yaml")


def test_packaged_copy_is_package_data():
    package_data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    assert "params.yaml" in package_data["poseintegrity"]


def test_load_params_without_a_path_gives_the_repository_values():
    ours = load_params()
    assert ours is default_params() and ours is load_params()  # validated once per process
    assert ours == load_params(ROOT / "params.yaml")
    # the mesh is named poseintegrity:assets/...: the same file from either copy, wherever the package lies
    assert ours.generate.scapula.mesh == PACKAGED_PARAMS.parent / "assets" / "scapula_left.stl"
    assert ours.generate.scapula.mesh.is_file()


def test_published_walks_dotted_keys():
    assert published("track.detection") is default_params().track.detection
    assert published("extract.ratio_test") == default_params().extract.ratio_test
    with pytest.raises(AttributeError):
        published("track.no_such_section")


def _frame():
    camera = default_params().track.camera
    ir, depth = render_frame(GEOMETRY + [0.0, 0.0, 0.45], [], camera, default_params().track.frames,
                             MARKER_DIAMETER_M / 2, np.random.default_rng(3))
    return ir, depth, unit_plane_lut(intrinsics(camera), camera.width, camera.height)


def test_tracking_entry_points_take_the_published_sections_and_explicit_ones_override():
    ir, depth, lut = _frame()
    track = default_params().track
    points = detect_markers(ir, depth, lut)
    np.testing.assert_array_equal(points, detect_markers(ir, depth, lut, track.detection))
    assert len(points) == len(GEOMETRY)
    huge_blobs_only = track.detection.model_copy(update={"min_area": 999.0})  # explicit params win: no blob is that big
    assert len(detect_markers(ir, depth, lut, huge_blobs_only)) == 0

    assignment = match_markers(points, GEOMETRY)
    np.testing.assert_array_equal(assignment, match_markers(points, GEOMETRY, None, track.matching))
    assert sorted(assignment) == list(range(len(GEOMETRY)))

    tracker, explicit = MarkerTracker(GEOMETRY), MarkerTracker(GEOMETRY, track.filter, track.matching)
    a, b = tracker.frame(0.0, points), explicit.frame(0.0, points)
    assert a.flag == b.flag and np.array_equal(a.T_filtered, b.T_filtered, equal_nan=True)
    assert MultiToolTracker({"probe": GEOMETRY}).frame(0.0, points)["probe"].flag == a.flag


def test_localization_entry_points_take_the_published_sections():
    rng = np.random.default_rng(5)
    image = (rng.random((120, 160)) * 255).astype(np.uint8)
    extract = default_params().extract
    ours, explicit = detect_features(image), detect_features(image, extract.clahe, extract.sift)
    np.testing.assert_array_equal(ours.points, explicit.points)
    assert len(ours.points) > 0
    train = ours.descriptors
    query = (train[:20] + rng.normal(0.0, 20.0, train[:20].shape)).astype(np.float32)  # near, not on, a model point
    np.testing.assert_array_equal(match_ratio_test(query, train), match_ratio_test(query, train, extract.ratio_test))
    assert not np.array_equal(match_ratio_test(query, train, 0.05), match_ratio_test(query, train, 0.99))


def test_a_fresh_interpreter_outside_the_repository_detects_markers_with_no_params_file(tmp_path):
    """A plain import, no params.yaml in the working directory: the packaged copy is the default."""
    code = ("import numpy as np; from poseintegrity.tracking import detect_markers; "
            "from poseintegrity.config import default_params; "
            "ir = np.zeros((8, 8), np.uint8); depth = np.full((8, 8), 400.0); lut = np.zeros((8, 8, 2)); "
            "print(len(detect_markers(ir, depth, lut)), default_params().track.detection.threshold)")
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["0", str(default_params().track.detection.threshold)]
