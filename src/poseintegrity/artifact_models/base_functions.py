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
A fit whose parameters end at a bound is flagged "at_bound" (fitted.py): the samples wanted a curve outside them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.special import erfc, erfcx

from poseintegrity.artifact_models.fitted import (
    LARGEST_LEVEL,
    FittedModel,
    line_fit,
    per_theta_means,
    too_few_samples,
    valid_samples,
)

K_MIN = 0.05  # lower bound of the EMG shape K: exponnorm misbehaves as K -> 0 (docs/references.md, "SciPy")
LONGEST_DECAY = 20.0  # longest decay length (K, tau, s) a fit may choose, in sampled spans


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
    """d eq.(1) / d(alpha, K, mu) : (m, 3), for the least squares fit (the EMG fit has a speed target).

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
        theta_u, mean_n = per_theta_means(theta, n_inliers)
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
    """A base function with its parameters bound: callable theta (m,) -> (m,) (picklable for the workers)."""

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

    def fit(self, theta: np.ndarray, n_inliers: np.ndarray, *, theta_end: float, max_nfev: int) -> FittedModel:
        """Fit by bounded non-linear least squares (trf), as scipy.optimize.curve_fit does. Never raises on bad data.

        theta : (m,) float, deg or mm;  n_inliers : (m,) counts (NaN and negative samples are dropped)
        theta_end : end of the range (deg or mm), up to which the fitted curve is checked (fitted.py)
        max_nfev : evaluation budget of the optimizer (``fit.max_nfev``)
        Returns a :class:`FittedModel` whose status says whether the fit is "ok", "at_bound" (a parameter ended at a
        bound: scipy.optimize.least_squares' ``active_mask``), "non_physical", or "fallback" (too few distinct
        theta, the optimizer failed, or a non-finite curve).
        """
        theta, n_inliers = valid_samples(theta, n_inliers)
        reason = too_few_samples(theta, len(self.param_names))
        if reason is not None:
            return FittedModel.failed(self.name, self.param_names, reason, theta, n_inliers)
        # curve_fit(method="trf") is this least_squares call (same residuals, Jacobian and options, hence the same
        # parameters); called directly for its active_mask, which curve_fit does not return
        jac = (lambda p: self.jac(theta, *p)) if self.jac else "2-point"
        with np.errstate(all="ignore"):
            try:
                p0, lower, upper = self.initial_guess(theta, n_inliers)
                result = least_squares(
                    lambda p: self.f(theta, *p) - n_inliers, p0, jac=jac, bounds=(lower, upper), method="trf",
                    x_scale="jac", max_nfev=max_nfev,
                )  # fmt: skip
            except (ValueError, np.linalg.LinAlgError) as error:  # e.g. residuals not finite at p0
                return FittedModel.failed(self.name, self.param_names, f"least squares: {error}", theta, n_inliers)
            if not result.success:  # e.g. max_nfev exceeded
                return FittedModel.failed(self.name, self.param_names, f"least squares: {result.message}", theta,
                                          n_inliers)  # fmt: skip
            curve = BaseCurve(self.f, tuple(float(v) for v in result.x))
            at_bound = [f"{name} = {value:.4g} ({'lower' if side < 0 else 'upper'})"
                        for name, value, side in zip(self.param_names, curve.p, result.active_mask, strict=True)
                        if side != 0]  # fmt: skip
            return FittedModel.checked(self.name, dict(zip(self.param_names, curve.p, strict=True)), curve, theta,
                                       n_inliers, theta_end, at_bound)  # fmt: skip


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
