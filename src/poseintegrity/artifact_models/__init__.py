"""Artifact models f: theta -> n_inliers (Windsor et al. III-D, Fig. 2), fitted to the first stops of a dataset.

    params.py          the ``fit`` section of params.yaml (FitParams)
    fitted.py          FittedModel: what every fitter returns (status ok / at_bound / non_physical / fallback, reason,
                       fallback line)
    base_functions.py  eq. 1 (scaled EMG) and four other decays, fitted by bounded least squares
    mlp.py             the 3 x 10 tanh MLP (IV-E), from scratch or EMG-pretrained + fine-tuned (III-D)
    models.py          fit_model(name, ...): one entry point for all of them
    series.py          Series: one dataset's samples (theta, n_inliers per image, in stop order)
    fig2.py            the Fig. 2 experiment on the stage-02 artifacts table
"""

from poseintegrity.artifact_models.base_functions import BASE_FUNCTIONS, EMG, BaseFunction, emg, emg_pdf
from poseintegrity.artifact_models.fig2 import (
    at_sampled_stops,
    fig2_rmse,
    fit_first_stops,
    fits_metrics,
    mean_rmse,
    status_counts,
)
from poseintegrity.artifact_models.fitted import FIT_STATUSES, FallbackLine, FittedModel
from poseintegrity.artifact_models.mlp import fit_mlp
from poseintegrity.artifact_models.models import MODEL_NAMES, fit_model
from poseintegrity.artifact_models.params import FitParams, MLPParams
from poseintegrity.artifact_models.series import Series, dataset_series

__all__ = [
    "BASE_FUNCTIONS",
    "EMG",
    "FIT_STATUSES",
    "MODEL_NAMES",
    "BaseFunction",
    "FallbackLine",
    "FitParams",
    "FittedModel",
    "MLPParams",
    "Series",
    "at_sampled_stops",
    "dataset_series",
    "emg",
    "emg_pdf",
    "fig2_rmse",
    "fit_first_stops",
    "fit_mlp",
    "fit_model",
    "fits_metrics",
    "mean_rmse",
    "status_counts",
]
