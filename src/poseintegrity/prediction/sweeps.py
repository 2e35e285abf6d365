"""The operating-point sweeps of Windsor et al. V (Figs. 5-8, Tables I-III) on a stage-02 artifacts table.

    sweep             theta_p of every predictor for every dataset, PnP method and operating point
                      (n_t = n_t_min .. n_t_max; static sizes 0 .. 45 deg / 0 .. 150 mm), fitted once per
                      dataset (and stop for the next-step predictor), one task per dataset and method on the workers
    attach_envelopes  joins the actual envelopes theta_a per tolerance (checked against the protocol) and adds SPL
                      (eq. 3), incursion (eq. 4); Tables I-III and the metrics come from it in :mod:`.paper_tables`

Predictors (column ``predictor``): "long_range", "long_range_lower" (stops on the lower bound of the
prediction interval, :mod:`.uncertainty`), "mlp", "next_step", "static", and beyond the paper
"long_range_relative" / "next_step_relative", whose operating point is n_t as a fraction of the dataset's mean n_i
at the first stop (the same fits as "long_range" / "next_step"), and "long_range_free_width" /
"next_step_free_width", the same predictors on a second artifact model (``predict.models``: the free-width EMG).
Ours beside them (issue 38, :mod:`.error_predictors`): "error_long_range" and "error_next_step", which stop where
k x the predicted localization error reaches the tolerance (operating point: the safety factor k), and
"error_next_step_observed", the latter calibrated on each arc by the robot's kinematics (datasets with the robot's
poses only). Their theta_p
depends on the tolerance, so their rows name it (column ``tolerance``; empty for every other predictor, whose
theta_p serves every tolerance). Ours too (issue 50, :mod:`.hazard`): "hazard_next_step" and "hazard_long_range", which stop where the failure
hazard, trained on the population's worlds, reaches h (operating point: h; rows per tolerance, arcs of the paper's
PnP method). "error_combined", the earlier stop of the error predictor and the paper's at its
chosen n_t, is made from both after the operating points are chosen (:func:`combined_rows`).
Only "long_range", "error_long_range" and "static" run on PnP methods other than ``protocol.pnp_method`` (Fig. 6).

Every row says how its theta_p was found (``status``, predictors.py) and what the fit behind it was worth
(``fit_status``: ok / at_bound / non_physical / fallback, artifact_models/fitted.py; "no_fit" for the static
baseline and rows without a fit). Flagged fits stay in the SPL / R_i curves, as what the robot would have done, and
are counted in predictors.json (``fit_status``).
"""

from __future__ import annotations

import warnings
from functools import partial

import numpy as np
import pandas as pd

from poseintegrity.artifact_models.fitted import OK
from poseintegrity.artifact_models.series import REQUIRED_COLUMNS, Series, dataset_series
from poseintegrity.params.fit import FitParams
from poseintegrity.params.predict import PredictParams
from poseintegrity.prediction.error_predictors import COUNT_TREND, combined, error_long_range, error_next_step
from poseintegrity.prediction.hazard.applied import HAZARD_PREDICTORS, HazardSet, hazard_rows
from poseintegrity.prediction.metrics import with_metrics
from poseintegrity.table_checks import TableError, check_artifacts, check_envelopes
from poseintegrity.workers import Workers
from poseintegrity.prediction.predictors import (
    NO_FIT,
    Boundaries,
    LongRange,
    fit_rng,
    long_range,
    next_step,
    relative_thresholds,
    static_baseline,
)
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.prediction.uncertainty import prediction_interval

COLUMNS = [
    "predictor", "model", "method", "trajectory", "dataset", "operating_point", "theta_p", "status", "fit_status",
    "reason", "tolerance",
]  # fmt: skip
PAPER_PREDICTORS = ("static", "long_range", "mlp", "next_step")  # the keys of predictors.json
RELATIVE_PREDICTORS = ("long_range_relative", "next_step_relative")  # beyond the paper
FREE_WIDTH_PREDICTORS = ("long_range_free_width", "next_step_free_width")  # ours: on the free-width EMG
ERROR_PREDICTORS = ("error_long_range", "error_next_step", "error_next_step_observed",
                    "error_combined")  # ours: on the predicted error
