"""The artifact model's tail (ours, beyond Windsor et al.): arcs whose long range theta_p overshoots the actual
envelope at every threshold.

Eq. 1 fixes the EMG's Gaussian width at 1 theta unit, so past its peak the fitted curve is a shifted exponential.
Fitted to the first 4 stops of an arc whose n_i has a shoulder and then a cliff, it predicts a long flat tail: the
long range predictor's theta_p (III-E) lies beyond theta_a (IV-E) at every reasonable n_t, and that one arc forces
the zero-incursion n_t of Tables I-III up for every arc. This module lists such arcs per tolerance, for eq. 1 and for
the free-width EMG (artifact_models.base_functions.emg_free_width), and refits their curves for a figure
(predictor_figures.py, ``tail_figure``).

    overshooting_arcs  the arcs whose theta_p > theta_a at every swept n_t <= ``predict.tail_n_t_max``
    tail_metrics       ``tails.<predictor>.<tolerance>.{n_overshooting, datasets}`` of predictors.json
    tail_fits          what the figure shows of those arcs: samples, the sampled stops, each predictor's fit, theta_a
"""

from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

from poseintegrity.artifact_models import FittedModel
from poseintegrity.artifact_models.series import Series, dataset_series
from poseintegrity.errors import ArgumentError
from poseintegrity.params.fit import FitParams
from poseintegrity.params.predict import PredictParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.prediction.predictors import fit_rng, long_range

TAIL_PREDICTORS = ("long_range", "long_range_free_width")  # eq. 1 and the free-width EMG (predict.models)
KEYS = ["predictor", "tolerance", "dataset"]


def shown_column(n_t: int) -> str:
    """The column of :func:`overshooting_arcs` holding theta_p at threshold n_t."""
    return f"theta_p_n_t_{n_t}"


def _arc_rows(table: pd.DataFrame, method: str, predictors: tuple[str, ...]) -> pd.DataFrame:
    return table[(table["trajectory"] == "arc") & (table["method"] == method) & table["predictor"].isin(predictors)]


def overshooting_arcs(
    table: pd.DataFrame, n_t_max: int, shown: tuple[int, ...], method: str,
    predictors: tuple[str, ...] = TAIL_PREDICTORS,
) -> pd.DataFrame:  # fmt: skip
    """The arcs whose long range theta_p overshoots theta_a (theta_p > theta_a) at every swept n_t <= n_t_max.

    table : a prediction table (rows of :func:`.sweeps.attach_envelopes`: predictor, method, trajectory, dataset,
        tolerance, operating_point, theta_p, theta_a, ...); the arc rows of ``method`` and ``predictors`` are read
    n_t_max : ``predict.tail_n_t_max``;  shown : thresholds whose theta_p is reported (``predict.tail_n_t_shown``)
    A flagged row (theta_p NaN) is no overshoot, so an arc with one is never listed.
    Returns one row per (predictor, tolerance, dataset) listed, sorted: theta_a, censored, ``shown_column(n_t)`` for
    each shown n_t (NaN where the table has no such threshold) and n_t_first_safe, the smallest swept n_t with
    theta_p <= theta_a (NaN: none in the sweep), the threshold this arc alone forces on a zero-incursion choice.
    """
    rows = _arc_rows(table, method, predictors)
    columns = [*KEYS, "theta_a", "censored", *(shown_column(n) for n in shown), "n_t_first_safe"]
    within = rows[rows["operating_point"] <= n_t_max]
    overshoot = (within["theta_p"] > within["theta_a"]).groupby([within[key] for key in KEYS]).all()
    listed = overshoot[overshoot].index
    if listed.empty:
        return pd.DataFrame(columns=columns)
    keyed = rows.set_index(KEYS)
    arcs = keyed.loc[keyed.index.isin(listed)].reset_index()
    result = arcs.groupby(KEYS, sort=True).agg(theta_a=("theta_a", "first"), censored=("censored", "first"))
    for n_t in shown:
        at = arcs[arcs["operating_point"] == n_t].set_index(KEYS)["theta_p"]
        result[shown_column(n_t)] = at.reindex(result.index)
    safe = arcs[arcs["theta_p"] <= arcs["theta_a"]].groupby(KEYS)["operating_point"].min()
    result["n_t_first_safe"] = safe.reindex(result.index)
    return result.reset_index()[columns]


