"""Stage 02 checks its data on read: corrupted copies of the synthetic datasets give a clear DatasetError naming the
dataset and the file before any work, or (a bad frame) rows flagged with the reason; never a raw pandas / json /
OpenCV traceback, and never status "ok" on a frame that cannot be trusted."""

import json
import shutil

import cv2
import numpy as np
import pandas as pd
import pytest
import yaml

import loc_synthetic as synthetic
from poseintegrity.localization import extract as E
from poseintegrity.localization.dataset import DatasetError
from poseintegrity.localization.frame_rows import usable
from sift_cache import copy_sift_features

METHODS = ["usac_magsac"]
DATASET = "line_a"  # 2 stops x 2 images: quick to localize


@pytest.fixture(scope="module")
def sift_done(synthetic_data_dir, extract_params, workers, tmp_path_factory):
    """A copy of the line dataset, extracted once for the module: its SIFT features serve every case (SIFT on every
    image took three quarters of a case)."""
    once = tmp_path_factory.mktemp("sift_done")
    shutil.copytree(synthetic_data_dir / "datasets" / DATASET, once / "datasets" / DATASET)
    synthetic.write_index(once, [index_row(DATASET)])
    E.extract_all(once, extract_params, METHODS, workers, progress=False)
    return once


@pytest.fixture
def data_dir(synthetic_data_dir, sift_done, extract_params, tmp_path):
    """A copy of the line dataset and of the features it needs (its own index), with the SIFT features of its images
    as a re-run of stage 02 finds them (a damaged image's are computed anew; every frame is localized again)."""
    shutil.copytree(synthetic_data_dir / "datasets" / DATASET, tmp_path / "datasets" / DATASET)
    synthetic.write_index(tmp_path, [index_row(DATASET)])
    copy_sift_features(sift_done, tmp_path, DATASET, extract_params)
    return tmp_path


def index_row(name: str) -> dict:
    return dict(dataset=name, world="main", scene="synthetic", trajectory="line", azimuth_deg=0.0, offset_deg=0.0, n_frames=4,
                path=f"datasets/{name}")


def folder(data_dir):
    return data_dir / "datasets" / DATASET


def edit_meta(data_dir, change):
    meta = json.loads((folder(data_dir) / "meta.json").read_text())
    change(meta)
    (folder(data_dir) / "meta.json").write_text(json.dumps(meta))


def edit_camera(data_dir, change):
    camera = yaml.safe_load((folder(data_dir) / "camera.yaml").read_text())
    change(camera)
    (folder(data_dir) / "camera.yaml").write_text(yaml.safe_dump(camera))


def edit_frames(data_dir, change):
    frames = pd.read_parquet(folder(data_dir) / "frames.parquet")
    frames = change(frames)
    frames.to_parquet(folder(data_dir) / "frames.parquet")


def write_image(data_dir, relative, image):
    cv2.imwrite(str(folder(data_dir) / relative), image)


def frame_image(data_dir, relative="images/s01_i00.png"):
    return cv2.imread(str(folder(data_dir) / relative), cv2.IMREAD_UNCHANGED)


def nan_pose(frames, row=2):
    frames.at[row, "T_cam_board"] = np.full(16, np.nan)
    return frames


def scaled_pose(frames, row=2):
    frames.at[row, "T_cam_board"] = np.asarray(frames.at[row, "T_cam_board"]) * 1.1
    return frames