FITTED_PREDICTORS = ("long_range", "long_range_lower", "mlp", "next_step", *RELATIVE_PREDICTORS,
                     *FREE_WIDTH_PREDICTORS, *ERROR_PREDICTORS, *HAZARD_PREDICTORS)  # fmt: skip
PAPER_COUNTERPART = {"long_range_free_width": "long_range", "next_step_free_width": "next_step"}  # same predictor
CONSERVATIVE_HIGH = {"static": False, "hazard_next_step": False, "hazard_long_range": False}
# a larger operating point is more conservative for n_t and k, not for a size or a hazard h
OPERATING_POINT_KEY = {"static": "best_size", "long_range_relative": "best_fraction",
                       "next_step_relative": "best_fraction"} | {p: "best_k" for p in ERROR_PREDICTORS} | {
                       p: "best_h" for p in HAZARD_PREDICTORS}
# predictors.json name of the best operating point


def prediction_rows(
    predictor: str, model: str, method: str, series: Series, operating_point: np.ndarray, found: Boundaries,
    fit_status: str | np.ndarray, reason: str | np.ndarray, tolerance: str = "",
) -> pd.DataFrame:  # fmt: skip
    return pd.DataFrame(
        {
            "predictor": predictor, "model": model, "method": method, "trajectory": series.trajectory,
            "dataset": series.dataset, "operating_point": operating_point, "theta_p": found.theta_p,
            "status": found.status, "fit_status": fit_status, "reason": reason, "tolerance": tolerance,
        },
        columns=COLUMNS,
    )  # fmt: skip


def fit_of(answer: LongRange) -> tuple[str, str]:
    """(fit_status, reason) of a long range answer; NO_FIT when there were too few stops to fit."""
    return (answer.fitted.status, answer.fitted.reason) if answer.fitted else (NO_FIT, "too few stops")


def _split(values, n: int) -> tuple:
    """The answers (:class:`Boundaries` or an array) for the first n thresholds and for the rest."""
    if isinstance(values, Boundaries):
        return (Boundaries(values.theta_p[:n], values.status[:n]), Boundaries(values.theta_p[n:], values.status[n:]))
    return values[:n], values[n:]


def predict_dataset(
    series: Series, method: str, predict: PredictParams, fit: FitParams, protocol: ProtocolParams
) -> pd.DataFrame:
    """Every predictor's theta_p over the operating points for one dataset and PnP method (rows of COLUMNS); the
    predictors sample ``protocol.stops_sampled`` stops first (IV-A).

    The absolute thresholds n_t and the relative ones (fraction x first-stop mean n_i) go through one fit of each
    predictor: the fit does not depend on the threshold.
    """
    n_t, n_sampled_stops, models = predict.thresholds, protocol.stops_sampled(series.trajectory), predict.models
    fractions = predict.relative_thresholds
    both = np.concatenate([n_t, relative_thresholds(series, fractions)])
    sizes = predict.static_sizes(series.theta_end)
    tables = [prediction_rows("static", "", method, series, sizes, static_baseline(sizes), NO_FIT, "no fit: one size for all")]
    answer = long_range(series, n_sampled_stops, models.long_range, both, fit,
                        fit_rng(predict.seed, method, series, n_sampled_stops), predict.n_grid)
    absolute, relative = _split(answer.prediction, n_t.size)
    fit_status, reason = fit_of(answer)
    tables.append(prediction_rows("long_range", models.long_range, method, series, n_t, absolute, fit_status, reason))
    tables += error_rows(series, method, predict, fit, protocol, with_next_step=method == protocol.pnp_method)
    if method != protocol.pnp_method:  # Fig. 6: the long range predictors alone on the other PnP methods
        return pd.concat(tables, ignore_index=True)
    tables.append(prediction_rows("long_range_relative", models.long_range, method, series, fractions, relative, fit_status,
                        reason))  # fmt: skip

    interval = prediction_interval(
        models.long_range, answer.fitted, answer.theta, answer.n_inliers, n_t,
        theta_end=series.theta_end, fit=fit, uncertainty=predict.uncertainty,
        rng=fit_rng(predict.seed + 1, method, series, n_sampled_stops), n_grid=predict.n_grid,
    )  # fmt: skip
    no_interval = np.isnan(interval.lower) & ~np.isnan(absolute.theta_p)
    lower = Boundaries(interval.lower, np.where(no_interval, "no_interval", absolute.status))
    lower_reason = interval.reason if fit_status == OK else f"{reason}; interval: {interval.reason}"
    tables.append(prediction_rows("long_range_lower", models.long_range, method, series, n_t, lower, fit_status, lower_reason))
    for predictor, model in (("mlp", models.mlp), ("long_range_free_width", models.long_range_free_width)):
        other = long_range(series, n_sampled_stops, model, n_t, fit,
                           fit_rng(predict.seed, method, series, n_sampled_stops), predict.n_grid)
        tables.append(prediction_rows(predictor, model, method, series, n_t, other.prediction, *fit_of(other)))
    step = next_step(series, n_sampled_stops, models.next_step, both, fit, predict.seed, method, predict.n_grid)
    step_absolute, step_relative = _split(step.prediction, n_t.size)
    status_absolute, status_relative = _split(step.fit_status, n_t.size)
    reason_absolute, reason_relative = _split(step.fit_reason, n_t.size)
    tables.append(prediction_rows("next_step", models.next_step, method, series, n_t, step_absolute, status_absolute,
                        reason_absolute))  # fmt: skip
    tables.append(prediction_rows("next_step_relative", models.next_step, method, series, fractions, step_relative,
                        status_relative, reason_relative))  # fmt: skip
    free = next_step(series, n_sampled_stops, models.next_step_free_width, n_t, fit, predict.seed, method,
                     predict.n_grid)
    tables.append(prediction_rows("next_step_free_width", models.next_step_free_width, method, series, n_t, free.prediction,
                        free.fit_status, free.fit_reason))  # fmt: skip
    return pd.concat(tables, ignore_index=True)


