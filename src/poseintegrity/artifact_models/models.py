"""One entry point for every artifact model of Fig. 2: base functions (least squares) and the two MLP recipes.

The least squares models are the paper's base functions and ours beside eq. 1 (the free-width EMG,
base_functions.LEAST_SQUARES).
"""

from __future__ import annotations

import numpy as np

from poseintegrity.errors import ArgumentError, check_scalar

from poseintegrity.artifact_models.base_functions import LEAST_SQUARES
from poseintegrity.artifact_models.fitted import MAX_THETA, FittedModel
from poseintegrity.artifact_models.mlp import fit_mlp
from poseintegrity.params.model_names import MLP_RECIPES, MODEL_NAMES
from poseintegrity.params.fit import FitParams


def fit_model(
    name: str,
    theta: np.ndarray,
    n_inliers: np.ndarray,
    *,
    theta_end: float,
    params: FitParams,
    rng: np.random.Generator,
) -> FittedModel:
    """Fit artifact model ``name`` (one of :data:`MODEL_NAMES`) to samples; never raises on bad data.

    theta : (m,) float, deg (arcs) or mm (lines);  n_inliers : (m,) counts
    theta_end : end of the trajectory range: the fitted curve is checked up to it (fitted.py), the MLP scales its
    input by it and puts its artificial points there
    rng : seeds the MLP weights (unused by base functions)
    Refused (:class:`~poseintegrity.errors.ArgumentError` naming the argument): an unknown name, theta and n_inliers
    of different lengths, a theta_end that is not a finite number within 1e6 or lies before the first valid sample.
    Accepted: samples with a non-finite theta or count (dropped, as frames without a measurement), theta and
    n_inliers of any shape with the same number of entries (flattened).
    """
    check_scalar("theta_end", theta_end, low=-MAX_THETA, high=MAX_THETA)
    if name in LEAST_SQUARES:
        return LEAST_SQUARES[name].fit(theta, n_inliers, theta_end=theta_end, max_nfev=params.max_nfev)
    if name in MLP_RECIPES:
        return fit_mlp(theta, n_inliers, theta_end=theta_end, mlp=params.mlp, rng=rng, pretrain=MLP_RECIPES[name])
    raise ArgumentError(f"name: unknown artifact model {name!r}; expected one of {MODEL_NAMES}")