# A bad frame: rows of that frame flagged (status, text the reason holds), the other frames localized as usual.
FLAGGED = {
    "image twice the size": (lambda d: write_image(d, "images/s01_i00.png", cv2.resize(frame_image(d), (1280, 800))),
                             "bad_image", "1280 x 800 px, its dataset's camera.yaml says 640 x 400"),
    "image half the size": (lambda d: write_image(d, "images/s01_i00.png", cv2.resize(frame_image(d), (320, 200))),
                            "bad_image", "320 x 200 px"),
    "16-bit image": (lambda d: write_image(d, "images/s01_i00.png", frame_image(d).astype(np.uint16) * 256),
                     "bad_image", "16-bit with 1 channel(s), expected 8-bit gray"),
    "colour image": (lambda d: write_image(d, "images/s01_i00.png", cv2.cvtColor(frame_image(d), cv2.COLOR_GRAY2BGR)),
                     "bad_image", "3 channel(s)"),
    "text file named .png": (lambda d: (folder(d) / "images/s01_i00.png").write_text("hello"),
                             "bad_image", "not a readable image"),
    "truncated png": (lambda d: (folder(d) / "images/s01_i00.png").write_bytes(
        (folder(d) / "images/s01_i00.png").read_bytes()[:300]), "bad_image", "s01_i00.png"),
    "NaN ground-truth pose": (lambda d: edit_frames(d, nan_pose), "bad_pose", "T_cam_board of frames.parquet holds NaN"),
    "non-rigid ground-truth pose": (lambda d: edit_frames(d, scaled_pose), "bad_pose", "is not a rigid transform"),
}


@pytest.mark.parametrize("case", FLAGGED)
def test_a_bad_frame_gives_flagged_rows(data_dir, extract_params, workers, case):
    damage, status, reason = FLAGGED[case]
    damage(data_dir)
    rows = E.extract_all(data_dir, extract_params, METHODS, workers, progress=False)
    bad = rows[(rows.stop == 1) & (rows.image == 0)].iloc[0]
    assert bad.status == status and reason in bad.reason, bad.reason
    assert np.isnan(bad.E_t_mm) and np.isnan(bad.E_r_deg)  # never "ok" with an error nobody can trust
    others = rows.drop(bad.name)
    assert (others.status == "ok").all() and (others.reason == "").all()
    assert len(usable(rows)) == len(rows) - 1


def missing_frame_image(d):
    (folder(d) / "images/s00_i01.png").unlink()


def duplicate_frame_row(frames):
    return pd.concat([frames, frames.iloc[[1]]], ignore_index=True)


