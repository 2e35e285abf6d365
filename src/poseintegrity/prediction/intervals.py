"""Intervals on the headlines of Tables I-III: a scene-clustered bootstrap and leave-one-arc-out (ours, issue 49).

The headline of Windsor et al. (the max mean SPL at zero incursion, eqs. 3-4) is an extreme value: the worst arc sets
the static baseline (the smallest theta_a) and often the operating point (the one arc that would incur at the next
bolder n_t). Over 21 arcs one arc moves it by tens of points of the ceiling. So every headline carries

- a **bootstrap interval**: each draw resamples the scenes with replacement (a scene's arcs go together: they share the
  target, its layout, the model pair and the boards), weights each arc by how often its scene was drawn, and repeats
  the whole selection a user would make on that table: every predictor's operating point chosen again at zero incursion
  (:func:`select`, as :func:`~.metrics.best_operating_point`), the static baseline's size too, and the ceiling's mean
  theta_a of the draw's arcs (:mod:`.ceiling`). Percentile interval at ``level`` (0.9: the 5-95 % of the draws);
- a **leave-one-arc-out range**: the same selection with each arc left out once, min .. max over the arcs;
- for two predictors, the **paired difference** of their max mean SPL on the same draws and P(A > B), the share of
  draws in which A's is larger.

A draw in which a predictor has no operating point at zero incursion (no n_t keeps every drawn arc safe) has no SPL:
it counts as worse than any SPL (``-inf`` in the quantiles; shown as null), and ``no_point_share`` says how often.

Per draw (module :mod:`.ceiling`): gain = SPL - static SPL (deg), share = gain / (mean theta_a - static SPL). A share is
a ratio: where a draw's mean theta_a lies near its static SPL the denominator is small and the share swings, so the
gain in degrees is reported beside it.

The draws are :func:`poseintegrity.resampling.cluster_weights` (why not ``scipy.stats.bootstrap``: there).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from poseintegrity.prediction.loso import scene_of
from poseintegrity.prediction.sweeps import CONSERVATIVE_HIGH
from poseintegrity.resampling import cluster_weights, percentile_interval
from poseintegrity.seeding import keyed_rng

INTERVAL_METHOD = ("percentile interval of a scene-clustered bootstrap (a scene's arcs drawn together; a world's lines "
                   "one by one), the operating point chosen again at zero incursion in each draw")
TIE_DEG = 1e-9  # mean SPLs closer than this are one value: the conservative operating point among them is taken


def leave_one_out_weights(d: int) -> np.ndarray:
    """(d, d) weights: row i leaves arc i out, every other arc once."""
    return 1.0 - np.eye(d)


@dataclass(frozen=True)
class Family:
    """One curve family of a prediction table (a predictor, PnP method, trajectory type and tolerance) as arrays over
    its d datasets and p operating points: ``spl`` (d, p) SPL of eq. 3 (0 where flagged), ``incurs`` (d, p) an incursion
    of eq. 4, ``valid`` (d, p) a theta_p was found (flagged rows, theta_p NaN, are left out of the curves, as in
    :func:`~.metrics.operating_curves`); ``theta_a`` (d,) deg or mm; ``points`` (p,) the operating points."""

    datasets: np.ndarray
    points: np.ndarray
    spl: np.ndarray
    incurs: np.ndarray
    valid: np.ndarray
    theta_a: np.ndarray


def family(rows: pd.DataFrame, datasets: np.ndarray) -> Family:
    """The :class:`Family` of prediction-table ``rows`` (one predictor, method, trajectory and tolerance; columns
    dataset, operating_point, theta_p, theta_a, spl, incursion) on the ``datasets`` order given; a (dataset,
    operating point) without a row is not valid."""
    points = np.sort(rows["operating_point"].unique())
    shape = (len(datasets), len(points))
    at = (pd.Index(datasets).get_indexer(rows["dataset"]), np.searchsorted(points, rows["operating_point"]))
    spl, incurs, valid = np.zeros(shape), np.zeros(shape, bool), np.zeros(shape, bool)
    found = rows["theta_p"].notna().to_numpy()
    valid[at] = found
    spl[at] = np.where(found, rows["spl"].to_numpy(dtype=float), 0.0)
    incurs[at] = found & (rows["incursion"].to_numpy(dtype=float) == 1.0)
    theta_a = rows.drop_duplicates("dataset").set_index("dataset")["theta_a"].reindex(datasets).to_numpy(dtype=float)
    return Family(np.asarray(datasets), points, spl, incurs, valid, theta_a)


def curves(fam: Family, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(mean SPL, incursion rate R_i), each (b, p), of the family's curve under b weight vectors (b, d): eq. 3's mean
    and eq. 4's I / n with each arc counted as often as its weight. NaN where no weighted arc has a theta_p."""
    n = weights @ fam.valid
    with np.errstate(invalid="ignore", divide="ignore"):
        return (weights @ fam.spl) / np.where(n > 0, n, np.nan), (weights @ fam.incurs) / np.where(n > 0, n, np.nan)


