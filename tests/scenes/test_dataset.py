"""Stage 01 on tiny parameters: layout, ground truth consistency, byte-for-byte determinism (whatever the worker
count; another generate.seed gives another world), atomic writes."""

import hashlib
import json

import cv2
import numpy as np
import pandas as pd
import pytest

from poseintegrity.boards import board_from_dict
from poseintegrity.config import load_params
from poseintegrity.lens import read_camera_yaml
from poseintegrity.scenes import dataset, renderer, trips
from poseintegrity.scenes.camera import true_camera
from poseintegrity.workers import Workers
from repository import ROOT

TINY = load_params(ROOT / "tests" / "params_tiny.yaml")  # params.yaml shrunk: the pipeline's configuration


def digest(root) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


def run(params, root, n_jobs: int = 1):
    """Stage 01 into ``root / "datasets"`` and ``root / "calibration"``; returns the index."""
    with Workers(TINY.parallel.model_copy(update={"n_jobs": n_jobs})) as workers:
        return dataset.generate(params, TINY.protocol, root / "datasets", workers, calibration_dir=root / "calibration",
                                progress=False)[0]


@pytest.fixture(scope="module")
def tiny_root(tmp_path_factory):
    params = TINY.generate
    top = tmp_path_factory.mktemp("stage01")
    run(params, top)
    return params, top / "datasets"


@pytest.mark.pipeline  # tiny_root: stage 01 on the tiny parameters
def test_layout_and_index(tiny_root):
    params, root = tiny_root
    index = pd.read_parquet(root / "index.parquet")
    assert list(index["dataset"]) == [p.dataset for name, world in params.worlds().items()
                                      for p in trips.plan_datasets(world, name)]
    assert set(index["trajectory"]) == {"arc", "line"} and set(index["world"]) == {"main", "validation"}
    for world in ("main", "validation"):
        calibration = root.parent / "calibration" / world
        views = params.worlds()[world].calibration.n_views
        assert (calibration / "camera.yaml").is_file() and len(list((calibration / "views").glob("*.png"))) == views
    for row in index.itertuples():
        frames = pd.read_parquet(root / row.dataset / "frames.parquet")
        meta = json.loads((root / row.dataset / "meta.json").read_text())
        camera = read_camera_yaml(root / row.dataset / "camera.yaml")  # the world's calibration, not the truth
        assert camera.K[0, 0] != meta["true_camera"]["K"][0][0] and meta["world"] == row.world
        images_per_stop = params.world(row.world).images_per_stop
        assert len(frames) == row.n_frames == meta["n_stops"] * images_per_stop
        assert (frames.groupby("stop")["theta_deg"].nunique() == 1).all()
        for file in frames["file"]:
            image = cv2.imread(str(root / row.dataset / file), cv2.IMREAD_UNCHANGED)
            assert image.dtype == np.uint8 and image.shape == (camera.height, camera.width)
        mask = cv2.imread(str(root / row.dataset / meta["model"]["masks"][0]), cv2.IMREAD_GRAYSCALE)
        assert set(np.unique(mask)) <= {0, 255} and (mask > 0).any()


@pytest.mark.pipeline  # tiny_root: stage 01 on the tiny parameters
def test_images_of_a_stop_differ_only_by_noise(tiny_root):
    _, root = tiny_root
    folder = root / "scene_a_arc000"
    a, b = (cv2.imread(str(folder / f"images/s00_i0{i}.png"), cv2.IMREAD_GRAYSCALE).astype(float) for i in (0, 1))
    assert 0 < np.abs(a - b).mean() < 4.0
    c = cv2.imread(str(folder / "images/s02_i00.png"), cv2.IMREAD_GRAYSCALE).astype(float)
    assert np.abs(a - c).mean() > 2 * np.abs(a - b).mean()  # another stop is another view


