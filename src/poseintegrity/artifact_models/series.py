"""One dataset's artifact samples, the input of every artifact model and predictor.

A :class:`Series` holds the images of one dataset (one trajectory: an arc in theta_deg or a straight line in x_mm)
for one PnP method, in stop order: what a robot has seen after each stop (Windsor et al. III-D, IV-A).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from poseintegrity.artifact_models.fitted import MAX_THETA
from poseintegrity.errors import ArgumentError, check_array, check_same_length, check_scalar
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.table_checks import TableError, check_artifacts

VARIABLE = {"arc": "theta_deg", "line": "x_mm"}  # independent variable of the artifact model per trajectory


@dataclass(frozen=True)
class Series:
    """One dataset's samples for one PnP method, in stop order.

    stop : (m,) int, 0-based;  theta : (m,) float, deg (arc) or mm (line);  n_inliers : (m,) float
    theta_end : end of the trajectory's range (protocol.arc_span_deg or line_length_mm): where the search for
    theta_p ends and the MLP's artificial point (theta_end, 0) lies (III-D, III-E)
    sigma_t, sigma_r : (m,) float or None, each image's predicted RMS E_t (mm) and E_r (deg) (stage 02's
    ``sigma_t_pred_mm``, ``sigma_r_pred_deg``; NaN without a pose), the error predictors' input (ours, issue 38)
    observed_t, observed_r : (m,) float or None, each image's disagreement with the robot's kinematics (mm, deg;
    stage 02's ``E_t_kinematic_mm``, ``E_r_kinematic_deg``, localization/kinematic_consistency.py; None when the
    dataset holds no robot poses), what ``error_next_step_observed`` calibrates the predicted error with
    """

    dataset: str
    trajectory: str
    stop: np.ndarray
    theta: np.ndarray
    n_inliers: np.ndarray
    theta_end: float
    sigma_t: np.ndarray | None = None
    sigma_r: np.ndarray | None = None
    observed_t: np.ndarray | None = None
    observed_r: np.ndarray | None = None

    def __post_init__(self) -> None:
        """Checked once when made (every predictor takes a Series): theta and n_inliers (m,) numbers (NaN / inf are
        samples without a measurement, dropped by the fits), stop (m,) integers >= 0 that never decrease, theta_end
        a finite number within 1e6; :class:`~poseintegrity.errors.ArgumentError` naming the field otherwise."""
        theta = check_array("Series.theta", self.theta, shape=(None,), finite=False)
        n_inliers = check_array("Series.n_inliers", self.n_inliers, shape=(None,), finite=False)
        stop = check_array("Series.stop", self.stop, shape=(None,), dtype="int")
        check_same_length(**{"Series.theta": theta, "Series.n_inliers": n_inliers, "Series.stop": stop})
        for name in ("sigma_t", "sigma_r", "observed_t", "observed_r"):
            if getattr(self, name) is not None:
                error = check_array(f"Series.{name}", getattr(self, name), shape=(len(theta),), finite=False)
                if (error[np.isfinite(error)] < 0).any():
                    raise ArgumentError(f"Series.{name}: an error is >= 0 (NaN: none)")
                object.__setattr__(self, name, error)
        if (stop < 0).any() or (np.diff(stop) < 0).any():
            raise ArgumentError("Series.stop: expected stop indices >= 0 in stop order")
        if (np.abs(theta[np.isfinite(theta)]) > MAX_THETA).any():
            raise ArgumentError(f"Series.theta: positions beyond +-{MAX_THETA:g} are not a trajectory")
        check_scalar("Series.theta_end", self.theta_end, low=-MAX_THETA, high=MAX_THETA)
        object.__setattr__(self, "theta", theta)
        object.__setattr__(self, "n_inliers", n_inliers)

    @property
    def n_stops(self) -> int:
        return int(np.unique(self.stop).size)

    def first_stops(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """(theta, n_inliers) of the images of the first k stops: what a robot has seen after k stops."""
        keep = np.isin(self.stop, np.unique(self.stop)[:k])
        return self.theta[keep], self.n_inliers[keep]


REQUIRED_COLUMNS = ("dataset", "trajectory", "stop", "image", "theta_deg", "x_mm", "method", "n_inliers")
PREDICTED_ERROR_COLUMNS = ("sigma_t_pred_mm", "sigma_r_pred_deg")  # read into Series.sigma_t / sigma_r when present
OBSERVED_ERROR_COLUMNS = ("E_t_kinematic_mm", "E_r_kinematic_deg")  # Series.observed_t / _r when any is known


def dataset_series(artifacts: pd.DataFrame, pnp_method: str, protocol: ProtocolParams) -> list[Series]:
    """Split the artifacts table into one :class:`Series` per (trajectory, dataset) for ``pnp_method``, each
    ending where ``protocol`` ends its trajectory type.

    Checked on read (:class:`~poseintegrity.table_checks.TableError` naming the table, column and row, or
    ArgumentError naming the dataset): the columns of stage 02's table, rows, one row per (dataset, stop, image,
    method) (a duplicated row would count twice in every fit), integer stops and images, finite positions, counts
    >= 0, a known trajectory type, stops in order of theta, theta inside [0, range end] (a table rendered for
    another protocol would otherwise be fitted and searched over the wrong range).
    """
    check_artifacts(artifacts, columns=REQUIRED_COLUMNS)
    rows = artifacts[artifacts["method"] == pnp_method]
    if rows.empty:
        raise TableError(f"the artifacts table: no rows with method {pnp_method!r}; methods present: "
                         f"{sorted(artifacts['method'].unique())}")
    series = []
    for (trajectory, dataset), group in rows.groupby(["trajectory", "dataset"], sort=True):
        group = group.sort_values(["stop", "image"], kind="stable")
        one = Series(
            dataset=str(dataset),
            trajectory=str(trajectory),
            stop=group["stop"].to_numpy(dtype=int),
            theta=group[VARIABLE[trajectory]].to_numpy(dtype=float),
            n_inliers=group["n_inliers"].to_numpy(dtype=float),
            theta_end=protocol.range_end(trajectory),
            **{name: group[column].to_numpy(dtype=float) if column in group else None
               for name, column in zip(("sigma_t", "sigma_r"), PREDICTED_ERROR_COLUMNS)},
            **{name: group[column].to_numpy(dtype=float) if column in group and group[column].notna().any() else None
               for name, column in zip(("observed_t", "observed_r"), OBSERVED_ERROR_COLUMNS)},
        )
        _check(one)
        series.append(one)
    return series


def _check(series: Series) -> None:
    """ArgumentError unless ``series`` has finite theta in [0, theta_end] whose per-stop mean increases with the stop."""
    variable = VARIABLE[series.trajectory]
    where = f"dataset {series.dataset} ({series.trajectory}, {variable})"
    if not np.all(np.isfinite(series.theta)):
        raise ArgumentError(f"{where}: non-finite {variable}")
    stops, index = np.unique(series.stop, return_inverse=True)
    per_stop = np.bincount(index, weights=series.theta) / np.bincount(index)
    if np.any(np.diff(per_stop) <= 0):
        raise ArgumentError(f"{where}: {variable} does not increase with the stop: {np.round(per_stop, 3).tolist()}")
    if series.theta.min() < 0 or series.theta.max() > series.theta_end:
        key = {"arc": "protocol.arc_span_deg", "line": "protocol.line_length_mm"}[series.trajectory]
        raise ArgumentError(f"{where}: spans {series.theta.min():g} .. {series.theta.max():g}, outside [0, "
                            f"{series.theta_end:g}], the range end {key}: set {key} to cover every stop (stage 01 "
                            f"checks recorded stops against it), or re-run stage 02 if its table was made with other "
                            f"params")
