"""Fixtures of the predictor tests: the sections of tests/params_tiny.yaml and synthetic stage-02 tables."""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd
import pytest

from artifact_models.tiny import protocol, tiny, tiny_fit, workers  # noqa: F401 (fixtures)
from poseintegrity.prediction import sweep

sys.path.insert(0, str(Path(__file__).parent))
from pred_synthetic import headline_rows, scene_tables  # noqa: E402


@pytest.fixture(scope="session")
def tiny_predict(tiny):
    return tiny.predict


@pytest.fixture(scope="session")
def tables(protocol):
    """(artifacts, envelopes of the headline theta_a rule): 6 arc datasets over 3 scenes, 2 line datasets, 2 PnP
    methods."""
    artifacts, envelopes = scene_tables(protocol)
    return artifacts, headline_rows(envelopes, protocol)


@pytest.fixture(scope="session")
def theta_p(tables, tiny_predict, tiny_fit, protocol, workers, run_once):  # noqa: F811
    """The whole sweep of ``tables`` (every predictor, dataset and operating point), made once per test session
    (run_once: test_sweeps.py and test_model_choice.py may run on different workers) and read back as it was made."""
    def produce(folder):
        sweep(tables[0], tiny_predict, tiny_fit, protocol, workers, progress=False).to_pickle(folder / "theta_p.pkl")

    return pd.read_pickle(run_once("prediction_sweep", produce) / "theta_p.pkl")