def error_rows(series: Series, method: str, predict: PredictParams, fit: FitParams, protocol: ProtocolParams,
               with_next_step: bool) -> list[pd.DataFrame]:
    """The error predictors' rows of one dataset and method, per tolerance (:mod:`.error_predictors`; none when the
    artifacts table carries no predicted error, e.g. one written before issue 38)."""
    if series.sigma_t is None or series.sigma_r is None:
        return []
    safety_factors, models, rows = predict.error.safety_factors, predict.models, []
    n_sampled_stops = protocol.stops_sampled(series.trajectory)
    for tolerance, name in zip(protocol.tolerances, protocol.tolerance_names):
        found, status, reason = error_long_range(series, n_sampled_stops, models.long_range, safety_factors, tolerance,
                                                 fit, fit_rng(predict.seed, method, series, n_sampled_stops),
                                                 predict.n_grid)
        rows.append(prediction_rows("error_long_range", models.long_range, method, series, safety_factors, found,
                                    status, reason, name))
        if with_next_step:
            step = error_next_step(series, n_sampled_stops, safety_factors, tolerance, predict.n_grid)
            rows.append(prediction_rows("error_next_step", COUNT_TREND, method, series, safety_factors,
                                        step.prediction, step.fit_status, step.fit_reason, name))
            if series.observed_t is not None and series.observed_r is not None:
                step = error_next_step(series, n_sampled_stops, safety_factors, tolerance, predict.n_grid,
                                       observed=True)
                rows.append(prediction_rows("error_next_step_observed", COUNT_TREND, method, series, safety_factors,
                                            step.prediction, step.fit_status, step.fit_reason, name))
    return rows


def _predict_task(task: tuple[Series, str], predict: PredictParams, fit: FitParams, protocol: ProtocolParams
                  ) -> pd.DataFrame:  # fmt: skip
    # loky restarts a worker whose memory grows 300 MB past what it held after its first task, and warns "A worker
    # stopped while some jobs were given to the executor" (docs/references.md). The MLP's torch (225 MB resident)
    # loads with the first task of protocol.pnp_method, which comes after the other PnP methods' tasks: loaded by
    # every worker's first task, it is part of what the worker holds from the start.
    import torch  # noqa: F401, PLC0415

    series, method = task
    return predict_dataset(series, method, predict, fit, protocol)