def select(fam: Family, weights: np.ndarray, conservative_high: bool, max_rate: float = 0.0
           ) -> tuple[np.ndarray, np.ndarray]:
    """(max mean SPL at R_i <= ``max_rate``, its operating point), each (b,), under b weight vectors (b, d): the
    selection of Tables I-III (:func:`~.metrics.best_operating_point`) repeated per weight vector, ties (within
    TIE_DEG) going to the largest operating point (``conservative_high``: n_t, k) or the smallest (a static size). NaN
    where no operating point is that safe."""
    mean, rate = curves(fam, weights)
    safe = rate <= max_rate
    masked = np.where(safe, mean, -np.inf)
    best = masked.max(axis=1, initial=-np.inf)
    tied = safe & (masked >= best[:, None] - TIE_DEG)
    points = np.where(tied, fam.points, -np.inf if conservative_high else np.inf)
    point = points.max(axis=1, initial=-np.inf) if conservative_high else points.min(axis=1, initial=np.inf)
    none = ~np.isfinite(best)
    return np.where(none, np.nan, best), np.where(none, np.nan, point)


@dataclass(frozen=True)
class Draws:
    """The headline figures of one method, trajectory and tolerance under b weight vectors (b,): per predictor its max
    mean SPL at zero incursion (``spl``, NaN: no operating point), and per weight vector the static baseline's
    (``static``) and the ceiling's mean theta_a (``mean_theta_a``)."""

    spl: dict[str, np.ndarray]
    static: np.ndarray
    mean_theta_a: np.ndarray

    def gain(self, predictor: str) -> np.ndarray:
        """SPL - static SPL (deg or mm), NaN where the predictor has no operating point."""
        return self.spl[predictor] - self.static

    def relative_gain(self, predictor: str) -> np.ndarray:
        """SPL / static SPL - 1, as Tables I-II give it (0.76 = +76 %); NaN where static's SPL is not positive."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.static > 0, self.gain(predictor) / np.where(self.static > 0, self.static, 1.0), np.nan)

    def share(self, predictor: str) -> np.ndarray:
        """(SPL - static SPL) / (mean theta_a - static SPL); NaN where the gap is not positive (nothing to share)."""
        gap = self.mean_theta_a - self.static
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(gap > 0, self.gain(predictor) / np.where(gap > 0, gap, 1.0), np.nan)


def headline_draws(rows: pd.DataFrame, predictors: tuple[str, ...], weights_for) -> tuple[Draws, np.ndarray]:
    """(:class:`Draws`, the arcs (d,) in weight order) of prediction-table ``rows`` of one method, trajectory and
    tolerance. ``weights_for`` maps the arcs (d,) to the (b, d) weights
    (:func:`~poseintegrity.resampling.cluster_weights`, :func:`leave_one_out_weights`). The arcs are static's (every scored dataset has a static row)."""
    datasets = np.sort(rows.loc[rows["predictor"] == "static", "dataset"].unique())
    weights = weights_for(datasets)
    by_predictor = {p: part for p, part in rows.groupby("predictor", sort=False)}
    static = family(by_predictor["static"], datasets)
    spl = {p: select(family(by_predictor[p], datasets), weights, CONSERVATIVE_HIGH.get(p, True))[0]
           for p in predictors if p in by_predictor}
    mean_theta_a = (weights @ static.theta_a) / weights.sum(axis=1)
    return Draws(spl, select(static, weights, False)[0], mean_theta_a), datasets


