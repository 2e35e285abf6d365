"""What every artifact-model fitter returns: a fitted model f: theta -> n_inliers, its status, a fallback.

Windsor et al. III-D fit the artifact model thousands of times unattended (every dataset, every k, every
step of the next-step predictor), so a fit never raises: it returns a :class:`FittedModel` whose
``converged`` flag and ``reason`` say what happened and whose ``predict`` then falls back to a straight
line through the samples (clipped at zero inliers), which exists for any data.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

OK = "ok"


def valid_samples(theta: np.ndarray, n_inliers: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Drop samples that cannot be counts: non-finite theta or n, and negative n.

    theta : (m,) float, the independent variable (deg for arcs, mm for lines)
    n_inliers : (m,) float, inlier counts (0 is a valid count: a failed frame)
    Returns the kept (theta, n_inliers), both (m',) float.
    """
    theta = np.asarray(theta, dtype=float).ravel()
    n_inliers = np.asarray(n_inliers, dtype=float).ravel()
    if theta.shape != n_inliers.shape:
        raise ValueError(f"theta {theta.shape} and n_inliers {n_inliers.shape} differ in length")
    keep = np.isfinite(theta) & np.isfinite(n_inliers) & (n_inliers >= 0)
    return theta[keep], n_inliers[keep]


def line_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(intercept, slope) of the least squares line y = intercept + slope * x; needs two distinct x."""
    dx = x - x.mean()
    slope = float(np.dot(dx, y - y.mean()) / np.dot(dx, dx))
    return float(y.mean()) - slope * float(x.mean()), slope


def too_few_samples(theta: np.ndarray, n_distinct_needed: int) -> str | None:
    """Why a model needing ``n_distinct_needed`` distinct theta cannot be fitted; None if it can."""
    if theta.size == 0:
        return "no valid samples"
    n_distinct = np.unique(theta).size
    if n_distinct < n_distinct_needed:
        return f"{n_distinct} distinct theta value(s), the model needs {n_distinct_needed}"
    return None


@dataclass(frozen=True)
class FallbackLine:
    """n = max(0, intercept + slope * theta): least squares line through the valid samples.

    With a single distinct theta the slope is 0 and the line is the mean count; with no valid sample it
    predicts 0 inliers everywhere (the conservative answer: no evidence of a localization envelope).
    """

    intercept: float
    slope: float

    @classmethod
    def fit(cls, theta: np.ndarray, n_inliers: np.ndarray) -> FallbackLine:
        theta, n_inliers = valid_samples(theta, n_inliers)
        if theta.size == 0:
            return cls(0.0, 0.0)
        if np.unique(theta).size < 2:
            return cls(float(n_inliers.mean()), 0.0)
        return cls(*line_fit(theta, n_inliers))

    def predict(self, theta: np.ndarray) -> np.ndarray:
        """theta : (m,) float -> (m,) float, inlier counts >= 0."""
        return np.maximum(self.intercept + self.slope * np.asarray(theta, dtype=float), 0.0)


@dataclass(frozen=True)
class FittedModel:
    """An artifact model f: theta -> n_inliers fitted to samples (Windsor et al. III-D).

    name : which model ("emg", "exponential", ..., "mlp_pretrained")
    params : fitted parameters by name (base functions) or training summary (MLP); nan when not fitted
    converged : True when the fit succeeded; otherwise ``predict`` uses ``fallback``
    reason : "ok" or why the fit failed (too few samples, optimizer message, non-finite output, ...)
    n_samples : valid samples the fit used
    curve : the fitted f, theta (m,) -> (m,); only meaningful when converged
    fallback : the straight line used when the fit failed
    """

    name: str
    params: Mapping[str, float]
    converged: bool
    reason: str
    n_samples: int
    curve: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    fallback: FallbackLine

    def predict(self, theta: np.ndarray) -> np.ndarray:
        """Predicted inlier count at theta : (m,) float -> (m,) float (the fallback if not converged)."""
        theta = np.atleast_1d(np.asarray(theta, dtype=float))
        return self.curve(theta) if self.converged else self.fallback.predict(theta)

    @classmethod
    def failed(
        cls, name: str, param_names: tuple[str, ...], reason: str, theta: np.ndarray, n_inliers: np.ndarray
    ) -> FittedModel:
        """The flagged result of a fit that could not be done or did not converge."""
        fallback = FallbackLine.fit(theta, n_inliers)
        return cls(
            name=name,
            params={key: float("nan") for key in param_names},
            converged=False,
            reason=reason,
            n_samples=int(theta.size),
            curve=fallback.predict,
            fallback=fallback,
        )