def sweep(
    artifacts: pd.DataFrame, predict: PredictParams, fit: FitParams, protocol: ProtocolParams, workers: Workers,
    progress: bool = True, hazard: HazardSet | None = None,
) -> pd.DataFrame:  # fmt: skip
    """theta_p of every predictor, dataset, PnP method and operating point (rows of COLUMNS), one task per dataset
    and PnP method on ``workers``; the hazard predictors' rows too where ``hazard`` is given
    (:func:`~poseintegrity.prediction.hazard.applied.hazard_rows`, over ``predict.hazard.levels``).

    artifacts : the stage-02 table (dataset, trajectory, stop, image, theta_deg, x_mm, method, n_inliers, ...)
    """
    tasks = [
        (series, str(method))
        for method in sorted(artifacts["method"].unique())
        for series in dataset_series(artifacts, str(method), protocol)
    ]
    results = workers.map(partial(_predict_task, predict=predict, fit=fit, protocol=protocol), tasks,
                          desc="predictor sweep (dataset, PnP method)", progress=progress)  # fmt: skip
    if hazard is not None:
        results.append(hazard_rows(artifacts, hazard, protocol, predict.hazard.levels))
    return pd.concat(results, ignore_index=True)


def combined_rows(theta_p: pd.DataFrame, best: pd.DataFrame, error: str = "error_next_step",
                  inliers: str = "next_step") -> pd.DataFrame:
    """The rows of "error_combined" (ours, issue 38): per dataset, method, tolerance and safety factor k, the earlier
    stop of ``error``'s theta_p(k) and of ``inliers``' theta_p at the n_t chosen for that tolerance, method and
    trajectory in ``best`` (the first world's Tables I-III, :func:`~.paper_tables.best_table`), each guarding what the
    other cannot see (:func:`~.error_predictors.combined`). Its status and fit are those of the predictor that
    stops first. No rows where ``best`` has no zero-incursion n_t."""
    chosen = best.loc[best["predictor"] == inliers, ["method", "trajectory", "tolerance", "best_operating_point"]]
    chosen = chosen.dropna().rename(columns={"best_operating_point": "n_t"})
    paper = theta_p.loc[theta_p["predictor"] == inliers, ["dataset", "method", "trajectory", "operating_point",
                                                            "theta_p", "status", "fit_status", "reason"]]
    rows = theta_p[theta_p["predictor"] == error].merge(chosen, on=["method", "trajectory", "tolerance"])
    rows = rows.merge(paper.rename(columns={"operating_point": "n_t"}), on=["dataset", "method", "trajectory", "n_t"],
                      suffixes=("", "_inliers"))
    earlier = rows["theta_p_inliers"] < rows["theta_p"]
    rows = rows.assign(predictor="error_combined", theta_p=combined(rows["theta_p"], rows["theta_p_inliers"]),
                       **{column: rows[f"{column}_inliers"].where(earlier, rows[column])
                          for column in ("status", "fit_status", "reason")})
    return rows[COLUMNS].reset_index(drop=True)


