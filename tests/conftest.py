"""Shared fixtures: the repository root and the tiny parameters every notebook test runs with."""

from pathlib import Path

import os

import pytest
import yaml
from hypothesis import settings

from poseintegrity.config import parse_params

# Property tests explore new random examples on every local run; on CI (CI=true) they replay a fixed set, so a
# submission never fails on a case nobody has seen. Run locally to find new counterexamples.
settings.register_profile("ci", derandomize=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

ROOT = Path(__file__).resolve().parents[1]
TINY_PARAMS = ROOT / "tests" / "params_tiny.yaml"


@pytest.fixture
def tiny_raw() -> dict:
    """tests/params_tiny.yaml as a plain dict, to be altered by a test."""
    return yaml.safe_load(TINY_PARAMS.read_text())


@pytest.fixture
def tiny_params(tiny_raw):
    return parse_params(tiny_raw)
