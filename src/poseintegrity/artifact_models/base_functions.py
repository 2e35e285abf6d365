"""Base functions of the artifact model n_inliers = f(theta), fitted by bounded non-linear least squares.

Windsor et al. III-D compare decays fitted with scipy.optimize.curve_fit and choose the scaled
exponentially modified Gaussian (EMG) of eq. 1. Every base function here is amplitude * shape(theta):

    emg          alpha * exponnorm.pdf(theta - mu, K)            (eq. 1, scale fixed at 1 theta unit)
    exponential  a * exp(-theta / tau)
    gaussian     a * exp(-(theta - m)^2 / (2 s^2))
    logistic     a / (1 + exp((theta - t50) / s))
    power_law    a / (1 + (theta / t50)^p)                       (Hill / log-logistic; tail ~ theta^-p)

and, beside them (ours, not the paper's; not in Fig. 2's comparison set :data:`BASE_FUNCTIONS`):

    emg_free_width  alpha * exponnorm.pdf((theta - mu) / sigma, K) / sigma   (eq. 1 with its Gaussian width sigma
                 fitted; sigma = 1 is eq. 1. With sigma fixed at 1 theta unit eq. 1 is a shifted exponential past
                 its peak: it cannot bend down into a cliff after a shoulder, a broad Gaussian part can)

Starting values and bounds are derived from the samples (see :class:`DecaySummary` and each ``_start_*``):
a decay length tau0 from a log-linear fit of the per-theta mean counts sets every scale parameter,
bounds are multiples of the sampled span, and the amplitude starts at its linear least squares
value given the starting shape. All theta units are those of the data (deg for arcs, mm for lines).
The free-width EMG is fitted from two starts (:class:`FreeWidthEMG`) and keeps the one of least cost.
A fit whose parameters end at a bound is flagged "at_bound" (fitted.py): the samples wanted a curve outside them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import OptimizeResult, least_squares
from scipy.special import erfc, erfcx

from poseintegrity.artifact_models.fitted import (
    LARGEST_LEVEL,
    FittedModel,
    line_fit,
    per_theta_means,
    too_few_samples,
    valid_samples,
)
from poseintegrity.params.model_names import LEAST_SQUARES_PARAMETERS as PARAMETERS

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


def emg_pdf_derivatives(x: np.ndarray, K: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(g, dg/dx, dg/dK) of g = exponnorm.pdf(x, K) = :func:`emg_pdf`, each (m,) for x : (m,).

    With phi the standard normal pdf, exp(1/(2K^2) - x/K) phi(x - 1/K) = phi(x), hence dg/dx = (phi - g) / K and
    dg/dK = g (x/K^2 - 1/K - 1/K^3) + phi / K^3.
    """
    g = emg_pdf(x, K)
    phi = np.exp(-0.5 * x * x) / np.sqrt(2.0 * np.pi)
    return g, (phi - g) / K, g * (x / K**2 - 1.0 / K - 1.0 / K**3) + phi / K**3


def emg_jacobian(theta: np.ndarray, alpha: float, K: float, mu: float) -> np.ndarray:
    """d eq.(1) / d(alpha, K, mu) : (m, 3), for the least squares fit (the EMG fit has a speed target).

    With x = theta - mu and g = exponnorm.pdf(x, K) (:func:`emg_pdf_derivatives`): (g, alpha dg/dK, -alpha dg/dx).
    """
    g, dg_dx, dg_dK = emg_pdf_derivatives(np.asarray(theta, dtype=float) - mu, K)
    return np.stack([g, alpha * dg_dK, -alpha * dg_dx], axis=1)


def emg_free_width(theta: np.ndarray, alpha: float, K: float, mu: float, sigma: float) -> np.ndarray:
    """Eq. (1) with a free Gaussian width (ours): alpha * exponnorm.pdf((theta - mu) / sigma, K) / sigma.

    scipy's exponnorm with ``loc=mu, scale=sigma`` (docs/references.md, "SciPy"): a Gaussian of width sigma (theta
    units) convolved with an exponential of decay length K sigma; alpha stays the area. sigma = 1 is eq. 1 to the bit
    (the same operations).
    theta : (m,) -> (m,) inliers
    """
    return alpha / sigma * emg_pdf((np.asarray(theta, dtype=float) - mu) / sigma, K)