# Damage to a dataset (not to one frame): a DatasetError before any work, naming what the message must hold.
STOPS = {
    "model image twice the size": (
        lambda d: write_image(d, "model/image_1.png", cv2.resize(frame_image(d, "model/image_1.png"), (1280, 800))),
        ["dataset line_a", "model/image_1.png", "1280 x 800"]),
    "16-bit model mask": (
        lambda d: write_image(d, "model/mask_0.png", frame_image(d, "model/mask_0.png").astype(np.uint16)),
        ["dataset line_a", "mask_0.png", "16-bit"]),
    "text file as model image": (lambda d: (folder(d) / "model/image_0.png").write_text("x"),
                                 ["dataset line_a", "image_0.png", "not a readable image"]),
    "missing frame image": (missing_frame_image, ["dataset line_a", "s00_i01.png", "missing"]),
    "missing meta.json": (lambda d: (folder(d) / "meta.json").unlink(), ["dataset line_a", "meta.json is missing"]),
    "unreadable meta.json": (lambda d: (folder(d) / "meta.json").write_text("{not json"),
                             ["dataset line_a", "cannot read", "meta.json"]),
    "meta.json without its world": (lambda d: edit_meta(d, lambda m: m.pop("world")),
                                    ["meta.json has invalid values", "world: Field required"]),
    "NaN model baseline": (lambda d: edit_meta(d, lambda m: m["model"]["T_cam1_cam0"][0].__setitem__(3, float("nan"))),
                           ["meta.json", "model.T_cam1_cam0", "the model pair's relative pose holds NaN or inf"]),
    "board ground truth without a board": (lambda d: edit_meta(d, lambda m: m.pop("board")),
                                           ["meta.json has invalid values", "board: needed with ground_truth board"]),
    "pose ground truth without model image 0's pose": (
        lambda d: edit_meta(d, lambda m: m.__setitem__("ground_truth", "poses")),
        ["meta.json has invalid values", "model.T_cam0_ref: needed with ground_truth poses"]),
    "unknown ground truth": (lambda d: edit_meta(d, lambda m: m.__setitem__("ground_truth", "gps")),
                             ["meta.json has invalid values", "ground_truth"]),
    "missing camera.yaml": (lambda d: (folder(d) / "camera.yaml").unlink(), ["dataset line_a", "camera.yaml"]),
    "camera.yaml with a negative focal length": (
        lambda d: edit_camera(d, lambda c: c["camera_matrix"]["data"].__setitem__(0, -600.0)),
        ["dataset line_a", "camera.yaml", "camera_matrix", "fx, fy > 0"]),
    "camera.yaml of an unknown lens model": (
        lambda d: edit_camera(d, lambda c: c.__setitem__("distortion_model", "fisheye")),
        ["dataset line_a", "distortion_model", "'fisheye'"]),
    "camera.yaml of a folding lens": (
        lambda d: edit_camera(d, lambda c: c["distortion_coefficients"]["data"].__setitem__(0, -2.0)),
        ["dataset line_a", "distortion_coefficients", "folds the image"]),
    "meta.json of another dataset": (lambda d: edit_meta(d, lambda m: m.__setitem__("dataset", "arc_a")),
                                     ["dataset line_a", "names the dataset 'arc_a'"]),
    "missing frames.parquet": (lambda d: (folder(d) / "frames.parquet").unlink(),
                               ["dataset line_a", "frames.parquet is missing"]),
    "unreadable frames.parquet": (lambda d: (folder(d) / "frames.parquet").write_text("PAR1 nonsense"),
                                  ["dataset line_a", "cannot read", "frames.parquet"]),
    "frames.parquet without poses": (lambda d: edit_frames(d, lambda f: f.drop(columns="T_cam_board")),
                                     ["frames.parquet lacks the column(s) ['T_cam_board']"]),
    "duplicated frame row": (lambda d: edit_frames(d, duplicate_frame_row),
                             ["dataset line_a", "2 rows with the same stop and image", "s00_i01.png"]),
    "NaN stop position": (lambda d: edit_frames(d, lambda f: f.assign(x_mm=f.x_mm.where(f.index != 0))),
                          ["dataset line_a", "x_mm"]),
    "text in a stop position": (lambda d: edit_frames(d, lambda f: f.assign(x_mm=[f"{x:.1f} mm" for x in f.x_mm])),
                                ["dataset line_a", "frames.parquet", "column x_mm must hold numbers",
                                 "'20.0 mm' in row 0 (stop 0, image 0)"]),  # as a table edited by hand
    "text in a stop number": (lambda d: edit_frames(d, lambda f: f.assign(stop=[f"stop {s}" for s in f.stop])),
                              ["dataset line_a", "frames.parquet", "column stop must hold numbers", "'stop 0' in row 0"]),
    "missing index.parquet": (lambda d: (d / "datasets" / "index.parquet").unlink(),
                              ["index.parquet is missing", "run stage 01"]),
    "unreadable index.parquet": (lambda d: (d / "datasets" / "index.parquet").write_bytes(b"garbage"),
                                 ["cannot read", "index.parquet"]),
    "index naming a dataset twice": (lambda d: synthetic.write_index(d, [index_row(DATASET), index_row(DATASET)]),
                                     ["index.parquet names dataset(s) ['line_a'] more than once"]),
    "index naming a missing folder": (lambda d: synthetic.write_index(d, [index_row(DATASET), index_row("gone")]),
                                      ["names dataset(s) ['gone'] whose folder is missing"]),
    "folder missing from the index": (
        lambda d: shutil.copytree(folder(d), d / "datasets" / "line_b"),
        ["dataset folder(s) ['line_b']", "missing from index.parquet"]),
}


@pytest.mark.parametrize("case", STOPS)
def test_a_bad_dataset_stops_before_any_work_naming_it(data_dir, extract_params, workers, monkeypatch, case):
    damage, expected = STOPS[case]
    damage(data_dir)
    localized = []
    monkeypatch.setattr(E, "frame_rows", lambda task: localized.append(task) or ([], ()))
    with pytest.raises(DatasetError) as error:  # a DatasetError, not a raw pandas / json / OpenCV error
        E.extract_all(data_dir, extract_params, METHODS, workers, progress=False)
    for text in expected:
        assert text in str(error.value), str(error.value)
    assert localized == []  # no frame was touched
