"""Artifact models f: theta -> n_inliers (Windsor et al. III-D, Fig. 2) and the envelope boundary theta_p (III-E).

    params.py          the ``fit`` section of params.yaml (FitParams)
    fitted.py          FittedModel: what every fitter returns (converged flag, reason, fallback line)
    base_functions.py  eq. 1 (scaled EMG) and four other decays, fitted by bounded curve_fit
    mlp.py             the 3 x 10 tanh MLP (IV-E), from scratch or EMG-pretrained + fine-tuned (III-D)
    models.py          fit_model(name, ...): one entry point for all of them
    roots.py           theta_p where f(theta) = n_t (scan + brentq), censored / below-at-start answers
    fig2.py            the Fig. 2 experiment on the stage-02 artifacts table
"""

from poseintegrity.artifacts.base_functions import BASE_FUNCTIONS, EMG, BaseFunction, emg, emg_pdf
from poseintegrity.artifacts.fig2 import dataset_series, fig2_rmse, fit_first_stops, fits_metrics, mean_rmse
from poseintegrity.artifacts.fitted import FallbackLine, FittedModel
from poseintegrity.artifacts.mlp import fit_mlp
from poseintegrity.artifacts.models import MODEL_NAMES, fit_model
from poseintegrity.artifacts.params import FitParams, MLPParams
from poseintegrity.artifacts.roots import EnvelopeBoundary, envelope_boundary

__all__ = [
    "BASE_FUNCTIONS",
    "EMG",
    "MODEL_NAMES",
    "BaseFunction",
    "EnvelopeBoundary",
    "FallbackLine",
    "FitParams",
    "FittedModel",
    "MLPParams",
    "dataset_series",
    "emg",
    "emg_pdf",
    "envelope_boundary",
    "fig2_rmse",
    "fit_first_stops",
    "fit_mlp",
    "fit_model",
    "fits_metrics",
    "mean_rmse",
]