def emg_free_width_jacobian(theta: np.ndarray, alpha: float, K: float, mu: float, sigma: float) -> np.ndarray:
    """d emg_free_width / d(alpha, K, mu, sigma) : (m, 4).

    With z = (theta - mu) / sigma, g = exponnorm.pdf(z, K) and c = alpha / sigma: f = c g, so
    df/dalpha = g / sigma, df/dK = c dg/dK, df/dmu = -c dg/dz / sigma, df/dsigma = -c (g + z dg/dz) / sigma.
    """
    z = (np.asarray(theta, dtype=float) - mu) / sigma
    g, dg_dz, dg_dK = emg_pdf_derivatives(z, K)
    c = alpha / sigma
    return np.stack([g / sigma, c * dg_dK, -c * dg_dz / sigma, -c * (g + z * dg_dz) / sigma], axis=1)


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


def _start_emg_free_width(s: DecaySummary) -> tuple[list[float], list[float], list[float]]:
    # the broad start: a half-Gaussian decay from the first sample (K at its least, sigma ~ the decay length), the
    # shoulder-and-cliff shape eq. 1 cannot take; FreeWidthEMG adds eq. 1's own fit as a second start. sigma's bounds
    # are the scale bounds widened to contain eq. 1's sigma = 1 theta unit, K (the decay length in sigmas) may reach
    # eq. 1's longest decay at the narrowest sigma: eq. 1's box at sigma = 1 lies inside, whatever the span.
    (k_lo, k_hi), (m_lo, m_hi) = s.scale_bounds, s.location_bounds
    s_lo, s_hi = min(k_lo, 1.0), max(k_hi, 1.0)
    return [K_MIN, s.t0, s.tau0], [0.0, K_MIN, m_lo, s_lo], [np.inf, k_hi / s_lo, m_hi, s_hi]


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

    def starts(self, theta: np.ndarray, n_inliers: np.ndarray, max_nfev: int
               ) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:  # fmt: skip
        """Starting points, each (n_params,), and the bounds (lower, upper) of the fit: one, :meth:`initial_guess`'s."""
        p0, lower, upper = self.initial_guess(theta, n_inliers)
        return [p0], lower, upper

    def solve(self, theta: np.ndarray, n_inliers: np.ndarray, p0: np.ndarray, lower: np.ndarray, upper: np.ndarray,
              max_nfev: int) -> OptimizeResult:  # fmt: skip
        """Bounded least squares (trf) from p0 on valid samples; raises ValueError when the residuals are not finite.

        curve_fit(method="trf") is this least_squares call (same residuals, Jacobian and options, hence the same
        parameters); called directly for its active_mask, which curve_fit does not return.
        """
        jac = (lambda p: self.jac(theta, *p)) if self.jac else "2-point"
        return least_squares(lambda p: self.f(theta, *p) - n_inliers, p0, jac=jac, bounds=(lower, upper),
                             method="trf", x_scale="jac", max_nfev=max_nfev)  # fmt: skip

    def fit(self, theta: np.ndarray, n_inliers: np.ndarray, *, theta_end: float, max_nfev: int) -> FittedModel:
        """Fit by bounded non-linear least squares (trf), as scipy.optimize.curve_fit does. Never raises on bad data.

        theta : (m,) float, deg or mm;  n_inliers : (m,) counts (NaN and negative samples are dropped)
        theta_end : end of the range (deg or mm), up to which the fitted curve is checked (fitted.py)
        max_nfev : evaluation budget of the optimizer from each start (``fit.max_nfev``)
        From several starts (:meth:`starts`) the converged result of least cost is kept; when none converged, the
        first start's failure is reported.
        Returns a :class:`FittedModel` whose status says whether the fit is "ok", "at_bound" (a parameter ended at a
        bound: scipy.optimize.least_squares' ``active_mask``), "non_physical", or "fallback" (too few distinct
        theta, the optimizer failed, or a non-finite curve).
        """
        theta, n_inliers = valid_samples(theta, n_inliers, theta_end)
        reason = too_few_samples(theta, len(self.param_names))
        if reason is not None:
            return FittedModel.failed(self.name, self.param_names, reason, theta, n_inliers)
        with np.errstate(all="ignore"):
            try:
                starts, lower, upper = self.starts(theta, n_inliers, max_nfev)
            except (ValueError, np.linalg.LinAlgError) as error:
                return FittedModel.failed(self.name, self.param_names, f"least squares: {error}", theta, n_inliers)
            results, failures = [], []
            for p0 in starts:
                try:
                    result = self.solve(theta, n_inliers, p0, lower, upper, max_nfev)
                except (ValueError, np.linalg.LinAlgError) as error:  # e.g. residuals not finite at p0
                    failures.append(f"least squares: {error}")
                    continue
                if result.success:
                    results.append(result)
                else:  # e.g. max_nfev exceeded
                    failures.append(f"least squares: {result.message}")
            if not results:
                return FittedModel.failed(self.name, self.param_names, failures[0], theta, n_inliers)
            result = min(results, key=lambda r: r.cost)  # the first of equal costs
            curve = BaseCurve(self.f, tuple(float(v) for v in result.x))
            at_bound = [f"{name} = {value:.4g} ({'lower' if side < 0 else 'upper'})"
                        for name, value, side in zip(self.param_names, curve.p, result.active_mask, strict=True)
                        if side != 0]  # fmt: skip
            return FittedModel.checked(self.name, dict(zip(self.param_names, curve.p, strict=True)), curve, theta,
                                       n_inliers, theta_end, at_bound)  # fmt: skip


