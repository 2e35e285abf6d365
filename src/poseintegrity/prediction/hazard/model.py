"""The discrete-time failure hazard: a logistic regression on the stop evidence, calibrated on held-out worlds (issue 50; the paper's future work, VI: "higher dimensional models" than its artifact model).

A hazard model maps a row of evidence x (:mod:`.stop_evidence`, :mod:`.risk_sets`) to the probability that the stop
it looks at fails, given that the arc has not failed before (a discrete-time hazard, fitted as a logistic regression
on the risk set: Singer and Willett's person-period form). The steps:

1. a column missing from the evidence (NaN) is filled with its training median (``fill``);
2. the columns are standardized with the training mean and standard deviation (``mean``, ``scale``);
3. p_raw = 1 / (1 + exp(-(w . z + b))), L2-penalized with inverse strength C (scikit-learn ``LogisticRegression``);
4. p = 1 / (1 + exp(-(a logit(p_raw) + c))), Platt's sigmoid (the ``method="sigmoid"`` of scikit-learn's
   ``CalibratedClassifierCV``), a and c fitted to the out-of-fold p_raw of ``calibration_folds`` folds of the
   training rows grouped by world (``GroupKFold``: a world's rows never in the fold they are judged in), then the
   regression refitted on all of them. Not isotonic: its steps give every stop of its lowest step the hazard 0
   (measured on the population: a third of the rows), so no h could tell those stops apart, and the predictors
   stop on the order of the hazards, which a sigmoid keeps (a > 0).

A model is kept as plain numbers (:meth:`HazardModel.to_dict`), so the one stage 04 reads (``predict.hazard.model``)
is readable JSON in git, and applying it needs neither scikit-learn nor the training data.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.special import expit
from sklearn.exceptions import ConvergenceWarning
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GroupKFold

from poseintegrity.errors import ArgumentError

ARRAYS = ("fill", "mean", "scale", "coef")  # a stored model's per-feature fields
SCALARS = ("intercept", "slope_a", "offset_c")
MAX_ITERATIONS = 10_000  # lbfgs on standardized columns converges in tens; a model that needs more is refused
PLATT_C = 1e6  # the calibration's two parameters fitted all but unpenalized


def columns(rows: pd.DataFrame, features: tuple[str, ...]) -> np.ndarray:
    """(n, F) float: the ``features`` columns of ``rows``, NaN for one ``rows`` lacks (step 1 fills it)."""
    return np.column_stack([rows[name].to_numpy(float) if name in rows.columns else np.full(len(rows), np.nan)
                            for name in features]) if len(rows) else np.empty((0, len(features)))


class HazardFitError(ArgumentError):
    """A hazard model cannot be fitted on these rows (one class only, too few worlds, no convergence)."""


@dataclass(frozen=True)
class HazardModel:
    """A fitted hazard (module docstring). features : (F,) column names; fill, mean, scale, coef : (F,);
    intercept : float; slope_a, offset_c : the calibration's a and c (step 4)."""

    features: tuple[str, ...]
    fill: np.ndarray
    mean: np.ndarray
    scale: np.ndarray
    coef: np.ndarray
    intercept: float
    slope_a: float = 1.0
    offset_c: float = 0.0

    def design(self, rows: pd.DataFrame) -> np.ndarray:
        """Steps 1-2: (n, F) standardized columns; a column ``rows`` lacks counts as missing (filled)."""
        X = columns(rows, self.features)
        X = np.where(np.isfinite(X), X, self.fill)
        return (X - self.mean) / self.scale

    def logit(self, rows: pd.DataFrame) -> np.ndarray:
        """Step 3's linear predictor w . z + b, (n,): the log odds of the uncalibrated probability."""
        return self.design(rows) @ self.coef + self.intercept

    def predict(self, rows: pd.DataFrame) -> np.ndarray:
        """(n,) calibrated hazards in (0, 1) (step 4)."""
        return expit(self.slope_a * self.logit(rows) + self.offset_c)

    def to_dict(self) -> dict:
        return {"features": list(self.features), **{name: float(getattr(self, name)) for name in SCALARS},
                **{name: np.asarray(getattr(self, name), float).tolist() for name in ARRAYS}}

    @classmethod
    def from_dict(cls, stored: dict, where: str = "the hazard model") -> HazardModel:
        """The model of :meth:`to_dict`; :class:`~poseintegrity.errors.ArgumentError` naming ``where`` and the key
        when a field is missing or of the wrong length."""
        try:
            features = tuple(str(name) for name in stored["features"])
            arrays = {name: np.asarray(stored[name], float) for name in ARRAYS}
            scalars = {name: float(stored[name]) for name in SCALARS}
        except (KeyError, TypeError, ValueError) as error:
            raise ArgumentError(f"{where}: not a hazard model ({type(error).__name__}: {error})") from None
        for name, values in arrays.items():
            if values.shape != (len(features),) or not np.isfinite(values).all():
                raise ArgumentError(f"{where}: {name} must hold {len(features)} finite numbers, one per feature")
        if not all(np.isfinite(v) for v in scalars.values()) or scalars["slope_a"] <= 0:
            raise ArgumentError(f"{where}: {', '.join(SCALARS)} must be finite and slope_a > 0")
        return cls(features, **arrays, **scalars)


