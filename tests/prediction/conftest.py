"""Fixtures of the predictor tests: tiny ``predict`` and ``fit`` sections and synthetic stage-02 tables."""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import pytest

from poseintegrity.artifact_models import FitParams
from poseintegrity.prediction import PredictParams

sys.path.insert(0, str(Path(__file__).parent))
from pred_synthetic import TINY_FIT, TINY_PREDICT, scene_tables  # noqa: E402


@pytest.fixture
def tiny_predict_raw() -> dict:
    return copy.deepcopy(TINY_PREDICT)


@pytest.fixture(scope="session")
def tiny_predict() -> PredictParams:
    return PredictParams.model_validate(TINY_PREDICT)


@pytest.fixture(scope="session")
def tiny_fit() -> FitParams:
    return FitParams.model_validate(TINY_FIT)


@pytest.fixture(scope="session")
def tables():
    """(artifacts, envelopes): 6 arc datasets over 3 scenes, 2 line datasets, 2 PnP methods."""
    return scene_tables()
