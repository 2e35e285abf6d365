"""Fixtures of the localization tests: tiny synthetic datasets in the stage-01 format (see loc_synthetic), and the
``extract`` / ``parallel`` sections of tests/params_tiny.yaml (params.yaml shrunk): never hand-written copies."""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

sys.path.insert(0, str(Path(__file__).parent))  # --import-mode=importlib: make loc_synthetic importable
import loc_synthetic as synthetic  # noqa: E402

from poseintegrity.config import load_params  # noqa: E402
from poseintegrity.params.extract import ExtractParams  # noqa: E402
from poseintegrity.workers import Workers  # noqa: E402
from repository import ROOT  # noqa: E402

TINY_PARAMS = ROOT / "tests" / "params_tiny.yaml"


@pytest.fixture(scope="session")
def protocol():
    """The ``protocol`` section the tiny parameters share with params.yaml."""
    return load_params(TINY_PARAMS).protocol


@pytest.fixture(scope="session")
def extract_params() -> ExtractParams:
    """The ``extract`` section of the tiny parameters."""
    return load_params(TINY_PARAMS).extract


@pytest.fixture(scope="session")
def workers():
    """The ``parallel`` section of the tiny parameters (local, n_jobs 1: in this process, so monkeypatching reaches
    the work)."""
    with Workers(load_params(TINY_PARAMS).parallel) as tiny_workers:
        yield tiny_workers


@pytest.fixture(scope="session")
def synthetic_data_dir(tmp_path_factory):
    """data_dir with an arc dataset (theta 10..55 deg), a line dataset, and ``bad``: one stop of five frames,
    a blank image (no keypoints, no board), the scene without its board, two dark discs on grey (a few keypoints),
    a text file named .png (flagged bad_image) and a frame whose ground-truth pose is NaN (flagged bad_pose)."""
    data_dir = tmp_path_factory.mktemp("data")
    rng = np.random.default_rng(7)
    rows = [
        synthetic.write_dataset(data_dir, "arc_a", rng),
        synthetic.write_dataset(data_dir, "line_a", rng, trajectory="line", stops=(20.0, 80.0)),
        synthetic.write_dataset(data_dir, "bad", np.random.default_rng(11), stops=(10.0,), images_per_stop=5),
    ]
    synthetic.write_index(data_dir, rows)
    folder = data_dir / "datasets" / "bad"
    T = synthetic.arc_pose(10.0, 0.0)
    cv2.imwrite(str(folder / "images" / "s00_i00.png"), np.full(synthetic.IMAGE_SIZE[::-1], 128, np.uint8))
    same_texture, _ = synthetic.canvas(np.random.default_rng(11), with_board=False)  # draws as write_dataset did
    cv2.imwrite(str(folder / "images" / "s00_i01.png"), synthetic.render(same_texture, T))
    few_blobs = np.full(synthetic.IMAGE_SIZE[::-1], 128, np.uint8)
    for centre in ((100, 100), (400, 250)):
        cv2.circle(few_blobs, centre, 6, 20, -1)  # a handful of keypoints, fewer than 4 matches
    cv2.imwrite(str(folder / "images" / "s00_i02.png"), few_blobs)
    (folder / "images" / "s00_i03.png").write_text("not an image")
    frames = pd.read_parquet(folder / "frames.parquet")
    frames.at[4, "T_cam_board"] = np.full(16, np.nan)
    frames.to_parquet(folder / "frames.parquet")
    return data_dir
