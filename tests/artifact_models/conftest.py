"""Fixtures of the artifact-model tests: the sections of tests/params_tiny.yaml and a synthetic artifacts table."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from artifact_models.tiny import protocol, tiny, tiny_fit, workers  # noqa: F401 (fixtures)
from poseintegrity.artifact_models.synthetic import synthetic_artifacts


@pytest.fixture(scope="session")
def artifacts_table() -> tuple[pd.DataFrame, pd.DataFrame]:
    """(artifacts, truth): 3 arcs and 2 lines, methods usac_magsac and epnp, seeded."""
    return synthetic_artifacts(np.random.default_rng(2024), n_arcs=3, n_lines=2)