def tail_metrics(table: pd.DataFrame, predict: PredictParams, protocol: ProtocolParams,
                 predictors: tuple[str, ...] = TAIL_PREDICTORS) -> dict:  # fmt: skip
    """``<predictor>.<tolerance>.{n_overshooting, datasets}`` of :func:`overshooting_arcs` on the arcs of
    ``protocol.pnp_method`` (n_t <= ``predict.tail_n_t_max``), every predictor and tolerance of the table; None for
    a predictor without arc rows (nothing was diagnosed, which is not "no overshoot")."""
    arcs = overshooting_arcs(table, predict.tail_n_t_max, tuple(predict.tail_n_t_shown), protocol.pnp_method,
                             predictors)  # fmt: skip
    present = set(_arc_rows(table, protocol.pnp_method, predictors)["predictor"])
    metrics: dict = {}
    for predictor in predictors:
        entry: dict = {}
        for tolerance in sorted(table["tolerance"].unique()):
            listed = arcs[(arcs["predictor"] == predictor) & (arcs["tolerance"] == tolerance)]["dataset"]
            entry[tolerance] = ({"n_overshooting": int(len(listed)), "datasets": sorted(listed)}
                                if predictor in present else None)  # fmt: skip
        metrics[predictor] = entry
    return metrics


@dataclass(frozen=True)
class TailFit:
    """One arc of the tail figure: its samples, the stops fitted, each predictor's fit, theta_a per tolerance.

    n_sampled_stops : the first stops of ``series`` every fit was fitted to
    fits : predictor -> the fitted model its theta_p came from (None: too few stops to fit)
    theta_a : tolerance -> theta_a, deg
    """

    series: Series
    n_sampled_stops: int
    fits: dict[str, FittedModel | None]
    theta_a: dict[str, float]


def tail_fits(
    artifacts: pd.DataFrame, table: pd.DataFrame, datasets: list[str], predict: PredictParams, fit: FitParams,
    protocol: ProtocolParams, predictors: tuple[str, ...] = TAIL_PREDICTORS,
) -> list[TailFit]:  # fmt: skip
    """The arcs ``datasets`` refitted as the sweep fitted them (the same stops, model and seed, hence the same
    curves), each predictor on its model of ``predict.models``; theta_a of every tolerance from the prediction table.

    artifacts : the stage-02 table the sweep read;  table : the prediction table (attach_envelopes)
    Raises ValueError naming a dataset that is not an arc of ``protocol.pnp_method`` in ``artifacts``.
    """
    method = protocol.pnp_method
    series = {s.dataset: s for s in dataset_series(artifacts, method, protocol) if s.trajectory == "arc"}
    missing = [d for d in datasets if d not in series]
    if missing:
        raise ArgumentError(f"datasets {missing} are not arcs of {method!r} in the artifacts table")
    n_sampled_stops = protocol.stops_sampled("arc")
    thresholds = predict.thresholds
    result = []
    for dataset in datasets:
        one = series[dataset]
        fits = {predictor: long_range(one, n_sampled_stops, getattr(predict.models, predictor), thresholds, fit,
                                      fit_rng(predict.seed, method, one, n_sampled_stops), predict.n_grid).fitted
                for predictor in predictors}  # fmt: skip
        rows = table[(table["dataset"] == dataset) & (table["method"] == method)]
        theta_a = rows.groupby("tolerance")["theta_a"].first()
        result.append(TailFit(one, n_sampled_stops, fits, {str(t): float(v) for t, v in theta_a.items()}))
    return result