@pytest.mark.pipeline  # tiny_root: stage 01 on the tiny parameters
def test_the_recorded_exact_pose_is_the_one_the_image_shows(tiny_root):
    """frames.parquet's T_cam_board (the robot's actual pose, turned by the image's ring-down) puts the board's
    ChArUco corners, through the *true* lens, where OpenCV detects them in the image: no bias (mean offset), and an
    RMS of a saddle corner's accuracy at the tiny quarter resolution."""
    params, root = tiny_root
    truth = true_camera(params.camera)
    for name in ("scene_b_arc000", "scene_a_arc090"):
        frames = pd.read_parquet(root / name / "frames.parquet")
        board = board_from_dict(json.loads((root / name / "meta.json").read_text())["board"]).cv_board()
        detector = cv2.aruco.CharucoDetector(board)
        offsets, detected = [], 0
        for row in frames.itertuples():
            corners, ids, _, _ = detector.detectBoard(cv2.imread(str(root / name / row.file), cv2.IMREAD_GRAYSCALE))
            if ids is None or len(ids) < 4:  # the view hides the board (stage 02 flags such frames)
                continue
            detected += 1
            T = np.asarray(row.T_cam_board).reshape(4, 4)
            projected, _ = cv2.projectPoints(board.getChessboardCorners()[ids.ravel()], cv2.Rodrigues(T[:3, :3])[0],
                                             T[:3, 3], truth.K, truth.dist)
            offsets.append(projected.reshape(-1, 2) - corners.reshape(-1, 2))
        assert detected >= 0.8 * len(frames)
        offsets = np.concatenate(offsets)
        assert np.abs(offsets.mean(axis=0)).max() < 0.2
        assert np.sqrt(np.mean(np.sum(offsets**2, axis=1))) < 0.5


@pytest.mark.pipeline  # tiny_root: stage 01 on the tiny parameters
def test_rerun_reproduces_every_file_byte_for_byte_on_two_workers(tiny_root, tmp_path):
    params, root = tiny_root
    run(params, tmp_path, n_jobs=2)
    assert digest(tmp_path) == digest(root.parent)


@pytest.mark.pipeline  # tiny_root: stage 01 on the tiny parameters
def test_another_seed_lays_out_and_exposes_another_world(tiny_root, tmp_path):
    """Every random draw derives from generate.seed: the scene layouts (board and target poses), the textures,
    the foam and the sensor noise."""
    params, root = tiny_root
    run(params.model_copy(update={"seed": params.seed + 1}), tmp_path)
    first, other = digest(root), digest(tmp_path / "datasets")
    assert first.keys() == other.keys()
    main = [file for file in first if file.startswith("scene_")]  # the validation world has a seed of its own
    assert all(first[file] != other[file] for file in main if file.endswith(".png") and "mask" not in file)
    assert all(first[file] == other[file] for file in first if file.startswith("val_"))
    for name in first:
        # the board lies elsewhere (a phantom faces the camera as its tilt says); the validation world is its own
        if name.endswith("frames.parquet") and name.startswith("scene_"):
            boards = [np.stack(pd.read_parquet(folder / name)["T_cam_board"]) for folder in (root, tmp_path / "datasets")]
            assert not np.allclose(*boards)


@pytest.mark.pipeline  # tiny_root: stage 01 on the tiny parameters
def test_interrupted_run_leaves_nothing_that_looks_complete(tiny_root, tmp_path, monkeypatch):
    params, _ = tiny_root
    calls = {"n": 0}
    real_expose = renderer.expose

    def failing_expose(*args, **kwargs):
        calls["n"] += 1
        calibration_views = sum(w.calibration.n_views for w in params.worlds().values())  # both worlds' sessions
        if calls["n"] > calibration_views + 10:  # into the datasets
            raise KeyboardInterrupt("simulated interruption")
        return real_expose(*args, **kwargs)

    monkeypatch.setattr(renderer, "expose", failing_expose)
    with pytest.raises(KeyboardInterrupt):
        run(params, tmp_path)
    assert not (tmp_path / "datasets" / "index.parquet").exists()
    assert [p.name for p in (tmp_path / "datasets").iterdir() if not p.name.startswith(".")] == []