def _regression(X: np.ndarray, y: np.ndarray, C: float) -> LogisticRegression:
    """Step 3 fitted on standardized X; :class:`HazardFitError` if lbfgs does not converge."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConvergenceWarning)
        try:
            return LogisticRegression(C=C, max_iter=MAX_ITERATIONS).fit(X, y)
        except ConvergenceWarning:
            raise HazardFitError(f"the hazard's logistic regression did not converge in {MAX_ITERATIONS} "
                                 f"iterations (predict.hazard.C = {C}): lower C") from None


def _standardized(rows: pd.DataFrame, features: tuple[str, ...]) -> tuple[np.ndarray, ...]:
    """Steps 1-2 fitted: (X standardized, fill, mean, scale)."""
    X = columns(rows, features)
    finite = np.isfinite(X)
    fill = np.array([np.median(X[finite[:, j], j]) if finite[:, j].any() else 0.0 for j in range(X.shape[1])])
    X = np.where(finite, X, fill)
    mean, scale = X.mean(axis=0), X.std(axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    return (X - mean) / scale, fill, mean, scale


def _uncalibrated(rows: pd.DataFrame, features: tuple[str, ...], C: float) -> HazardModel:
    """Steps 1-3, with an identity calibration."""
    y = rows["failed"].to_numpy(int)
    X, fill, mean, scale = _standardized(rows, features)
    fitted = _regression(X, y, C)
    return HazardModel(features, fill, mean, scale, fitted.coef_[0].astype(float), float(fitted.intercept_[0]))


def fit_hazard(rows: pd.DataFrame, features: tuple[str, ...], C: float, calibration_folds: int) -> HazardModel:
    """A calibrated hazard (module docstring) fitted on ``rows`` (the feature columns, ``failed`` 0/1 and ``world``).

    Refused (:class:`HazardFitError`, naming what is missing): rows of one class only (no failure, or only
    failures: nothing to tell apart), fewer than 2 worlds (no held-out fold to calibrate on).
    """
    if not len(features):
        raise ArgumentError("features: a hazard model needs at least one evidence column")
    y = rows["failed"].to_numpy(int)
    if len(np.unique(y)) < 2:
        raise HazardFitError(f"the hazard's training rows ({len(rows)}) hold {'no' if not y.any() else 'only'} "
                             f"failures: nothing to tell apart")
    groups = rows["world"].to_numpy()
    n_folds = min(calibration_folds, len(np.unique(groups)))
    if n_folds < 2:
        raise HazardFitError("the hazard's calibration needs rows of at least 2 worlds (population.worlds)")
    out_of_fold = np.empty(len(rows))
    for train, held in GroupKFold(n_splits=n_folds).split(rows, y, groups):
        fold = rows.iloc[train]
        if len(np.unique(fold["failed"])) < 2:
            raise HazardFitError(f"a calibration fold of {n_folds} (worlds {sorted(set(groups[train]))}) holds no "
                                 f"failure: too few worlds to calibrate on")
        out_of_fold[held] = _uncalibrated(fold, features, C).logit(rows.iloc[held])
    platt = _regression(out_of_fold[:, None], y, PLATT_C)
    slope_a, offset_c = float(platt.coef_[0, 0]), float(platt.intercept_[0])
    if slope_a <= 0:
        raise HazardFitError(f"the hazard's held-out log odds do not rise with the failures (calibration slope "
                             f"{slope_a:.3g}): the evidence tells nothing on held-out worlds")
    model = _uncalibrated(rows, features, C)
    return HazardModel(model.features, model.fill, model.mean, model.scale, model.coef, model.intercept, slope_a,
                       offset_c)


def brier_score(p: np.ndarray, failed: np.ndarray) -> float:
    """Mean squared difference of the hazards p (n,) and the outcomes (n,) 0/1: lower is better."""
    return float(np.mean((np.asarray(p, float) - np.asarray(failed, float)) ** 2)) if len(p) else float("nan")


def reliability(p: np.ndarray, failed: np.ndarray, edges: np.ndarray) -> pd.DataFrame:
    """The reliability diagram's points: per bin of predicted hazard (``edges`` (B+1,) in [0, 1]), the rows in it,
    their mean predicted hazard and the share that failed (NaN for an empty bin)."""
    p, failed = np.asarray(p, float), np.asarray(failed, float)
    bins = np.clip(np.searchsorted(edges, p, side="right") - 1, 0, len(edges) - 2)
    table = pd.DataFrame({"bin": bins, "p": p, "failed": failed}).groupby("bin").agg(
        n=("p", "size"), mean_hazard=("p", "mean"), failure_rate=("failed", "mean"))
    table = table.reindex(range(len(edges) - 1))
    return table.assign(low=edges[:-1], high=edges[1:], n=table["n"].fillna(0).astype(int)).reset_index(drop=True)
