"""Shared fixtures: the repository root and the tiny parameters every notebook test runs with."""

from pathlib import Path

import os

import pytest
from hypothesis import settings

from poseintegrity.config import parse_params, read_raw

# Property tests explore new random examples on every local run; on CI (CI=true) they replay a fixed set, so a
# submission never fails on a case nobody has seen. Run locally to find new counterexamples.
settings.register_profile("ci", derandomize=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

ROOT = Path(__file__).resolve().parents[1]
TINY_PARAMS = ROOT / "tests" / "params_tiny.yaml"


@pytest.fixture
def tiny_raw() -> dict:
    """tests/params_tiny.yaml merged onto params.yaml, as a plain dict to be altered by a test."""
    return read_raw(TINY_PARAMS)[0]


@pytest.fixture
def tiny_params(tiny_raw):
    return parse_params(tiny_raw, base_dir=ROOT)