def with_pnp_variants(
    artifacts: pd.DataFrame, envelopes: pd.DataFrame, variants: pd.DataFrame, variant_envelopes: pd.DataFrame
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Stage 02's (artifacts, envelopes) with stage 05's tables of the other PnP methods added (Fig. 6).

    A method already in ``artifacts`` keeps stage 02's rows; an envelope (dataset, trajectory, tolerance, method
    and, when the tables have one, failed-frame rule) present in both keeps stage 02's. Each of the four tables is
    checked first (:mod:`poseintegrity.table_checks`: a duplicated row inside one of them is refused naming
    it, never silently dropped or counted twice).
    """
    check_artifacts(artifacts, "the artifacts table (stage 02)", columns=REQUIRED_COLUMNS)
    check_artifacts(variants, "the PnP variants table (stage 05)", columns=REQUIRED_COLUMNS)
    check_envelopes(envelopes, "the envelopes table (stage 02)")
    check_envelopes(variant_envelopes, "the PnP variants' envelopes table (stage 05)")
    extra = variants[~variants["method"].isin(artifacts["method"].unique())]
    keys = ["dataset", "trajectory", "tolerance", "method", *(["rule"] if "rule" in envelopes.columns else [])]
    return (
        pd.concat([artifacts, extra], ignore_index=True),
        pd.concat([envelopes, variant_envelopes], ignore_index=True).drop_duplicates(keys),
    )


ENVELOPE_COLUMNS = ("world", "dataset", "trajectory", "method", "tolerance", "theta_a", "censored")


def attach_envelopes(theta_p: pd.DataFrame, envelopes: pd.DataFrame, protocol: ProtocolParams) -> pd.DataFrame:
    """The prediction table: one row per sweep row and tolerance, with world, theta_a, censored, spl, incursion.

    envelopes : the stage-02 envelopes of one failed-frame rule (:func:`poseintegrity.localization.envelope.headline`
    gives the paper's tables' rule). A dataset / method without an actual envelope is dropped (it cannot be scored).
    Checked on read (ValueError): the envelopes' columns, one envelope per dataset, trajectory, method and tolerance
    (a duplicated row would count a dataset twice in every curve), their tolerances are those of ``protocol`` (a
    tolerance the params name would otherwise find no row, and its figures would silently be NaN), theta_a in
    [0, range end], and an envelope for every (dataset, trajectory, method) of ``theta_p`` (one missing would
    drop that dataset from every curve): :class:`~poseintegrity.table_checks.TableError` naming them. A sweep row that names
    a tolerance (the error predictors') is scored on that tolerance's envelope only. An envelope stage 02
    could not read (theta_a NaN, status ``not_measured``) is left out of the scoring with a warning naming its
    datasets: there is nothing to score a prediction against.
    """
    missing = [column for column in ENVELOPE_COLUMNS if column not in envelopes.columns]
    if missing:
        raise TableError(f"the envelopes table lacks columns {missing} (stage 02 writes {list(ENVELOPE_COLUMNS)})")
    keys = ["dataset", "trajectory", "method"]
    repeated = envelopes[envelopes.duplicated([*keys, "tolerance"], keep=False)]
    if len(repeated):
        row = repeated.iloc[0]
        raise TableError(f"the envelopes table holds {len(repeated)} rows for the same dataset, trajectory, method and "
                         f"tolerance, e.g. {row.dataset} ({row.trajectory}, {row.method}, {row.tolerance}): one "
                         f"failed-frame rule's rows are expected (localization.envelope.headline)")
    if set(envelopes["tolerance"]) != set(protocol.tolerance_names):
        raise TableError(f"the envelopes have tolerances {sorted(set(envelopes['tolerance']))}, protocol.tolerances "
                         f"are {protocol.tolerance_names}: was stage 02 run with another protocol?")
    end = envelopes["trajectory"].map(protocol.range_end)
    outside = envelopes[~envelopes["theta_a"].between(0.0, end) & envelopes["theta_a"].notna()]
    if len(outside):
        row = outside.iloc[0]
        raise TableError(f"{len(outside)} envelopes lie outside [0, the protocol's range end], e.g. {row.dataset} "
                         f"({row.trajectory}, {row.tolerance}, {row.method}): theta_a = {row.theta_a}")
    check_envelopes(envelopes, "the envelopes table")
    wanted = theta_p[keys].drop_duplicates()
    absent = wanted.merge(envelopes[keys].drop_duplicates(), on=keys, how="left", indicator=True)
    absent = absent[absent["_merge"] == "left_only"]
    if len(absent):
        shown = ", ".join(f"{row.dataset} ({row.trajectory}, {row.method})" for row in absent.head(5).itertuples())
        raise TableError(f"the envelopes table has no envelope for {len(absent)} (dataset, trajectory, method) of the "
                         f"predictions, e.g. {shown}: they would be dropped from every curve (was stage 02 run on "
                         f"other datasets?)")
    scored = envelopes[[*keys, "world", "tolerance", "theta_a", "censored"]]
    tolerance_free = theta_p["tolerance"].fillna("") == "" if "tolerance" in theta_p else pd.Series(True, theta_p.index)
    table = pd.concat([  # a row made for one tolerance is scored on it alone, the others on every tolerance
        theta_p[tolerance_free].drop(columns="tolerance", errors="ignore").merge(scored, on=keys, how="inner"),
        theta_p[~tolerance_free].merge(scored, on=[*keys, "tolerance"], how="inner"),
    ], ignore_index=True)
    unread = table[table["theta_a"].isna()]  # not_measured (check_envelopes): nothing to score a prediction against
    if len(unread):
        names = sorted(set(unread["dataset"]))
        warnings.warn(f"{len(names)} dataset(s) left out of the scoring: their actual envelope could not be read (no "
                      f"trusted ground truth before it ends; stage 02's envelopes, status not_measured): {names}",
                      stacklevel=2)
    return with_metrics(table[table["theta_a"].notna()].reset_index(drop=True))
