"""What every artifact-model fitter returns: a fitted model f: theta -> n_inliers, its status, a fallback.

Windsor et al. III-D fit the artifact model thousands of times unattended (every dataset, every k, every
step of the next-step predictor), so a fit never raises: it returns a :class:`FittedModel` whose ``status``
and ``reason`` say what happened. Statuses, from the most to the least severe (:data:`FIT_STATUSES`):

    "fallback"      the fit could not be done (too few distinct theta, optimizer error, non-finite curve):
                    ``predict`` uses a straight line through the samples (clipped at zero inliers) instead
    "non_physical"  the fitted curve, evaluated over [first stop, range end], predicts a count that rounds below
                    zero, does not fall from the first stop to the range end (a decay is what the artifact
                    model stands for, III-D), or exceeds LARGEST_LEVEL times the largest mean count sampled; or it
                    does not follow its own samples: its RMSE on them exceeds LACK_OF_FIT times their noise and is
                    no better than their mean's (e.g. rising counts fitted by a decay family)
    "at_bound"      a least squares parameter ended at one of its bounds (base_functions.DecaySummary): the data
                    wanted a curve outside the family allowed, e.g. a decay longer than 20 sampled spans
    "ok"            none of these

Only "fallback" changes what ``predict`` returns. A fit at a bound or a non-physical one still predicts with its
fitted curve: that is what the predictor of III-E would act on (it has no other curve), so its theta_p counts in
the SPL / R_i sweeps as the robot would really have moved; the tables carry the status beside every row and the
metrics count them (fits.json, predictors.json), so that no such fit is ever reported as a clean one.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from poseintegrity.errors import ArgumentError, check_scalar
from poseintegrity.table_checks import FIT_STATUSES  # the fits tables' status column: least to most severe

OK, AT_BOUND, NON_PHYSICAL, FALLBACK = FIT_STATUSES
LARGEST_LEVEL = 10.0  # largest count level a model may predict or a level parameter take, in largest mean counts
NEGATIVE_COUNT = -0.5  # a prediction below this rounds to a negative inlier count
ONE_INLIER = 0.5  # a prediction from this on rounds to at least one inlier
LACK_OF_FIT = 3.0  # a fit's RMSE on its own samples above this many noise levels, and no better than their mean: flagged
NO_BETTER_THAN_MEAN = 0.9  # ... "no better": RMSE at least this share of the mean's (R^2 below 0.19)
MAX_THETA = 1e6  # |theta| and range ends beyond a million deg or mm are not a trajectory
CHECK_POINTS = 181  # grid of the physical check over [first stop, range end] (0.25 deg steps over a 45 deg arc)


def worst(statuses) -> str:
    """The most severe of some fit statuses (:data:`FIT_STATUSES` order); "ok" for none."""
    return FIT_STATUSES[max((FIT_STATUSES.index(s) for s in statuses), default=0)]


def valid_samples(theta: np.ndarray, n_inliers: np.ndarray, theta_end: float | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Drop samples that cannot be counts: non-finite theta or n, and negative n.

    theta : (m,) float, the independent variable (deg for arcs, mm for lines)
    n_inliers : (m,) float, inlier counts (0 is a valid count: a failed frame)
    theta_end : when given (every fitter passes its range end), checked: a finite number not before the first
        valid sample (a NaN or early range end would skip the physical check of the fit)
    Returns the kept (theta, n_inliers), both (m',) float. :class:`~poseintegrity.errors.ArgumentError` naming the
    argument when theta and n_inliers differ in length, hold something other than numbers, or theta_end is bad.
    """
    try:
        theta = np.asarray(theta, dtype=float).ravel()
        n_inliers = np.asarray(n_inliers, dtype=float).ravel()
    except (TypeError, ValueError) as error:
        raise ArgumentError(f"theta, n_inliers: expected numbers ({error})") from None
    if theta.shape != n_inliers.shape:
        raise ArgumentError(f"theta {theta.shape} and n_inliers {n_inliers.shape} differ in length")
    keep = np.isfinite(theta) & np.isfinite(n_inliers) & (n_inliers >= 0)
    theta, n_inliers = theta[keep], n_inliers[keep]
    if theta_end is not None:
        check_scalar("theta_end", theta_end, low=-MAX_THETA, high=MAX_THETA)
        if theta.size and theta_end < theta.min():
            raise ArgumentError(f"theta_end: the range end {theta_end:g} lies before the first sample "
                                f"{theta.min():g}: the fit could not be checked up to it")
    return theta, n_inliers


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


