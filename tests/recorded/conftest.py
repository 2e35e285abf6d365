"""Fixtures of the recorded-format tests: stage-01 datasets of tests/localization/loc_synthetic (exact poses, an
ArUco board, a textured target) and the tiny ``extract`` / ``parallel`` sections."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path[:0] = [str(Path(__file__).parents[1] / "localization"), str(Path(__file__).parent)]  # importlib mode:
# loc_synthetic and recorded_tools importable
import loc_synthetic as synthetic  # noqa: E402

from poseintegrity.config import load_params  # noqa: E402
from poseintegrity.recorded.export import export_all  # noqa: E402
from poseintegrity.workers import Workers  # noqa: E402
from repository import ROOT  # noqa: E402

TINY_PARAMS = ROOT / "tests" / "params_tiny.yaml"


@pytest.fixture(scope="session")
def extract_params():
    return load_params(TINY_PARAMS).extract


@pytest.fixture(scope="session")
def workers():
    with Workers(load_params(TINY_PARAMS).parallel) as tiny_workers:
        yield tiny_workers


@pytest.fixture(scope="session")
def rendered_dir(tmp_path_factory) -> Path:
    """data_dir with two stage-01 datasets: an arc (theta 10, 25, 40 deg, two images a stop) and a line (x 20, 80 mm)."""
    data_dir = tmp_path_factory.mktemp("rendered")
    rng = np.random.default_rng(3)
    rows = [synthetic.write_dataset(data_dir, "arc_r", rng, stops=(10.0, 25.0, 40.0)),
            synthetic.write_dataset(data_dir, "line_r", rng, trajectory="line", stops=(20.0, 80.0), images_per_stop=1)]
    synthetic.write_index(data_dir, rows)
    return data_dir


@pytest.fixture(scope="session")
def exported(rendered_dir, tmp_path_factory) -> Path:
    """The rendered datasets exported to the recorded format: a folder of recorded dataset folders."""
    out = tmp_path_factory.mktemp("recorded")
    export_all(rendered_dir, out)
    return out
