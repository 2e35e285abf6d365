"""The tiny configuration every artifact-model and predictor test runs on: tests/params_tiny.yaml (params.yaml shrunk),
validated as a stage validates it. A test that needs other values derives them from these, naming the variation."""

from __future__ import annotations

from pathlib import Path

import pytest

from poseintegrity.config import Params, load_params
from poseintegrity.workers import Workers

TINY_PARAMS = Path(__file__).resolve().parents[1] / "params_tiny.yaml"


@pytest.fixture(scope="session")
def tiny() -> Params:
    """The whole of tests/params_tiny.yaml (fails, not skips, when it does not validate)."""
    return load_params(TINY_PARAMS)


@pytest.fixture(scope="session")
def tiny_fit(tiny):
    return tiny.fit


@pytest.fixture(scope="session")
def protocol(tiny):
    return tiny.protocol


@pytest.fixture(scope="session")
def workers(tiny):
    """The workers of the tiny ``parallel`` section (one in-process worker)."""
    with Workers(tiny.parallel) as opened:
        yield opened