def per_theta_means(theta: np.ndarray, n_inliers: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(distinct theta, mean count at each) of valid samples : (s,), (s,), theta increasing."""
    theta_u, index = np.unique(theta, return_inverse=True)
    return theta_u, np.bincount(index, weights=n_inliers) / np.bincount(index)


def largest_mean_count(theta: np.ndarray, n_inliers: np.ndarray) -> float:
    """The largest per-theta mean count of valid samples, at least 1: the scale of a dataset's counts."""
    return max(float(per_theta_means(theta, n_inliers)[1].max()), 1.0) if theta.size else 1.0


def check_grid(theta: np.ndarray, theta_end: float) -> np.ndarray:
    """The points of the physical check: [first sampled theta, theta_end] : (CHECK_POINTS,) (the first sample alone
    when it lies at the range end). ArgumentError when theta_end is not finite or lies before the first sample."""
    first = float(np.min(theta))
    if not (np.isfinite(theta_end) and theta_end >= first):
        raise ArgumentError(f"theta_end: expected a finite range end at or after the first sample {first:g}, "
                            f"got {theta_end!r}")
    return np.linspace(first, theta_end, CHECK_POINTS) if theta_end > first else np.array([first])


def non_finite(curve: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, grid: np.ndarray) -> str | None:
    """Why ``curve`` cannot be used (a non-finite value at a sample or on the check grid); None if it can."""
    for where, points in (("a sample", theta), ("the range", grid)):
        with np.errstate(all="ignore"):
            finite = np.all(np.isfinite(curve(points)))
        if not finite:
            return f"non-finite prediction at {where}"
    return None


def physical_problems(curve: Callable[[np.ndarray], np.ndarray], grid: np.ndarray, n_max: float) -> list[str]:
    """What makes a finite fitted curve non-physical over ``grid`` (first stop .. range end); [] if nothing.

    A count that rounds below zero (< NEGATIVE_COUNT); a curve that does not fall from the first stop to the range
    end while it predicts at least one inlier somewhere (III-D: n_i decays with the viewing angle; a curve at zero
    everywhere is a physical answer); a count above LARGEST_LEVEL x n_max, the largest per-theta mean count sampled
    (the cap on the levels of the base functions, base_functions.DecaySummary).
    """
    f = curve(grid)
    problems = []
    low = int(np.argmin(f))
    if f[low] < NEGATIVE_COUNT:
        problems.append(f"negative count {f[low]:.3g} at theta {grid[low]:.4g}")
    if grid.size > 1 and f.max() >= ONE_INLIER and f[-1] >= f[0]:
        problems.append(f"no decay: {f[-1]:.4g} inliers at the range end {grid[-1]:.4g} >= {f[0]:.4g} at the first "
                        f"stop {grid[0]:.4g}")
    high = int(np.argmax(f))
    if f[high] > LARGEST_LEVEL * n_max:
        problems.append(f"count {f[high]:.3g} at theta {grid[high]:.4g} > {LARGEST_LEVEL:g} x the largest mean "
                        f"count sampled ({n_max:.4g})")
    return problems


def lack_of_fit(curve: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, n_inliers: np.ndarray) -> str | None:
    """Why a finite curve does not follow its own samples; None if it does.

    Flagged when its RMSE on the samples exceeds LACK_OF_FIT noise levels and is at least NO_BETTER_THAN_MEAN of
    the RMSE of their mean (the curve explains almost nothing of them). Noise: the pooled standard deviation of the
    counts at a repeated theta, at least sqrt(mean count) (counting noise) and 1 inlier.
    """
    rmse = float(np.sqrt(np.mean((curve(theta) - n_inliers) ** 2)))
    theta_u, index = np.unique(theta, return_inverse=True)
    means = np.bincount(index, weights=n_inliers) / np.bincount(index)
    repeats = theta.size - theta_u.size
    pooled = float(np.sqrt(np.sum((n_inliers - means[index]) ** 2) / repeats)) if repeats else 0.0
    noise = max(pooled, float(np.sqrt(max(n_inliers.mean(), 0.0))), 1.0)
    flat = float(np.sqrt(np.mean((n_inliers - n_inliers.mean()) ** 2)))
    if rmse > LACK_OF_FIT * noise and rmse >= NO_BETTER_THAN_MEAN * flat:
        return (f"lack of fit: RMSE {rmse:.3g} on its own samples > {LACK_OF_FIT:g} x their noise {noise:.3g} and no "
                f"better than their mean's {flat:.3g}")
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
    status : one of :data:`FIT_STATUSES` (module docstring); ``predict`` uses ``fallback`` when it is "fallback"
    reason : "ok" or every problem found, e.g. "at bound: K = 135 (upper); no decay: ..."
    n_samples : valid samples the fit used
    curve : the fitted f, theta (m,) -> (m,); the fallback line's when the fit could not be done
    fallback : the straight line used when the fit could not be done
    """

    name: str
    params: Mapping[str, float]
    status: str
    reason: str
    n_samples: int
    curve: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    fallback: FallbackLine

    def __post_init__(self) -> None:
        if self.status not in FIT_STATUSES:
            raise ArgumentError(f"unknown fit status {self.status!r}; expected one of {FIT_STATUSES}")

    @property
    def has_curve(self) -> bool:
        """True when ``predict`` uses the fitted curve (any status but "fallback")."""
        return self.status != FALLBACK

    def predict(self, theta: np.ndarray) -> np.ndarray:
        """Predicted inlier count at theta : (m,) float -> (m,) float (the fallback line for a "fallback" fit)."""
        theta = np.atleast_1d(np.asarray(theta, dtype=float))
        return self.curve(theta) if self.has_curve else self.fallback.predict(theta)

    @classmethod
    def failed(
        cls, name: str, param_names: tuple[str, ...], reason: str, theta: np.ndarray, n_inliers: np.ndarray
    ) -> FittedModel:
        """The flagged result of a fit that could not be done: status "fallback"."""
        fallback = FallbackLine.fit(theta, n_inliers)
        return cls(
            name=name,
            params={key: float("nan") for key in param_names},
            status=FALLBACK,
            reason=reason,
            n_samples=int(theta.size),
            curve=fallback.predict,
            fallback=fallback,
        )

    @classmethod
    def checked(
        cls, name: str, params: Mapping[str, float], curve: Callable[[np.ndarray], np.ndarray], theta: np.ndarray,
        n_inliers: np.ndarray, theta_end: float, at_bound: list[str] = (),
    ) -> FittedModel:  # fmt: skip
        """A fitted curve with its status: "fallback" if it is non-finite at a sample or over [first stop,
        theta_end], else "non_physical" / "at_bound" / "ok" (module docstring). ``at_bound`` : the parameters
        that ended at a bound, e.g. ["K = 135 (upper)"]. theta, n_inliers : (m,) the valid samples fitted."""
        grid = check_grid(theta, theta_end)
        broken = non_finite(curve, theta, grid)
        if broken is not None:
            return cls.failed(name, tuple(params), broken, theta, n_inliers)
        with np.errstate(all="ignore"):
            problems = physical_problems(curve, grid, largest_mean_count(theta, n_inliers))
            problems += [poor] if (poor := lack_of_fit(curve, theta, n_inliers)) else []
        bounds = [f"at bound: {', '.join(at_bound)}"] if at_bound else []
        status = NON_PHYSICAL if problems else AT_BOUND if at_bound else OK
        return cls(
            name=name,
            params=dict(params),
            status=status,
            reason="; ".join([*problems, *bounds]) or OK,
            n_samples=int(theta.size),
            curve=curve,
            fallback=FallbackLine.fit(theta, n_inliers),
        )
