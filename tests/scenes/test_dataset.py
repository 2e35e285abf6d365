"""Stage 01 on tiny parameters: layout, ground truth consistency, byte-for-byte determinism (whatever the worker
count; another generate.seed gives another world), atomic writes."""

import hashlib
import json

import cv2
import numpy as np
import pandas as pd
import pytest

from poseintegrity.config import load_params
from poseintegrity.parallel import Workers
from poseintegrity.scenes import dataset, renderer
from repository import ROOT

TINY = load_params(ROOT / "tests" / "params_tiny.yaml")  # params.yaml shrunk: the pipeline's configuration


def digest(root) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def tiny_root(tmp_path_factory):
    params = TINY.generate
    root = tmp_path_factory.mktemp("datasets")
    with Workers(TINY.parallel) as workers:
        dataset.generate(params, TINY.protocol, root, workers, progress=False)
    return params, root


def test_layout_and_index(tiny_root):
    params, root = tiny_root
    index = pd.read_parquet(root / "index.parquet")
    assert list(index["dataset"]) == [p.dataset for p in dataset.plan_datasets(params)]
    assert set(index["trajectory"]) == {"arc", "line"}
    for row in index.itertuples():
        frames = pd.read_parquet(root / row.dataset / "frames.parquet")
        meta = json.loads((root / row.dataset / "meta.json").read_text())
        assert len(frames) == row.n_frames == meta["n_stops"] * params.images_per_stop
        assert (frames.groupby("stop")["theta_deg"].nunique() == 1).all()
        for file in frames["file"]:
            image = cv2.imread(str(root / row.dataset / file), cv2.IMREAD_UNCHANGED)
            assert image.dtype == np.uint8 and image.shape == (meta["image_size"][1], meta["image_size"][0])
        mask = cv2.imread(str(root / row.dataset / meta["model"]["masks"][0]), cv2.IMREAD_GRAYSCALE)
        assert set(np.unique(mask)) <= {0, 255} and (mask > 0).any()


def test_images_of_a_stop_differ_only_by_noise(tiny_root):
    _, root = tiny_root
    folder = root / "scene_a_arc000"
    a, b = (cv2.imread(str(folder / f"images/s00_i0{i}.png"), cv2.IMREAD_GRAYSCALE).astype(float) for i in (0, 1))
    assert 0 < np.abs(a - b).mean() < 4.0
    c = cv2.imread(str(folder / "images/s02_i00.png"), cv2.IMREAD_GRAYSCALE).astype(float)
    assert np.abs(a - c).mean() > 2 * np.abs(a - b).mean()  # another stop is another view


@pytest.mark.parametrize("flags", ["IMAGE_PNG_FLAGS", "MASK_PNG_FLAGS"])
def test_png_files_hold_exactly_the_pixels_exposed(tmp_path, flags):
    """The encoder settings are lossless on a noisy camera image and a flat mask, whatever they compress."""
    folder = dataset._partial(tmp_path, "d")
    folder.mkdir()
    noisy = renderer.expose(np.full((64, 96), 0.6, np.float32), TINY.generate.sensor, np.random.default_rng(0))
    mask = np.zeros((64, 96), np.uint8)
    mask[10:40, 20:70] = 255
    for name, image in (("noisy.png", noisy), ("mask.png", mask)):
        dataset._write_png(tmp_path, ("d",), name, image, getattr(dataset, flags))
        assert (cv2.imread(str(folder / name), cv2.IMREAD_UNCHANGED) == image).all()


def test_board_ground_truth_agrees_with_opencv_aruco_pose(tiny_root):
    """T_cam_board of the renderer and the pose OpenCV recovers from the rendered board agree (half resolution)."""
    from poseintegrity.scenes import trajectories
    from poseintegrity.poses import inverse
    from poseintegrity.scenes.camera import Intrinsics
    params, _ = tiny_root
    params = params.model_copy(update={"camera": params.camera.model_copy(update={"downscale": 2})})
    world = dataset.world(params, 1)
    cam = Intrinsics.from_params(params.camera)
    T_world_cam = trajectories.model_pair(world.scene.aim, world.scene.view_dir, params.scenes[1].distance_mm,
                                          20.0)[0]
    frame = renderer.render(world.geometry, cam.K, cam.width, cam.height, inverse(T_world_cam))
    image = renderer.expose(renderer.optics(frame.radiance, params.sensor), params.sensor, np.random.default_rng(0))
    board = world.scene.board.board()
    detector = cv2.aruco.ArucoDetector(board.getDictionary(), cv2.aruco.DetectorParameters())
    corners, ids, _ = detector.detectMarkers(image)
    assert ids is not None and len(ids) >= 4  # of 6; the target may hide one
    obj, img = board.matchImagePoints(corners, ids)
    ok, rvec, tvec = cv2.solvePnP(obj, img, cam.K, None)
    T_true = inverse(T_world_cam) @ world.scene.T_world_board
    assert ok
    assert np.linalg.norm(tvec.ravel() - T_true[:3, 3]) < 3.0  # mm, at ~350 mm
    R_err = cv2.Rodrigues(rvec)[0] @ T_true[:3, :3].T
    assert np.degrees(np.arccos(np.clip((np.trace(R_err) - 1) / 2, -1, 1))) < 1.5


def test_rerun_reproduces_every_file_byte_for_byte_on_two_workers(tiny_root, tmp_path):
    params, root = tiny_root
    with Workers(TINY.parallel.model_copy(update={"n_jobs": 2})) as workers:
        dataset.generate(params, TINY.protocol, tmp_path, workers, progress=False)
    assert digest(tmp_path) == digest(root)


def test_another_seed_lays_out_and_exposes_another_world(tiny_root, tmp_path):
    """Every random draw derives from generate.seed: the scene layouts (board and target poses), the textures,
    the foam and the sensor noise."""
    params, root = tiny_root
    with Workers(TINY.parallel) as workers:
        dataset.generate(params.model_copy(update={"seed": params.seed + 1}), TINY.protocol, tmp_path, workers,
                         progress=False)
    first, other = digest(root), digest(tmp_path)
    assert first.keys() == other.keys()
    assert all(first[file] != other[file] for file in first if file.endswith(".png") and "mask" not in file)
    for name in first:
        if name.endswith("frames.parquet"):  # the board lies elsewhere (a phantom faces the camera as its tilt says)
            boards = [np.stack(pd.read_parquet(folder / name)["T_cam_board"]) for folder in (root, tmp_path)]
            assert not np.allclose(*boards)


def test_interrupted_run_leaves_nothing_that_looks_complete(tiny_root, tmp_path, monkeypatch):
    params, _ = tiny_root
    calls = {"n": 0}
    real_expose = renderer.expose

    def failing_expose(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] > 5:
            raise KeyboardInterrupt("simulated interruption")
        return real_expose(*args, **kwargs)

    monkeypatch.setattr(renderer, "expose", failing_expose)
    with Workers(TINY.parallel.model_copy(update={"n_jobs": 1})) as workers, pytest.raises(KeyboardInterrupt):
        dataset.generate(params, TINY.protocol, tmp_path, workers, progress=False)
    assert not (tmp_path / "index.parquet").exists()
    assert [p.name for p in tmp_path.iterdir() if not p.name.startswith(".")] == []
