"""How well the predicted localization error (:mod:`pose_covariance`) says what the measured one is (issue 38).

A predicted error is only worth a predictor if it is calibrated. Per world and tolerance, over the frames of the
paper's PnP path before their dataset's theta_a (where the pose is the least-squares fit first order describes,
not a wrong consensus), that have a prediction and a measured error:

- ``within_1sigma_t`` / ``within_2sigma_t``: the share whose measured E_t (against the ground truth, IV-C) is no
  larger than 1 / 2 x the predicted RMS sigma_t; likewise for E_r (``_r``) and against the renderer's exact pose
  (``_t_exact``, rendered worlds; NaN without exact poses). For a 3-D Gaussian error these are 0.61-0.68 and
  0.95-0.99 (isotropic to one dominant axis);
- ``median_ratio_t`` / ``median_ratio_r``: median of measured / predicted (1: calibrated; above 1: under-predicted);
- ``spearman_t``: the rank correlation of sigma_t with E_t per frame, beside ``spearman_n_i_t``, that of -n_i with
  E_t (how well the inlier count alone orders the errors);
- ``pixel_noise_px``: the median over datasets of the model pair's measured keypoint noise;
- ``unconditioned``: ``within_1sigma_t``, ``within_2sigma_t`` and ``median_ratio_t`` of the plain first-order
  prediction, without the inlier test's conditioning (pose_covariance.py, (c));
- ``kinematic``: what the robot observes of the same frames (kinematic_consistency.py): ``spearman_t``, the rank
  correlation of E_t_kinematic_mm with E_t; ``median_abs_difference_mm``, the median |E_t_kinematic - E_t|;
  ``median_first_stop_mm``, its median at the first stop (the model view: the robot's and the placement's own
  disagreement); NaN for datasets without the robot's poses.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.stats import spearmanr

def calibration_frames(artifacts: pd.DataFrame, envelopes: pd.DataFrame, method: str) -> pd.DataFrame:
    """The frames a calibration is read on, one row per frame and tolerance: those of ``method`` with a predicted
    error (``covariance_status`` ok) at a position before their dataset's theta_a (``envelopes``: one failed-frame
    rule, columns dataset, tolerance, method, theta_a; a dataset without a theta_a contributes nothing)."""
    rows = artifacts[(artifacts["method"] == method) & (artifacts["covariance_status"] == "ok")]
    rows = rows.assign(position=np.where(rows["trajectory"] == "arc", rows["theta_deg"], rows["x_mm"]))
    theta_a = envelopes.loc[envelopes["method"] == method, ["dataset", "tolerance", "theta_a"]]
    rows = rows.merge(theta_a, on="dataset", how="inner")
    return rows[rows["position"] < rows["theta_a"]]


def _share_within(measured: pd.Series, sigma: pd.Series, n_sigma: float) -> float:
    known = measured.notna() & sigma.notna()
    return float((measured[known] <= n_sigma * sigma[known]).mean()) if known.any() else float("nan")


def _spearman(a: pd.Series, b: pd.Series) -> float:
    known = a.notna() & b.notna()
    if known.sum() < 3 or a[known].nunique() < 2 or b[known].nunique() < 2:
        return float("nan")
    return float(spearmanr(a[known], b[known]).statistic)


def _kinematic(judged: pd.DataFrame) -> dict:
    """The ``kinematic`` block of one world and tolerance (module docstring)."""
    observed = judged["E_t_kinematic_mm"] if "E_t_kinematic_mm" in judged else pd.Series(np.nan, index=judged.index)
    return {"spearman_t": _spearman(observed, judged["E_t_mm"]),
            "median_abs_difference_mm": float((observed - judged["E_t_mm"]).abs().median()),
            "median_first_stop_mm": float(observed[judged["stop"] == 0].median())}


def calibration_metrics(frames: pd.DataFrame) -> dict:
    """``<world>.<tolerance>.{n_frames, within_*, median_ratio_*, spearman_*, pixel_noise_px}`` of
    :func:`calibration_frames` rows (module docstring)."""
    metrics: dict = {}
    for (world, tolerance), rows in frames.groupby(["world", "tolerance"], sort=True):
        judged = rows[rows["E_t_mm"].notna()]
        ratio_t = (judged["E_t_mm"] / judged["sigma_t_pred_mm"]).median()
        ratio_r = (judged["E_r_deg"] / judged["sigma_r_pred_deg"]).median()
        metrics.setdefault(str(world), {})[str(tolerance)] = {
            "n_frames": int(len(judged)),
            "within_1sigma_t": _share_within(judged["E_t_mm"], judged["sigma_t_pred_mm"], 1.0),
            "within_2sigma_t": _share_within(judged["E_t_mm"], judged["sigma_t_pred_mm"], 2.0),
            "within_1sigma_r": _share_within(judged["E_r_deg"], judged["sigma_r_pred_deg"], 1.0),
            "within_2sigma_r": _share_within(judged["E_r_deg"], judged["sigma_r_pred_deg"], 2.0),
            "within_2sigma_t_exact": _share_within(rows["E_t_exact_mm"], rows["sigma_t_pred_mm"], 2.0),
            "median_ratio_t": float(ratio_t), "median_ratio_r": float(ratio_r),
            "spearman_t": _spearman(judged["sigma_t_pred_mm"], judged["E_t_mm"]),
            "spearman_n_i_t": _spearman(-judged["n_inliers"], judged["E_t_mm"]),
            "pixel_noise_px": float(rows.drop_duplicates("dataset")["model_pixel_noise_px"].median()),
            "unconditioned": {
                "within_1sigma_t": _share_within(judged["E_t_mm"], judged["sigma_t_unconditioned_mm"], 1.0),
                "within_2sigma_t": _share_within(judged["E_t_mm"], judged["sigma_t_unconditioned_mm"], 2.0),
                "median_ratio_t": float((judged["E_t_mm"] / judged["sigma_t_unconditioned_mm"]).median()),
            },
            "kinematic": _kinematic(judged),
        }
    return metrics
