"""The rows of ``fits.json`` (stage 03, Windsor et al. Fig. 2): each artifact model's mean RMSE from the first 4 stops
(inliers) and the share of its fits per status; the models' and the statuses' names, which the predictors' rows
share."""

from __future__ import annotations

from poseintegrity.report.headlines.sections import Headline

FIT_STATUS_LABELS = {"ok": "ok", "at_bound": "at a bound", "non_physical": "non-physical",
                     "fallback": "fallen back to a line"}  # the statuses of artifact_models/fitted.py
MODEL_LABELS = {"emg": "EMG (eq. 1)", "exponential": "exponential", "gaussian": "Gaussian", "logistic": "logistic",
                "power_law": "power law", "emg_free_width": "ours: EMG with a fitted Gaussian width",
                "mlp_scratch": "MLP, samples only", "mlp_pretrained": "MLP, EMG-pretrained + fine-tuned"}


def _fit_status_rows() -> list[Headline]:
    """fits.json: per model, the share of all its Fig. 2 fits per status (ok / at a bound / non-physical / fallback)."""
    rows = []
    for model, name in MODEL_LABELS.items():
        for status, label in FIT_STATUS_LABELS.items():
            rows.append(Headline("fits", f"fit_status.{model}.{status}",
                                 f"{name}: share of fits {label}" if status == "ok" else f"... {label}",
                                 target=">= 99 %" if (model, status) == ("emg", "ok") else "-", fmt="{:.1%}"))
    return rows


FIT_ROWS: list[Headline] = [
    Headline("fits", "rmse_k4.emg", "EMG (eq. 1)", "lowest of the least-squares fits"),
    Headline("fits", "rmse_k4.exponential", "exponential"),
    Headline("fits", "rmse_k4.gaussian", "Gaussian"),
    Headline("fits", "rmse_k4.logistic", "logistic"),
    Headline("fits", "rmse_k4.power_law", "power law"),
    Headline("fits", "rmse_k4.emg_free_width", "ours, not the paper's: EMG with a fitted Gaussian width"),
    Headline("fits", "rmse_k4.mlp_scratch", "MLP, samples only", "'very high RMSE'"),
    Headline("fits", "rmse_k4.mlp_pretrained", "MLP, EMG-pretrained + fine-tuned", "competitive with least squares"),
    *_fit_status_rows(),
]
