"""Recorded folders into stage 02's layout. The round trip is the test: stage-01 datasets exported to the recorded
format and materialized back give stage 02 (extract_dataset) artifact rows identical to the originals', value for
value; images stored in colour, 16 bit or TIFF arrive as the same 8-bit gray pixels; with pose ground truth the
recorded poses are the truth; an interrupted run leaves nothing that looks complete."""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

from poseintegrity.boards import board_from_dict
from poseintegrity.localization.dataset import load_dataset, load_index
from poseintegrity.localization.extract import extract_dataset
from poseintegrity.recorded import materialize as materialize_module
from poseintegrity.recorded.materialize import materialize
from poseintegrity.recorded.reader import RecordedFormatError
from recorded_tools import assert_rows_identical
from sift_cache import copy_sift_features

METHODS = ["epnp", "sqpnp"]


def extract(data_dir: Path, name: str, params, workers) -> pd.DataFrame:
    return extract_dataset(data_dir, f"datasets/{name}", params, METHODS, workers, progress=False)


def copy(exported: Path, tmp_path: Path, name: str) -> Path:
    return Path(shutil.copytree(exported / name, tmp_path / "recorded" / name))


@pytest.fixture(scope="module")
def materialized(exported, tmp_path_factory) -> Path:
    data_dir = tmp_path_factory.mktemp("materialized")
    materialize(sorted(exported.iterdir()), data_dir)
    return data_dir


@pytest.mark.parametrize("name", ["arc_r", "line_r"])
def test_round_trip_gives_identical_artifact_rows(rendered_dir, materialized, extract_params, workers, name):
    original = extract(rendered_dir, name, extract_params, workers)
    again = extract(materialized, name, extract_params, workers)
    assert (original["status"] == "ok").mean() > 0.5  # the rows carry localizations, not only failures
    assert_rows_identical(original, again)


def test_round_trip_keeps_images_meta_and_index(rendered_dir, materialized):
    index = load_index(materialized)
    assert list(index["dataset"]) == ["arc_r", "line_r"] and list(index["n_frames"]) == [6, 2]
    original, again = load_dataset(rendered_dir, "datasets/arc_r"), load_dataset(materialized, "datasets/arc_r")
    for a, b in zip(original.frames.itertuples(), again.frames.itertuples()):
        assert (a.stop, a.image, a.theta_deg, a.x_mm) == (b.stop, b.image, b.theta_deg, b.x_mm)
        assert list(a.T_cam_board) == list(b.T_cam_board)
        assert original.path(a.file).read_bytes() == again.path(b.file).read_bytes()
    assert np.array_equal(original.model_baseline(), again.model_baseline())
    assert board_from_dict(again.meta["board"]) == board_from_dict(original.meta["board"])  # written with its type
    assert again.meta["ground_truth"] == "board"


def test_colour_16_bit_and_tiff_images_are_converted_once(exported, materialized, tmp_path):
    """Stored as BGR PNG (equal channels), 16-bit TIFF (value * 257) and BGRA PNG, the images arrive as the same 8-bit
    gray pixels (OpenCV's gray weights sum to 1; the high byte of v * 257 is v)."""
    folder = copy(exported, tmp_path, "line_r")
    files = {"images/s00_i00.png": "bgr", "images/s01_i00.png": "tiff16", "model/image_1.png": "bgra"}
    for file, kind in files.items():
        gray = cv2.imread(str(folder / file), cv2.IMREAD_UNCHANGED)
        (folder / file).unlink()
        if kind == "tiff16":
            cv2.imwrite(str(folder / "images" / "s01_i00.tif"), gray.astype(np.uint16) * 257)
        else:
            cv2.imwrite(str(folder / file), cv2.cvtColor(gray, cv2.COLOR_GRAY2BGR if kind == "bgr" else cv2.COLOR_GRAY2BGRA))
    (folder / "stops.csv").write_text((folder / "stops.csv").read_text().replace("s01_i00.png", "s01_i00.tif"))
    materialize([folder], tmp_path / "data")
    for file, target in (("images/s00_i00.png", "images/s00_i00.png"), ("images/s01_i00.png", "images/s01_i00.png"),
                         ("model/image_1.png", "model/model_1.png")):
        expected = cv2.imread(str(exported / "line_r" / file), cv2.IMREAD_UNCHANGED)
        assert np.array_equal(cv2.imread(str(tmp_path / "data/datasets/line_r" / target), cv2.IMREAD_UNCHANGED),
                              expected)


