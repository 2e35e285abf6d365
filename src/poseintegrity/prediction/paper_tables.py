"""Tables I-III and the metrics of stage 04 from the prediction tables of :mod:`.sweeps` (Windsor et al. V).

    best_table        per predictor, PnP method, trajectory and tolerance: max mean SPL at zero incursion and its
                      operating point (Tables I-III)
    deciding_datasets the datasets that hold an operating point where it is (they incur at the next bolder one)
    table_metrics     one world's Tables I-III, Figs. 6-7, fit statuses and tails (the validation world's figures)
    headline_metrics  the keys of ``reports/metrics/predictors.json`` (the main world: table_metrics, LOSO, live)
    rule_metrics      Tables I-III under each failed-frame rule of theta_a
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.artifact_models import FIT_STATUSES
from poseintegrity.prediction.ceiling import ceiling, ceiling_share
from poseintegrity.prediction.intervals import INTERVAL_METHOD, live_intervals, world_intervals
from poseintegrity.prediction.live_trials import heldout_metrics, trial_figures
from poseintegrity.prediction.loso import loso_summary
from poseintegrity.prediction.metrics import (best_operating_point, operating_curves, relative_improvement,
                                               with_metrics)
from poseintegrity.params.predict import PredictParams
from poseintegrity.prediction.predictors import NO_FIT
from poseintegrity.prediction.sweeps import (
    CONSERVATIVE_HIGH, ERROR_PREDICTORS, FITTED_PREDICTORS, HAZARD_PREDICTORS, FREE_WIDTH_PREDICTORS, OPERATING_POINT_KEY,
    PAPER_COUNTERPART, PAPER_PREDICTORS, RELATIVE_PREDICTORS, attach_envelopes,
)
from poseintegrity.params.protocol import FAILED_FRAME_RULES, ProtocolParams
from poseintegrity.prediction.tails import tail_metrics
from poseintegrity.seeding import keyed_rng


def best_table(curves: pd.DataFrame, max_incursion_rate: float = 0.0) -> pd.DataFrame:
    """Tables I-III: per (predictor, method, trajectory, tolerance) the max mean SPL at R_i <= rate and its point."""
    rows = []
    for (predictor, method, trajectory, tolerance), curve in curves.groupby(
        ["predictor", "method", "trajectory", "tolerance"], sort=True
    ):
        spl, point = best_operating_point(curve, max_incursion_rate, CONSERVATIVE_HIGH.get(predictor, True))
        rows.append(dict(predictor=predictor, method=method, trajectory=trajectory, tolerance=tolerance,
                         max_mean_spl=spl, best_operating_point=point))  # fmt: skip
    return pd.DataFrame(rows)


def deciding_datasets(table: pd.DataFrame, predictor: str, method: str, trajectory: str, tolerance: str,
                      point: float) -> list[str]:
    """The datasets that decide a headline: those incurring (eq. 4) at the nearest operating point bolder than
    ``point`` (a smaller n_t; a larger static size, :data:`~.sweeps.CONSERVATIVE_HIGH`) at which any dataset incurs.
    Sorted; empty when ``point`` is NaN or no bolder point incurs. table : prediction rows (theta_p, theta_a)."""
    rows = table[(table["predictor"] == predictor) & (table["method"] == method) & (table["trajectory"] == trajectory)
                 & (table["tolerance"] == tolerance)]
    if not np.isfinite(point) or rows.empty:
        return []
    rows = with_metrics(rows) if "incursion" not in rows else rows
    high = CONSERVATIVE_HIGH.get(predictor, True)
    bolder = rows[(rows["operating_point"] < point) if high else (rows["operating_point"] > point)]
    incurring = bolder[bolder["incursion"] == 1.0]
    if incurring.empty:
        return []
    nearest = incurring["operating_point"].max() if high else incurring["operating_point"].min()
    return sorted(incurring.loc[incurring["operating_point"] == nearest, "dataset"].unique().tolist())


def fit_status_shares(table: pd.DataFrame) -> dict[str, dict]:
    """predictor -> {n_rows, ok, at_bound, non_physical, fallback, no_fit}: the share of the predictor's rows (every
    dataset, PnP method, trajectory and operating point of the table, once whatever the tolerances joined) whose
    theta_p rests on a fit of that status."""
    # a sweep row serves every tolerance, but the error predictors' rows were made for one (sweeps.py)
    once = ["predictor", "method", "trajectory", "dataset", "operating_point"]
    made_for_one = table["predictor"].isin((*ERROR_PREDICTORS, *HAZARD_PREDICTORS))
    table = table.assign(made_for=table["tolerance"].where(made_for_one, ""))
    table = table.drop_duplicates([*once, "made_for"])
    shares = {}
    for predictor in FITTED_PREDICTORS:
        rows = table.loc[table["predictor"] == predictor, "fit_status"]
        counts = rows.value_counts()
        entry: dict = {"n_rows": int(len(rows))}
        for status in (*FIT_STATUSES, NO_FIT):
            entry[status] = float(counts.get(status, 0) / len(rows)) if len(rows) else np.nan
        shares[predictor] = entry
    return shares


def table_metrics(table: pd.DataFrame, curves: pd.DataFrame, predict: PredictParams, protocol: ProtocolParams) -> dict:
    """What one world's prediction table says, as Tables I-III, Figs. 6-7 and beyond report it.

    <predictor>.<tolerance>.{max_mean_spl_zero_incursion, best_n_t} on the arc datasets of the paper's PnP path
    (best_n_t is null for "static", whose operating point is ``best_size``, and for the relative-threshold
    predictors, whose operating point is ``best_fraction``), and for the paper's predictors ``decided_by``, the arcs
    that hold that operating point (:func:`deciding_datasets`); <predictor>.relative_improvement
    over static on the mean across tolerances (Tables I, II), long_range.relative_improvement_vs_mlp,
    next_step.relative_improvement_vs_long_range; straight_line.relative_improvement (Fig. 7);
    pnp.<method>.{max_mean_spl_zero_incursion, static_max_mean_spl_zero_incursion} (Fig. 6);
    fit_status.<predictor>.{n_rows, ok, at_bound, non_physical, fallback, no_fit} (:func:`fit_status_shares`). Ours,
    beside the paper's keys: <free-width predictor> as the others, with relative_improvement_vs_<its eq. 1
    counterpart>; tails.<long_range | long_range_free_width>.<tolerance>.{n_overshooting, datasets}
    (:func:`.tails.tail_metrics`). NaN where there is no value (written as null).

    Ours (issue 49), beside every predictor's headline: ``gain`` (SPL - static SPL, deg), ``relative_gain`` (as Tables
    I-II), and ``interval`` (:func:`.intervals.headline_intervals`: bootstrap intervals of the SPL, the gains and the
    ceiling share with the operating point chosen again in each draw, leave-one-arc-out ranges); ``intervals``: how
    they were drawn and, per tolerance, the arcs and scenes behind them and the paired differences of the predictors;
    ``straight_line.interval`` and ``pnp.<method>.interval`` the long range predictor's on the lines and each method.
    """
    best = best_table(curves)

    def get(predictor: str, trajectory: str, tolerance: str, method: str = protocol.pnp_method) -> tuple[float, float]:
        row = best[(best.predictor == predictor) & (best.trajectory == trajectory) & (best.tolerance == tolerance)
                   & (best.method == method)]  # fmt: skip
        return (float(row.max_mean_spl.iloc[0]), float(row.best_operating_point.iloc[0])) if len(row) else (np.nan,) * 2

    tolerances = sorted(table["tolerance"].unique())
    static_mean = float(np.mean([get("static", "arc", t)[0] for t in tolerances]))
    limits = ceiling(table, best, protocol.pnp_method, tolerances)
    predictors = (*PAPER_PREDICTORS, "long_range_lower", *RELATIVE_PREDICTORS, *FREE_WIDTH_PREDICTORS,
                  *ERROR_PREDICTORS, *HAZARD_PREDICTORS)
    draws = predict.intervals

    def spread(predictors: tuple[str, ...], method: str, trajectory: str, tolerances: list[str]) -> dict:
        return world_intervals(table, predictors, tolerances, method, trajectory, draws.n_draws, draws.level,
                               predict.seed)

    arcs = spread(predictors, protocol.pnp_method, "arc", tolerances)
    metrics: dict = {"ceiling": limits, "intervals": {
        "method": INTERVAL_METHOD, "n_draws": draws.n_draws, "level": draws.level,
        **{t: {key: arcs[t].get(key) for key in ("n_arcs", "n_scenes", "pairs")} for t in tolerances}}}
    for predictor in predictors:
        point_key = OPERATING_POINT_KEY.get(predictor, "best_n_t")
        entry: dict = {}
        for tolerance in tolerances:
            spl, point = get(predictor, "arc", tolerance)
            static = get("static", "arc", tolerance)[0]
            entry[tolerance] = {"max_mean_spl_zero_incursion": spl, point_key: point,
                                "ceiling_share": ceiling_share(spl, limits[tolerance]), "gain": spl - static,
                                "relative_gain": relative_improvement(spl, static),
                                "interval": arcs[tolerance].get(predictor, {})}
            if predictor in (*PAPER_PREDICTORS, *ERROR_PREDICTORS, *HAZARD_PREDICTORS):
                entry[tolerance]["decided_by"] = deciding_datasets(table, predictor, protocol.pnp_method, "arc",
                                                                   tolerance, point)
            if point_key != "best_n_t":
                entry[tolerance]["best_n_t"] = None
        mean_spl = float(np.mean([entry[t]["max_mean_spl_zero_incursion"] for t in tolerances]))
        entry["mean_max_mean_spl_zero_incursion"] = mean_spl
        if predictor != "static":
            entry["relative_improvement"] = relative_improvement(mean_spl, static_mean)
        metrics[predictor] = entry
    mean = {p: metrics[p]["mean_max_mean_spl_zero_incursion"] for p in ("long_range", "mlp", "next_step")}
    metrics["long_range"]["relative_improvement_vs_mlp"] = relative_improvement(mean["long_range"], mean["mlp"])
    metrics["next_step"]["relative_improvement_vs_long_range"] = relative_improvement(
        mean["next_step"], mean["long_range"]
    )  # Table I: +7.4 % over the MLP; V-B: +9.8 % over the long range predictor
    for ours, paper in PAPER_COUNTERPART.items():  # ours on the free-width EMG vs the same predictor on eq. 1
        metrics[ours][f"relative_improvement_vs_{paper}"] = relative_improvement(
            metrics[ours]["mean_max_mean_spl_zero_incursion"], metrics[paper]["mean_max_mean_spl_zero_incursion"]
        )
    tol = predict.tolerance_fig6_fig7
    metrics["straight_line"] = {
        "tolerance": tol,
        "long_range_max_mean_spl_zero_incursion": get("long_range", "line", tol)[0],
        "error_long_range_max_mean_spl_zero_incursion": get("error_long_range", "line", tol)[0],
        "static_max_mean_spl_zero_incursion": get("static", "line", tol)[0],
        "relative_improvement": relative_improvement(get("long_range", "line", tol)[0], get("static", "line", tol)[0]),
    }
    lines = spread(("static", "long_range", "error_long_range"), protocol.pnp_method, "line", [tol])[tol]
    metrics["straight_line"] |= {"n_lines": lines["n_arcs"], "interval": lines.get("long_range", {})}
    metrics["pnp"] = {
        str(method): {
            "tolerance": tol,
            "max_mean_spl_zero_incursion": get("long_range", "arc", tol, method)[0],
            "best_n_t": get("long_range", "arc", tol, method)[1],
            "error_long_range_max_mean_spl_zero_incursion": get("error_long_range", "arc", tol, method)[0],
            "static_max_mean_spl_zero_incursion": get("static", "arc", tol, method)[0],
            "interval": spread(("static", "long_range", "error_long_range"), str(method), "arc",
                               [tol])[tol].get("long_range", {}),
        }
        for method in sorted(table["method"].unique())
    }
    metrics["fit_status"] = fit_status_shares(table)
    metrics["tails"] = tail_metrics(table, predict, protocol)
    return metrics


def headline_metrics(
    table: pd.DataFrame, curves: pd.DataFrame, loso: pd.DataFrame, live: pd.DataFrame, predict: PredictParams,
    protocol: ProtocolParams, error_live: pd.DataFrame | None = None, error_live_safety_factor: float = np.nan,
    heldout_live: pd.DataFrame | None = None,
) -> dict:
    """The content of ``reports/metrics/predictors.json``, of the main world: :func:`table_metrics`, and
    loso.<predictor>.<tolerance>.{heldout_incursion_rate, heldout_mean_spl, ceiling_share, ...} at the first target
    rate (the held-out mean SPL's share of the world's ceiling); live.{n_t, incursions, n_trials, envelope_share,
    n_flagged_fits, static_*} (V-C), and live.error_next_step.{k, incursions, n_trials, envelope_share,
    n_flagged_fits} for ``error_live`` (:func:`~.live_trials.live_trials` of "error_next_step" at the safety factor
    ``error_live_safety_factor``, ours); each with ``interval``, the live trials resampled by scene
    (:func:`.intervals.live_intervals`, ours); and
    live.heldout.{n_t, static_size (per scene), n_trials, incursions, envelope_share, static_envelope_share,
    static_incursions, n_flagged_fits, interval} for ``heldout_live`` (:func:`~.live_trials.heldout_live_trials`,
    every operating point chosen on the other scenes; ours)."""
    metrics = table_metrics(table, curves, predict, protocol)
    metrics["loso"] = loso_summary(loso, predict.loso_target_rates[0])
    for entry in metrics["loso"].values():
        for tolerance, figures in entry.items():
            figures["ceiling_share"] = ceiling_share(figures["heldout_mean_spl"], metrics["ceiling"][tolerance])
    metrics["live"] = {
        "n_t": predict.live_n_t, "tolerance": predict.live_tolerance, **trial_figures(live),
        "static_size": float(live["static_size"].iloc[0]) if len(live) else np.nan,
        "static_incursions": float(live["static_incursion"].sum()),
        "static_envelope_share": float(live["static_share"].mean()),
    }  # fmt: skip
    live_rows = table[(table["trajectory"] == "arc") & (table["method"] == protocol.pnp_method)
                      & (table["tolerance"] == predict.live_tolerance)]

    def live_spread(predictor: str, point: float) -> dict:  # ours (issue 49): resampled by scene
        return live_intervals(live_rows, predictor, point, predict.intervals.n_draws, predict.intervals.level,
                              keyed_rng(predict.seed, "live intervals", predictor))

    metrics["live"]["interval"] = live_spread("next_step", predict.live_n_t)
    if error_live is not None:
        metrics["live"]["error_next_step"] = {"k": float(error_live_safety_factor), **trial_figures(error_live),
                                              "interval": live_spread("error_next_step", error_live_safety_factor)}
    if heldout_live is not None and len(heldout_live):
        metrics["live"]["heldout"] = heldout_metrics(heldout_live, predict)
    return metrics


def rule_metrics(theta_p: pd.DataFrame, envelopes: pd.DataFrame, protocol: ProtocolParams,
                 predictors: tuple[str, ...] = PAPER_PREDICTORS) -> dict:
    """Tables I-III under every failed-frame rule of theta_a (:mod:`poseintegrity.localization.envelope`):
    <rule>.<predictor>.<tolerance>.{max_mean_spl_zero_incursion, best_operating_point, ceiling_share} on the arcs of
    the paper's PnP path, and <rule>.<predictor>.relative_improvement over static (mean of the tolerances). Every tolerance of
    ``protocol`` has its entry, NaN where nothing was measured (a world without arcs).

    theta_p : :func:`~.sweeps.sweep` rows (those of datasets without an envelope, e.g. of another world, are left
    out); envelopes : one world's stage-02 envelopes, every rule
    """
    metrics: dict = {}
    theta_p = theta_p[theta_p["dataset"].isin(envelopes["dataset"])]  # this world's rows (other worlds' are left out)
    for rule in FAILED_FRAME_RULES:
        table = attach_envelopes(theta_p, envelopes[envelopes["rule"] == rule].drop(columns="rule"), protocol)
        best = best_table(operating_curves(table))
        limits = ceiling(table, best, protocol.pnp_method, protocol.tolerance_names)
        best = best[(best["trajectory"] == "arc") & (best["method"] == protocol.pnp_method)]
        entry: dict = {}
        for predictor in predictors:
            rows = best[best["predictor"] == predictor].set_index("tolerance").reindex(protocol.tolerance_names)
            entry[predictor] = {tol: {"max_mean_spl_zero_incursion": float(row.max_mean_spl),
                                      "best_operating_point": float(row.best_operating_point),
                                      "ceiling_share": ceiling_share(float(row.max_mean_spl), limits[tol])}
                                for tol, row in rows.iterrows()}
            entry[predictor]["mean_max_mean_spl_zero_incursion"] = float(rows["max_mean_spl"].mean())
        static = entry["static"]["mean_max_mean_spl_zero_incursion"] if "static" in entry else np.nan
        for predictor in predictors:
            if predictor != "static":
                entry[predictor]["relative_improvement"] = relative_improvement(
                    entry[predictor]["mean_max_mean_spl_zero_incursion"], static)
        metrics[rule] = entry
    return metrics
