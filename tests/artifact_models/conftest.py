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


@pytest.fixture(scope="session")
def fit_base(tiny_fit, protocol):
    """base.fit with the tiny ``fit`` budget on an arc (range end from the protocol)."""
    def run(base, theta, n, **changes):
        budget = {"theta_end": protocol.range_end("arc"), "max_nfev": tiny_fit.max_nfev, **changes}
        return base.fit(theta, n, **budget)

    return run