def _ranked(values: np.ndarray) -> np.ndarray:
    """NaN (no operating point) as -inf: worse than any SPL or gain."""
    return np.where(np.isnan(values), -np.inf, values)


def _range(values: np.ndarray) -> list[float | None]:
    """[min, max] of leave-one-out values (NaN: ranked lowest); a bound at -inf, or of no value at all, is None."""
    if values.size == 0:
        return [None, None]
    return [float(v) if np.isfinite(v) else None for v in (values.min(), values.max())]


def _figures(draws: Draws, predictor: str) -> dict[str, np.ndarray]:
    """The predictor's max mean SPL, gain, relative gain and ceiling share per draw, a draw without an operating point
    at -inf in each (a ratio without a denominator, NaN, is left out)."""
    none = np.isnan(draws.spl[predictor])
    return {"max_mean_spl": _ranked(draws.spl[predictor]), "gain": _ranked(draws.gain(predictor)),
            "relative_gain": np.where(none, -np.inf, draws.relative_gain(predictor)),
            "ceiling_share": np.where(none, -np.inf, draws.share(predictor))}


def _paired(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """A - B per draw with a missing operating point ranked lowest: both missing 0, A alone -inf, B alone +inf."""
    both, only_a, only_b = np.isnan(a) & np.isnan(b), np.isnan(a) & ~np.isnan(b), ~np.isnan(a) & np.isnan(b)
    return np.select([both, only_a, only_b], [0.0, -np.inf, np.inf], default=a - b)


def headline_intervals(rows: pd.DataFrame, predictors: tuple[str, ...], pairs: tuple[tuple[str, str], ...],
                       n_draws: int, level: float, rng: np.random.Generator,
                       cluster_of: Callable[[str], str] = scene_of) -> dict:
    """The intervals of one method, trajectory and tolerance of a prediction table (module docstring), JSON-ready:

    ``{n_arcs, n_scenes, <predictor>: {max_mean_spl, gain, relative_gain, ceiling_share, no_point_share,
    leave_one_arc_out: {the same four}}, pairs: {"<A> vs <B>": {point, difference, p_better}}}`` (``point``: A's max
    mean SPL less B's on the whole table); each
    interval a [low, high] pair (None: a bound without an operating point). ``rows``: the prediction table's rows of
    that method, trajectory and tolerance (every predictor's; static's must be among them). ``cluster_of`` names what
    is drawn as a whole from a dataset id: its scene (:func:`~.loso.scene_of`), or the dataset itself (``str``).
    """
    if not (rows["predictor"] == "static").any():
        return {"n_arcs": 0, "n_scenes": 0}
    draws, datasets = headline_draws(rows, predictors, lambda d: cluster_weights(
        np.array([cluster_of(name) for name in d]), n_draws, rng))
    left_out, _ = headline_draws(rows, predictors, lambda d: leave_one_out_weights(len(d)))
    result: dict = {"n_arcs": int(len(datasets)), "n_scenes": int(len({cluster_of(name) for name in datasets}))}
    for predictor in draws.spl:
        boot, loo = _figures(draws, predictor), _figures(left_out, predictor)
        result[predictor] = {name: percentile_interval(values, level) for name, values in boot.items()} | {
            "no_point_share": float(np.isnan(draws.spl[predictor]).mean()),
            "leave_one_arc_out": {name: _range(values[~np.isnan(values)]) for name, values in loo.items()}}
    every, _ = headline_draws(rows, predictors, lambda d: np.ones((1, len(d))))  # the table itself
    result["pairs"] = {}
    for a, b in pairs:
        if a in draws.spl and b in draws.spl:
            difference, point = _paired(draws.spl[a], draws.spl[b]), _paired(every.spl[a], every.spl[b])[0]
            result["pairs"][f"{a} vs {b}"] = {"point": float(point) if np.isfinite(point) else None,
                                              "difference": percentile_interval(difference, level),
                                              "p_better": float((difference > 0).mean())}
    return result


# every predictor but static (whose pairs are the gains) compared in pairs, in the order "A vs B" is read (A - B):
# ours before the paper's, a variant before its predictor, so that the keys say "next_step vs long_range" (V-B),
# "long_range vs mlp" (Table I), "long_range_free_width vs long_range"
PAIRED = ("hazard_next_step", "hazard_long_range", "error_combined", "error_next_step_observed", "error_next_step", "error_long_range", "next_step_free_width",
          "long_range_free_width", "next_step_relative", "long_range_relative", "next_step", "long_range_lower",
          "long_range", "mlp")
PAIRS = tuple((a, b) for i, a in enumerate(PAIRED) for b in PAIRED[i + 1:])


def world_intervals(table: pd.DataFrame, predictors: tuple[str, ...], tolerances: list[str], method: str,
                    trajectory: str, n_draws: int, level: float, seed: int) -> dict:
    """:func:`headline_intervals` of one world's prediction table per tolerance (``<tolerance>: {...}``) on the
    datasets of ``method`` and ``trajectory``, each with its own seeded draws (:func:`~poseintegrity.seeding.keyed_rng`
    of ``seed`` and the method, trajectory and tolerance: the same draws whatever else the table holds). The lines of a
    world are one scene: they are resampled one by one (their ids name each its own cluster)."""
    rows = table[(table["method"] == method) & (table["trajectory"] == trajectory)]
    result = {}
    for tolerance in tolerances:
        part = rows[rows["tolerance"] == tolerance]
        result[tolerance] = headline_intervals(part, predictors, PAIRS, n_draws, level,
                                               keyed_rng(seed, "intervals", method, trajectory, tolerance),
                                               scene_of if trajectory == "arc" else str)
    return result


def live_intervals(rows: pd.DataFrame, predictor: str, point: float, n_draws: int, level: float,
                   rng: np.random.Generator) -> dict:
    """The simulated live trials (V-C, :func:`~.live_trials.live_trials`) resampled by scene: ``predictor`` at the
    fixed operating point ``point`` against the static baseline at its best zero-incursion size, chosen again in each
    draw.

    rows : the prediction table's rows of the live trials' method, arcs and tolerance. Returns ``{envelope_share_gain,
    relative_gain}``: intervals of (mean SPL / theta_a of ``predictor``) - (static's), and of their ratio - 1, the
    paper's 74.7 % vs 60.4 %; ``{}`` when the rows hold no such point. An arc with theta_a 0 has no share: left out.
    """
    datasets = np.sort(rows.loc[rows["predictor"] == "static", "dataset"].unique())
    ours, static = (family(rows[rows["predictor"] == p], datasets) for p in (predictor, "static"))
    column = np.flatnonzero(np.isclose(ours.points, point))
    if not len(datasets) or not len(column):
        return {}
    weights = cluster_weights(np.array([scene_of(name) for name in datasets]), n_draws, rng)
    has_share = ours.theta_a > 0
    weights = weights * has_share
    theta_a = np.where(has_share, ours.theta_a, 1.0)
    share = np.where(ours.valid[:, column[0]], ours.spl[:, column[0]] / theta_a, 0.0)
    counted = weights @ ours.valid[:, column[0]]
    _, size = select(static, weights, conservative_high=False)
    static_share = np.take_along_axis(static.spl / theta_a[:, None], np.searchsorted(static.points, np.nan_to_num(size))
                                      [None, :].repeat(len(datasets), 0), axis=1)  # (d, b): at each draw's size
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_ours = (weights @ share) / counted
        mean_static = np.einsum("bd,db->b", weights, static_share) / weights.sum(axis=1)
        return {"envelope_share_gain": percentile_interval(mean_ours - mean_static, level),
                "relative_gain": percentile_interval(mean_ours / mean_static - 1.0, level)}


def fixed_point_interval(rows: pd.DataFrame, predictor: str, point: float, n_draws: int, level: float,
                         rng: np.random.Generator) -> dict:
    """``predictor`` at an operating point chosen elsewhere (another world, the population), resampled by scene: its
    mean SPL and R_i at ``point``, and its share of the ceiling against the static baseline and the ceiling of each
    draw (static's size chosen again in each). rows : the prediction table's rows of one method, arcs and tolerance
    (static's among them). Returns {mean_spl, incursion_rate, share, share_interval, incursion_rate_interval}; {}
    where the rows hold no such point."""
    datasets = np.sort(rows.loc[rows["predictor"] == "static", "dataset"].unique())
    ours, static = (family(rows[rows["predictor"] == p], datasets) for p in (predictor, "static"))
    column = np.flatnonzero(np.isclose(ours.points, point))
    if not len(datasets) or not len(column):
        return {}
    everything = np.ones((1, len(datasets)))
    weights = np.vstack([everything, cluster_weights(np.array([scene_of(n) for n in datasets]), n_draws, rng)])
    spl, rate = (values[:, column[0]] for values in curves(ours, weights))
    static_spl, _ = select(static, weights, conservative_high=False)
    mean_theta_a = (weights @ ours.theta_a) / weights.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = (spl - static_spl) / (mean_theta_a - static_spl)
    return {"mean_spl": float(spl[0]), "incursion_rate": float(rate[0]), "share": float(share[0]),
            "share_interval": percentile_interval(share[1:], level),
            "incursion_rate_interval": percentile_interval(rate[1:], level)}


def rate_bands(rows: pd.DataFrame, predictors: tuple[str, ...], rates: np.ndarray, n_draws: int, level: float,
               rng: np.random.Generator) -> pd.DataFrame:
    """The SPL vs R_i figure's bands: per predictor and incursion rate r of ``rates`` (R,), the max mean SPL at
    R_i <= r (:func:`select`) of all the arcs (``max_mean_spl``) and its interval over scene-resampled draws
    (``low``, ``high``: the selection repeated in each draw, NaN where no operating point is that safe). ``rows``:
    the prediction table's rows of one method, trajectory and tolerance (static's among them)."""
    datasets = np.sort(rows.loc[rows["predictor"] == "static", "dataset"].unique())
    weights = cluster_weights(np.array([scene_of(name) for name in datasets]), n_draws, rng)
    out = []
    for predictor in (p for p in predictors if (rows["predictor"] == p).any()):  # in the order given
        fam, high = family(rows[rows["predictor"] == predictor], datasets), CONSERVATIVE_HIGH.get(predictor, True)
        for rate in rates:
            point = select(fam, np.ones((1, len(datasets))), high, rate)[0][0]
            draws = select(fam, weights, high, rate)[0]
            low, top = percentile_interval(_ranked(draws), level)
            out.append({"predictor": predictor, "incursion_rate": float(rate), "max_mean_spl": point,
                        "low": np.nan if low is None else low, "high": np.nan if top is None else top})
    return pd.DataFrame(out, columns=["predictor", "incursion_rate", "max_mean_spl", "low", "high"])