@dataclass(frozen=True)
class FreeWidthEMG(BaseFunction):
    """The free-width EMG (ours), started from a broad half-Gaussian (its start rule) and from eq. 1's own least
    squares fit with sigma = 1 (eq. 1 is its member at sigma = 1, inside its bounds). trf only accepts steps that lower
    the cost, so when the second start converges the fit never fits the samples worse than eq. 1 does."""

    def starts(self, theta: np.ndarray, n_inliers: np.ndarray, max_nfev: int
               ) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:  # fmt: skip
        (broad,), lower, upper = super().starts(theta, n_inliers, max_nfev)
        try:
            eq1 = EMG.solve(theta, n_inliers, *EMG.initial_guess(theta, n_inliers), max_nfev)
        except (ValueError, np.linalg.LinAlgError):  # eq. 1 could not start: the broad start alone
            return [broad], lower, upper
        return ([broad, np.clip([*eq1.x, 1.0], lower, upper)] if eq1.success else [broad]), lower, upper


EMG = BaseFunction("emg", PARAMETERS["emg"], emg, _start_emg, emg_jacobian)
# The least squares base functions of Fig. 2 (III-D): eq. 1 and the decays it was compared with (stage 02's realism
# bar R1 compares them, as the paper did)
BASE_FUNCTIONS: dict[str, BaseFunction] = {
    b.name: b
    for b in (
        EMG,
        BaseFunction("exponential", PARAMETERS["exponential"], exponential, _start_exponential),
        BaseFunction("gaussian", PARAMETERS["gaussian"], gaussian, _start_gaussian),
        BaseFunction("logistic", PARAMETERS["logistic"], logistic, _start_logistic),
        BaseFunction("power_law", PARAMETERS["power_law"], power_law, _start_power_law),
    )
}
EMG_FREE_WIDTH = FreeWidthEMG("emg_free_width", PARAMETERS["emg_free_width"], emg_free_width, _start_emg_free_width,
                              emg_free_width_jacobian)  # fmt: skip
# Every least squares model fit_model knows: the paper's base functions and ours beside eq. 1
LEAST_SQUARES: dict[str, BaseFunction] = {**BASE_FUNCTIONS, EMG_FREE_WIDTH.name: EMG_FREE_WIDTH}
