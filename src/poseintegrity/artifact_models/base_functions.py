"""Base functions of the artifact model n_inliers = f(theta), fitted by bounded non-linear least squares.

Windsor et al. III-D compare decays fitted with scipy.optimize.curve_fit and choose the scaled
exponentially modified Gaussian (EMG) of eq. 1. Every base function here is amplitude * shape(theta):

    emg          alpha * exponnorm.pdf(theta - mu, K)            (eq. 1, scale fixed at 1 theta unit)
    exponential  a * exp(-theta / tau)
    gaussian     a * exp(-(theta - m)^2 / (2 s^2))
    logistic     a / (1 + exp((theta - t50) / s))
    power_law    a / (1 + (theta / t50)^p)                       (Hill / log-logistic; tail ~ theta^-p)

Starting values and bounds are derived from the samples (see :class:`DecaySummary` and each ``_start_*``):
a decay length tau0 from a log-linear fit of the per-theta mean counts sets every scale parameter,
bounds are multiples of the sampled span, and the amplitude starts at its linear least squares
value given the starting shape. All theta units are those of the data (deg for arcs, mm for lines).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import OptimizeWarning, curve_fit
from scipy.special import erfc, erfcx

from poseintegrity.artifact_models.fitted import (
    OK,
    FallbackLine,
    FittedModel,
    line_fit,
    too_few_samples,
    valid_samples,
)

K_MIN = 0.05  # lower bound of the EMG shape K: exponnorm misbehaves as K -> 0 (docs/references.md, "SciPy")
LONGEST_DECAY = 20.0  # longest decay length (K, tau, s) a fit may choose, in sampled spans
LARGEST_LEVEL = 10.0  # largest amplitude (a level, in counts) a fit may choose, in largest mean counts


def emg_pdf(x: np.ndarray, K: np.ndarray | float) -> np.ndarray:
    """Eq. (1) with alpha = 1 and mu = 0: scipy.stats.exponnorm.pdf(x, K), written to stay finite.

        f(x, K) = 1/(2K) exp(1/(2K^2) - x/K) erfc(u),   u = -(x - 1/K) / sqrt(2)      (eq. 1, erfc eq. 2)

    For u >= 0, exp(1/(2K^2) - x/K) erfc(u) = exp(-x^2/2) erfcx(u) avoids overflow * underflow at small K;
    for u < 0 the direct form has a negative exponent and erfc(u) in (1, 2].

    x : (m,) float, theta - mu;  K : float > 0 (shape: exponential decay length in theta units)
    """
    x = np.asarray(x, dtype=float)
    inv_K = 1.0 / K
    u = (inv_K - x) / np.sqrt(2.0)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        stable = np.exp(-0.5 * x * x) * erfcx(u)
        direct = np.exp(0.5 * inv_K * inv_K - x * inv_K) * erfc(u)
    return 0.5 * inv_K * np.where(u >= 0.0, stable, direct)


def emg(theta: np.ndarray, alpha: float, K: float, mu: float) -> np.ndarray:
    """Eq. (1): the scaled EMG, alpha * exponnorm.pdf(theta - mu, K). theta : (m,) -> (m,) inliers."""
    return alpha * emg_pdf(np.asarray(theta, dtype=float) - mu, K)


def emg_jacobian(theta: np.ndarray, alpha: float, K: float, mu: float) -> np.ndarray:
    """d eq.(1) / d(alpha, K, mu) : (m, 3), for curve_fit (the EMG fit has a speed target).

    With x = theta - mu, g = exponnorm.pdf(x, K) and phi the standard normal pdf,
    exp(1/(2K^2) - x/K) phi(x - 1/K) = phi(x), hence dg/dx = (phi - g) / K and
    dg/dK = g (x/K^2 - 1/K - 1/K^3) + phi / K^3.
    """
    x = np.asarray(theta, dtype=float) - mu
    g = emg_pdf(x, K)
    phi = np.exp(-0.5 * x * x) / np.sqrt(2.0 * np.pi)
    dg_dK = g * (x / K**2 - 1.0 / K - 1.0 / K**3) + phi / K**3
    dg_dx = (phi - g) / K
    return np.stack([g, alpha * dg_dK, -alpha * dg_dx], axis=1)


def exponential(theta: np.ndarray, a: float, tau: float) -> np.ndarray:
    """a * exp(-theta / tau)."""
    return a * np.exp(-np.asarray(theta, dtype=float) / tau)


def gaussian(theta: np.ndarray, a: float, m: float, s: float) -> np.ndarray:
    """a * exp(-(theta - m)^2 / (2 s^2))."""
    z = (np.asarray(theta, dtype=float) - m) / s
    return a * np.exp(-0.5 * z * z)


def logistic(theta: np.ndarray, a: float, t50: float, s: float) -> np.ndarray:
    """a / (1 + exp((theta - t50) / s)); exp overflowing to inf gives the right limit, 0."""
    z = (np.asarray(theta, dtype=float) - t50) / s
    with np.errstate(over="ignore"):
        return a / (1.0 + np.exp(z))


def power_law(theta: np.ndarray, a: float, t50: float, p: float) -> np.ndarray:
    """a / (1 + (theta / t50)^p), theta clipped at 0 (the variable is an absolute magnitude)."""
    ratio = np.maximum(np.asarray(theta, dtype=float), 0.0) / t50
    with np.errstate(over="ignore"):
        return a / (1.0 + ratio**p)


@dataclass(frozen=True)
class DecaySummary:
    """What the starting values and bounds are made of: the sampled range and a first decay length.

    t0, t1 : first and last sampled theta;  span : t1 - t0 (> 0)
    n_max : largest per-theta mean count (at least 1)
    tau0 : decay length of a line fitted to log(1 + mean count) vs theta, clipped to [span/10, 10 span];
           10 span when the counts do not decrease.
    Bounds: scale parameters (tau, s; K >= K_MIN) lie in [span/100, LONGEST_DECAY * span], locations (mu, m, t50)
    in [t0 - 10 span, t1 + LONGEST_DECAY * span], levels (the amplitude of every base function but the
    EMG, whose alpha is an area) in [0, LARGEST_LEVEL * n_max]. Without these caps, flat or purely
    exponential samples open valleys to infinity (alpha, K -> inf in eq. 1; a -> inf, t50 -> -inf for
    the logistic) along which the optimizer walks until its evaluation budget runs out.
    """

    t0: float
    t1: float
    span: float
    n_max: float
    tau0: float

    @classmethod
    def from_samples(cls, theta: np.ndarray, n_inliers: np.ndarray) -> DecaySummary:
        theta_u, index = np.unique(theta, return_inverse=True)
        mean_n = np.bincount(index, weights=n_inliers) / np.bincount(index)
        t0, t1 = float(theta_u[0]), float(theta_u[-1])
        span = t1 - t0
        slope = line_fit(theta_u, np.log1p(mean_n))[1]
        tau0 = -1.0 / slope if slope < 0 else 10.0 * span
        tau0 = float(np.clip(tau0, span / 10.0, 10.0 * span))
        return cls(t0, t1, span, max(float(mean_n.max()), 1.0), tau0)

    @property
    def scale_bounds(self) -> tuple[float, float]:
        return self.span / 100.0, LONGEST_DECAY * self.span

    @property
    def level_bound(self) -> float:
        return LARGEST_LEVEL * self.n_max

    @property
    def location_bounds(self) -> tuple[float, float]:
        return self.t0 - 10.0 * self.span, self.t1 + LONGEST_DECAY * self.span


# Starting shape of each base function and bounds of all its parameters: (shape0, lower, upper), where
# shape0 excludes the amplitude (started at its least squares value) and lower/upper include it.
StartRule = Callable[[DecaySummary], tuple[list[float], list[float], list[float]]]


def _start_emg(s: DecaySummary) -> tuple[list[float], list[float], list[float]]:
    # K ~ decay length; Gaussian centre 2 sigma (2 theta units) before the first sample, so the samples
    # start on the decaying side of the peak. K >= K_MIN (docs/references.md, "SciPy": exponnorm trouble at small K).
    (_, k_hi), (m_lo, m_hi) = s.scale_bounds, s.location_bounds
    return [s.tau0, s.t0 - 2.0], [0.0, K_MIN, m_lo], [np.inf, k_hi, m_hi]


def _start_exponential(s: DecaySummary) -> tuple[list[float], list[float], list[float]]:
    (k_lo, k_hi) = s.scale_bounds
    return [s.tau0], [0.0, k_lo], [s.level_bound, k_hi]


def _start_gaussian(s: DecaySummary) -> tuple[list[float], list[float], list[float]]:
    # half-Gaussian decay from the first sample
    (k_lo, k_hi), (m_lo, m_hi) = s.scale_bounds, s.location_bounds
    return [s.t0, s.tau0], [0.0, m_lo, k_lo], [s.level_bound, m_hi, k_hi]


def _start_logistic(s: DecaySummary) -> tuple[list[float], list[float], list[float]]:
    # half level where the exponential start would have halved; width half the decay length
    (k_lo, k_hi), (m_lo, m_hi) = s.scale_bounds, s.location_bounds
    return [s.t0 + s.tau0 * np.log(2.0), s.tau0 / 2.0], [0.0, m_lo, k_lo], [s.level_bound, m_hi, k_hi]


def _start_power_law(s: DecaySummary) -> tuple[list[float], list[float], list[float]]:
    # half level where the exponential start would have halved; t50 > 0 as theta / t50 is raised to p
    (k_lo, _), (_, m_hi) = s.scale_bounds, s.location_bounds
    return [s.t0 + s.tau0 * np.log(2.0), 2.0], [0.0, k_lo, 0.1], [s.level_bound, m_hi, 20.0]


@dataclass(frozen=True)
class BaseCurve:
    """A base function with its parameters bound: callable theta (m,) -> (m,) (picklable for joblib)."""

    f: Callable[..., np.ndarray]
    p: tuple[float, ...]

    def __call__(self, theta: np.ndarray) -> np.ndarray:
        return self.f(theta, *self.p)


@dataclass(frozen=True)
class BaseFunction:
    """A decay ``f(theta, amplitude, *shape)`` and the rule for its starting values and bounds."""

    name: str
    param_names: tuple[str, ...]  # amplitude first
    f: Callable[..., np.ndarray]
    start_rule: StartRule
    jac: Callable[..., np.ndarray] | None = None  # analytic d f / d params; None: finite differences

    def initial_guess(self, theta: np.ndarray, n_inliers: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Starting values p0 and bounds (lower, upper), each (n_params,), from valid samples.

        Needs at least two distinct theta. The amplitude starts at its least squares value given the
        starting shape: a0 = sum(g n) / sum(g^2), g = f(theta, 1, *shape0).
        """
        shape0, lower, upper = self.start_rule(DecaySummary.from_samples(theta, n_inliers))
        lower, upper = np.array(lower), np.array(upper)
        shape0 = np.clip(shape0, lower[1:], upper[1:])
        g = self.f(theta, 1.0, *shape0)
        gg = float(np.dot(g, g))
        a0 = float(np.dot(g, n_inliers)) / gg if gg > 0 and np.isfinite(gg) else float(n_inliers.max())
        return np.array([np.clip(a0, lower[0], upper[0]), *shape0]), lower, upper

    def fit(self, theta: np.ndarray, n_inliers: np.ndarray, max_nfev: int = 400) -> FittedModel:
        """Fit by scipy.optimize.curve_fit (trf, bounded). Never raises on bad data.

        theta : (m,) float, deg or mm;  n_inliers : (m,) counts (NaN and negative samples are dropped)
        Returns a converged :class:`FittedModel`, or a flagged one (reason given) that predicts with the
        fallback line when there are too few distinct theta, the optimizer fails, or the fit is non-finite.
        """
        theta, n_inliers = valid_samples(theta, n_inliers)
        reason = too_few_samples(theta, len(self.param_names))
        if reason is not None:
            return FittedModel.failed(self.name, self.param_names, reason, theta, n_inliers)
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", OptimizeWarning)  # the covariance is not used
            try:
                p0, lower, upper = self.initial_guess(theta, n_inliers)
                popt, _ = curve_fit(
                    self.f, theta, n_inliers, p0=p0, bounds=(lower, upper), method="trf",
                    jac=self.jac or "2-point", x_scale="jac", max_nfev=max_nfev,
                )  # fmt: skip
            except (RuntimeError, ValueError, np.linalg.LinAlgError) as error:  # e.g. max_nfev exceeded
                return FittedModel.failed(self.name, self.param_names, f"curve_fit: {error}", theta, n_inliers)
            curve = BaseCurve(self.f, tuple(float(v) for v in popt))
            if not np.all(np.isfinite(curve(theta))):
                return FittedModel.failed(self.name, self.param_names, "non-finite fit", theta, n_inliers)
        return FittedModel(
            name=self.name,
            params=dict(zip(self.param_names, curve.p, strict=True)),
            converged=True,
            reason=OK,
            n_samples=int(theta.size),
            curve=curve,
            fallback=FallbackLine.fit(theta, n_inliers),
        )


EMG = BaseFunction("emg", ("alpha", "K", "mu"), emg, _start_emg, emg_jacobian)
BASE_FUNCTIONS: dict[str, BaseFunction] = {
    b.name: b
    for b in (
        EMG,
        BaseFunction("exponential", ("a", "tau"), exponential, _start_exponential),
        BaseFunction("gaussian", ("a", "m", "s"), gaussian, _start_gaussian),
        BaseFunction("logistic", ("a", "t50", "s"), logistic, _start_logistic),
        BaseFunction("power_law", ("a", "t50", "p"), power_law, _start_power_law),
    )
}
