"""Fixtures of the localization tests: tiny synthetic datasets in the stage-01 format (see loc_synthetic)."""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))  # --import-mode=importlib: make loc_synthetic importable
import loc_synthetic as synthetic  # noqa: E402

from poseintegrity.config import load_params  # noqa: E402
from poseintegrity.localization import ExtractParams  # noqa: E402

TINY_PARAMS = Path(__file__).resolve().parents[1] / "params_tiny.yaml"


@pytest.fixture(scope="session")
def protocol():
    """The ``protocol`` section the tiny parameters share with params.yaml."""
    return load_params(TINY_PARAMS).protocol


@pytest.fixture(scope="session")
def extract_params() -> ExtractParams:
    """The ``extract`` section of the tiny parameters (sequential, so monkeypatching reaches the work)."""
    return load_params(TINY_PARAMS).extract


@pytest.fixture(scope="session")
def synthetic_data_dir(tmp_path_factory):
    """data_dir with an arc dataset (theta 10..55 deg), a line dataset, and ``bad``: one stop of three frames,
    a blank image (no keypoints, no board), the scene without its board, and two dark discs on grey (a few keypoints)."""
    data_dir = tmp_path_factory.mktemp("data")
    rng = np.random.default_rng(7)
    rows = [
        synthetic.write_dataset(data_dir, "arc_a", rng),
        synthetic.write_dataset(data_dir, "line_a", rng, trajectory="line", stops=(20.0, 80.0)),
        synthetic.write_dataset(data_dir, "bad", np.random.default_rng(11), stops=(10.0,), images_per_stop=3),
    ]
    synthetic.write_index(data_dir, rows)
    folder = data_dir / "datasets" / "bad" / "images"
    T = synthetic.arc_pose(10.0, 0.0)
    cv2.imwrite(str(folder / "s00_i00.png"), np.full(synthetic.IMAGE_SIZE[::-1], 128, np.uint8))
    same_texture, _ = synthetic.canvas(np.random.default_rng(11), with_board=False)  # draws as write_dataset did
    cv2.imwrite(str(folder / "s00_i01.png"), synthetic.render(same_texture, T))
    few_blobs = np.full(synthetic.IMAGE_SIZE[::-1], 128, np.uint8)
    for centre in ((100, 100), (400, 250)):
        cv2.circle(few_blobs, centre, 6, 20, -1)  # a handful of keypoints, fewer than 4 matches
    cv2.imwrite(str(folder / "s00_i02.png"), few_blobs)
    return data_dir
