"""Actual localization envelope theta_a (paper IV-E).

theta_a is the viewing-angle change (or, for straight-line datasets, the camera translation x_i) at which the
mean localization error over a stop's images first exceeds the tolerance, linearly interpolated between stops.

Rules (ours, the paper leaves them open):
- a tolerance is a pair (E_t mm, E_r deg); a stop fails when its mean E_t or its mean E_r exceeds its bound;
- theta_a is the earliest crossing, taking each error linearly interpolated between the last passing stop and
  the first failing one (equivalently: the first crossing of max(E_t / tol_t, E_r / tol_r) along the
  piecewise-linear error curves);
- the first stop is the trajectory start (theta = 0, the model view, IV-D; x = 0 on lines): a dataset whose first
  stop already fails has theta_a = the first stop's position (no safe motion at all);
- a frame without a pose (failed localization) has infinite error, so its stop fails and theta_a is the
  previous stop;
- a dataset whose mean errors never exceed the tolerance is censored at its last stop (``censored`` True).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.protocol import tolerance_name


def actual_envelope(theta: np.ndarray, mean_errors: np.ndarray, tolerance: np.ndarray) -> tuple[float, bool]:
    """theta_a and whether it is censored.

    theta : (m,) increasing stop positions (deg or mm), the first one the trajectory start
    mean_errors : (m, b) mean error per stop for each of the b bounds (inf: a stop with failed frames)
    tolerance : (b,) the bounds
    """
    theta = np.asarray(theta, dtype=float)
    errors = np.asarray(mean_errors, dtype=float)
    exceeded = np.any(errors > tolerance, axis=1)
    if not exceeded.any():
        return float(theta[-1]), True
    k = int(np.argmax(exceeded))  # first failing stop
    if k == 0:
        return float(theta[0]), False
    crossings = []
    for e_prev, e_next, bound in zip(errors[k - 1], errors[k], tolerance):
        if e_next > bound:
            fraction = 0.0 if np.isinf(e_next) else (bound - e_prev) / (e_next - e_prev)
            crossings.append(theta[k - 1] + fraction * (theta[k] - theta[k - 1]))
    return float(min(crossings)), False


def envelopes(table: pd.DataFrame, tolerances: list[tuple[float, float]]) -> pd.DataFrame:
    """theta_a per dataset, tolerance and method from an artifacts table.

    Uses ``theta_deg`` for arcs and ``x_mm`` for lines; columns: dataset, trajectory, tolerance, method,
    theta_a (deg for arcs, mm for lines), censored.
    """
    rows = []
    errors = table.assign(
        E_t=table["E_t_mm"].fillna(np.inf), E_r=table["E_r_deg"].fillna(np.inf)
    )  # a failed frame has infinite error
    for (dataset, trajectory, method), frames in errors.groupby(["dataset", "trajectory", "method"], sort=True):
        position = "x_mm" if trajectory == "line" else "theta_deg"
        per_stop = frames.groupby("stop").agg(position=(position, "mean"), E_t=("E_t", "mean"), E_r=("E_r", "mean"))
        for tolerance in tolerances:
            theta_a, censored = actual_envelope(
                per_stop["position"].to_numpy(), per_stop[["E_t", "E_r"]].to_numpy(), np.asarray(tolerance)
            )
            rows.append(
                dict(dataset=dataset, trajectory=trajectory, tolerance=tolerance_name(tolerance), method=method,
                     theta_a=theta_a, censored=censored)
            )
    return pd.DataFrame(rows, columns=["dataset", "trajectory", "tolerance", "method", "theta_a", "censored"])