def test_a_jpeg_image_is_decoded_as_opencv_decodes_it(exported, tmp_path):
    """A stop stored as JPEG (lossy): materialized, its pixels are cv2.imdecode's of the JPEG bytes (the reference),
    written as a lossless PNG."""
    folder = copy(exported, tmp_path, "line_r")
    gray = cv2.imread(str(folder / "images/s01_i00.png"), cv2.IMREAD_UNCHANGED)
    (folder / "images/s01_i00.png").unlink()
    data = cv2.imencode(".jpg", gray, [cv2.IMWRITE_JPEG_QUALITY, 90])[1].tobytes()
    (folder / "images/s01_i00.jpg").write_bytes(data)
    (folder / "stops.csv").write_text((folder / "stops.csv").read_text().replace("s01_i00.png", "s01_i00.jpg"))
    materialize([folder], tmp_path / "data")
    expected = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
    again = cv2.imread(str(tmp_path / "data/datasets/line_r/images/s01_i00.png"), cv2.IMREAD_UNCHANGED)
    assert np.array_equal(again, expected) and not np.array_equal(expected, gray)  # lossy, yet read as OpenCV reads


def test_pose_ground_truth_replaces_the_board(rendered_dir, exported, extract_params, workers, tmp_path):
    """ground_truth: poses, no board.yaml: M_t is placed by model image 0's pose, E_t/E_r are measured against the
    recorded (here exact) poses, so they equal the _exact columns, and stay near the board-truth run's."""
    folder = copy(exported, tmp_path, "arc_r")
    (folder / "dataset.yaml").write_text((folder / "dataset.yaml").read_text().replace("ground_truth: board",
                                                                                       "ground_truth: poses"))
    (folder / "board.yaml").unlink()
    materialize([folder], tmp_path / "data")
    original = extract(rendered_dir, "arc_r", extract_params, workers)
    copy_sift_features(rendered_dir, tmp_path / "data", "arc_r", extract_params)  # the same images
    rows = extract(tmp_path / "data", "arc_r", extract_params, workers)
    assert set(rows["board_status"]) == {"no_board"}
    ok = rows["status"] == "ok"
    assert ok.sum() >= len(rows) // 2
    assert np.array_equal(rows["E_t_mm"], rows["E_t_exact_mm"], equal_nan=True)
    assert np.array_equal(rows["E_r_deg"], rows["E_r_exact_deg"], equal_nan=True)
    both = ok & (original["status"] == "ok")
    assert np.abs(rows.loc[both, "E_t_mm"] - original.loc[both, "E_t_exact_mm"]).max() < 1.0  # M_t placed alike


def test_board_truth_without_recorded_poses(rendered_dir, exported, extract_params, workers, tmp_path):
    """No T_cam_ref anywhere (T_cam1_cam0 in dataset.yaml, theta in stops.csv): frames are not flagged, the _exact
    errors are NaN and the board-truth errors are the original's."""
    folder = copy(exported, tmp_path, "arc_r")
    for table in ("stops.csv", "model.csv"):
        lines = [line.split(",") for line in (folder / table).read_text().splitlines()]
        drop = lines[0].index("T_cam_ref")
        (folder / table).write_text("\n".join(",".join(cells[:drop] + cells[drop + 1:]) for cells in lines) + "\n")
    materialize([folder], tmp_path / "data")
    original = extract(rendered_dir, "arc_r", extract_params, workers)
    copy_sift_features(rendered_dir, tmp_path / "data", "arc_r", extract_params)  # the same images
    rows = extract(tmp_path / "data", "arc_r", extract_params, workers)
    assert not rows["status"].isin(["bad_pose"]).any() and rows["E_t_exact_mm"].isna().all()
    pd.testing.assert_series_equal(rows["E_t_mm"], original["E_t_mm"], check_exact=True)


def test_bad_folders_are_refused_before_anything_is_written(exported, tmp_path):
    bad = copy(exported, tmp_path, "arc_r")
    (bad / "images" / "s00_i00.png").unlink()
    with pytest.raises(RecordedFormatError) as info:
        materialize([exported / "line_r", bad], tmp_path / "data")
    assert "s00_i00.png is missing" in str(info.value)
    assert not (tmp_path / "data").exists()


def test_an_interrupted_run_leaves_nothing_that_looks_complete(exported, tmp_path, monkeypatch):
    writes = []
    real = materialize_module._write_image

    def failing(source, target):
        writes.append(target)
        if len(writes) == 5:
            raise KeyboardInterrupt  # the run is stopped while the first dataset's images are written
        real(source, target)

    monkeypatch.setattr(materialize_module, "_write_image", failing)
    with pytest.raises(KeyboardInterrupt):
        materialize(sorted(exported.iterdir()), tmp_path / "data")
    assert list((tmp_path / "data" / "datasets").iterdir()) == []  # no dataset, no partial folder, no index
