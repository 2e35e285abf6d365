"""Fixtures of the artifact-model tests: tiny ``fit`` params and a synthetic artifacts table (eq. 1 + noise)."""

from __future__ import annotations

import copy

import numpy as np
import pandas as pd
import pytest

from poseintegrity.artifact_models import FitParams
from poseintegrity.artifact_models.synthetic import synthetic_artifacts

# The tiny ``fit`` section used by the tests (and, in YAML, by the notebook test).
TINY_FIT = {
    "pnp_method": "usac_magsac",
    "models": ["emg", "exponential", "gaussian", "logistic", "power_law", "mlp_scratch", "mlp_pretrained"],
    "k_min": 3,
    "k_max": 5,
    "k_report_arc": 4,
    "k_report_line": 5,
    "theta_max_deg": 45.0,
    "x_max_mm": 150.0,
    "max_nfev": 400,
    "seed": 7,
    "n_jobs": 1,
    "mlp": {
        "hidden_layers": 3,
        "hidden_units": 10,
        "max_iter_scratch": 60,
        "max_iter_pretrain": 60,
        "max_iter_finetune": 10,
        "tolerance_change": 1e-12,
        "n_pretrain_points": 50,
        "n_artificial": 10,
    },
}


@pytest.fixture
def tiny_fit_raw() -> dict:
    """The tiny ``fit`` section as a fresh (mutable) mapping."""
    return copy.deepcopy(TINY_FIT)


@pytest.fixture(scope="session")
def tiny_fit() -> FitParams:
    return FitParams.model_validate(TINY_FIT)


@pytest.fixture(scope="session")
def tiny_fit_mlp_only() -> FitParams:
    """An even smaller MLP budget for the property tests (they run many fits)."""
    raw = copy.deepcopy(TINY_FIT)
    raw["mlp"].update(max_iter_scratch=15, max_iter_pretrain=15, max_iter_finetune=5, n_pretrain_points=20)
    return FitParams.model_validate(raw)


@pytest.fixture(scope="session")
def artifacts_table() -> tuple[pd.DataFrame, pd.DataFrame]:
    """(artifacts, truth): 3 arcs and 2 lines, methods usac_magsac and epnp, seeded."""
    return synthetic_artifacts(np.random.default_rng(2024), n_arcs=3, n_lines=2)
