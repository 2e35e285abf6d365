"""The failure hazard trained and judged on the population's worlds, never on the world it is judged on (issue 50).

For every world A of the population (its held-out world), per tolerance:

1. **h chosen on the training worlds alone.** Each training world B is predicted by hazard models fitted on the
   training worlds other than B (:func:`~poseintegrity.prediction.hazard.model.fit_hazard`); on those held-out
   curves h is chosen by the population's rule (:func:`~poseintegrity.population.judge.chosen_on`: the largest mean
   SPL among the h with zero incursion in ``population.transfer.zero_incursion_worlds`` of them);
2. **A predicted by models fitted on all training worlds**, at every h: its SPL / R_i curves, and its rows read at
   the h of step 1 (the judge's ``others`` point for the hazard predictors);
3. on A's risk-set rows, the held-out hazards beside two one-column hazards fitted alike (the predicted error alone;
   n_i alone): their Brier scores and reliability; the permutation importance of each evidence column (the Brier
   score's rise when the column is shuffled within A's rows, :func:`importance`);
4. the failure mode of each of A's arcs that failed (:func:`failure_modes`).

Then the models stage 04 applies (main, validation, recorded data) are fitted on every world, with the h chosen on
the held-out curves of step 2 (the file ``predict.hazard.model``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from poseintegrity.localization.envelope import headline
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.population.judge import arc_curves, chosen_on
from poseintegrity.prediction.hazard.applied import LONG_RANGE, NEXT_STEP, HazardSet, arc_rows
from poseintegrity.prediction.hazard.model import HazardFitError, HazardModel, brier_score, fit_hazard, reliability
from poseintegrity.prediction.hazard.risk_sets import LONG_RANGE as LONG_RANGE_COLUMNS
from poseintegrity.prediction.hazard.risk_sets import long_range_rows, next_step_rows
from poseintegrity.prediction.hazard.stop_evidence import EVIDENCE, stop_evidence
from poseintegrity.prediction.metrics import operating_curves, with_metrics
from poseintegrity.prediction.transfer import DECIMALS
from poseintegrity.resampling import cluster_weights, percentile_interval
from poseintegrity.seeding import keyed_rng
from poseintegrity.workers import Progress

FEATURES = {NEXT_STEP: EVIDENCE, LONG_RANGE: LONG_RANGE_COLUMNS}
ONE_COLUMN = {"error_alone": ("predicted_error",), "inliers_alone": ("log_inliers",)}  # the Brier comparisons
CLIFF_INLIERS = 8.0  # a stop's mean n_i below this: the count fell off its cliff (issue 38: val_2_arc090 8.3 -> 6.0)
MODES = ("no_pose", "cliff", "accelerating_bias")
MIN_WORLDS = 4  # a held-out world, one held out within its training worlds, two to fit and calibrate on


class World:
    """One world of the population for one tolerance: its stage-02 rows, evidence and risk sets."""

    def __init__(self, name: str, artifacts: pd.DataFrame, envelopes: pd.DataFrame, tolerance: tuple[float, float],
                 tolerance_name: str, protocol: ProtocolParams) -> None:
        self.name, self.artifacts = name, artifacts.assign(world=name)
        arcs = envelopes[(envelopes["trajectory"] == "arc") & (envelopes["method"] == protocol.pnp_method)
                         & (envelopes["tolerance"] == tolerance_name)]
        self.envelopes = arcs.assign(world=name)
        self.evidence = stop_evidence(self.artifacts, protocol.pnp_method, tolerance)
        n_sampled_stops = protocol.stops_sampled("arc")
        self.rows = {NEXT_STEP: next_step_rows(self.evidence, self.envelopes, n_sampled_stops),
                     LONG_RANGE: long_range_rows(self.evidence, self.envelopes, n_sampled_stops)}


def _fit(worlds: list[World], predictor: str, features: tuple[str, ...], C: float, folds: int) -> HazardModel:
    rows = pd.concat([w.rows[predictor] for w in worlds], ignore_index=True)
    return fit_hazard(rows, features, C, folds)


def fit_models(worlds: list[World], C: float, folds: int) -> dict[str, HazardModel]:
    """Both predictors' hazard models fitted on the risk sets of ``worlds`` (:data:`FEATURES`)."""
    return {predictor: _fit(worlds, predictor, features, C, folds) for predictor, features in FEATURES.items()}


def models_without(population: list[World], C: float, folds: int) -> Callable[..., dict[str, HazardModel]]:
    """models_without(*names): :func:`fit_models` on the worlds of ``population`` other than ``names``, each set of
    names fitted once (h chosen for world A holds world B out, and for world B world A: the same models)."""
    fitted: dict[frozenset, dict[str, HazardModel]] = {}

    def without(*names: str) -> dict[str, HazardModel]:
        key = frozenset(names)
        if key not in fitted:
            fitted[key] = fit_models([w for w in population if w.name not in key], C, folds)
        return fitted[key]

    return without


def predicted(world: World, models: dict[str, HazardModel], protocol: ProtocolParams, tolerance_name: str,
              levels: np.ndarray) -> pd.DataFrame:
    """``world``'s hazard rows at every h (stage 04's rows with world, theta_a, censored, spl, incursion)."""
    rows = arc_rows(world.evidence, models, protocol, tolerance_name, levels)
    scored = rows.merge(world.envelopes[["dataset", "world", "theta_a", "censored"]], on="dataset", how="inner")
    return with_metrics(scored[scored["theta_a"].notna()])


def choose_h(held: World, population: list[World], without: Callable[..., dict[str, HazardModel]],
             protocol: ProtocolParams, tolerance_name: str, levels: np.ndarray,
             zero_incursion_worlds: float) -> pd.DataFrame:
    """Step 1 for ``held``: (predictor, tolerance, operating_point, feasible) chosen on the curves of the other
    worlds, each predicted by models fitted without it and without ``held`` (``without``: :func:`models_without`)."""
    curves = {other.name: arc_curves(operating_curves(predicted(other, without(held.name, other.name), protocol,
                                                                tolerance_name, levels)), protocol.pnp_method)
              for other in population if other is not held}
    return chosen_on(curves, zero_incursion_worlds)


def importance(model: HazardModel, rows: pd.DataFrame, repeats: int, rng: np.random.Generator) -> pd.DataFrame:
    """Permutation importance (Breiman 2001; scikit-learn's ``permutation_importance`` computes the same but asks for
    an estimator with ``fit``, which a stored model has not): per evidence column, the mean and standard deviation
    over ``repeats`` shuffles of that column within ``rows`` of the Brier score's rise."""
    failed = rows["failed"].to_numpy(float)
    base = brier_score(model.predict(rows), failed)
    found = []
    for feature in model.features:
        rises = []
        for _ in range(repeats):
            shuffled = rows.assign(**{feature: rng.permutation(rows[feature].to_numpy())}) if feature in rows else rows
            rises.append(brier_score(model.predict(shuffled), failed) - base)
        found.append({"feature": feature, "importance": float(np.mean(rises)), "importance_std": float(np.std(rises))})
    return pd.DataFrame(found, columns=["feature", "importance", "importance_std"])


def failure_modes(world: World, max_failed_fraction: float) -> pd.DataFrame:
    """Per arc of ``world`` that failed (not censored): the stop it failed at (the first stop at or past theta_a)
    and why (:data:`MODES`): ``no_pose`` when more than ``max_failed_fraction`` of that stop's images had no pose;
    ``cliff`` when its mean n_i fell below CLIFF_INLIERS or to less than half the previous stop's; else
    ``accelerating_bias`` (poses with a healthy count, wrong beyond the tolerance: the consensus turned wrong).
    Columns: world, dataset, theta_a, failed_stop, stop_before, mode."""
    rows = []
    failed = world.envelopes[~world.envelopes["censored"].astype(bool) & world.envelopes["theta_a"].notna()]
    for row in failed.itertuples(index=False):
        arc = world.evidence[world.evidence["dataset"] == row.dataset].sort_values("stop")
        at_or_past = np.flatnonzero(arc["theta_deg"].to_numpy() >= row.theta_a - 1e-9)
        if not len(at_or_past) or at_or_past[0] == 0:
            continue  # the first stop failed: nothing came before it to see
        j = int(at_or_past[0])
        inliers = np.expm1(arc["log_inliers"].to_numpy())
        if 1.0 - arc["posed_share"].iloc[j] > max_failed_fraction:
            mode = "no_pose"
        elif inliers[j] < CLIFF_INLIERS or inliers[j] < 0.5 * inliers[j - 1]:
            mode = "cliff"
        else:
            mode = "accelerating_bias"
        rows.append({"world": world.name, "dataset": row.dataset, "theta_a": float(row.theta_a),
                     "failed_stop": int(arc["stop"].iloc[j]), "stop_before": int(arc["stop"].iloc[j - 1]),
                     "mode": mode})
    return pd.DataFrame(rows, columns=["world", "dataset", "theta_a", "failed_stop", "stop_before", "mode"])


def train_population(worlds: dict[str, tuple[pd.DataFrame, pd.DataFrame]], protocol: ProtocolParams,
                     levels: np.ndarray, C: float, folds: int, repeats: int, seed: int,
                     zero_incursion_worlds: float, progress: bool = True) -> dict:
    """Steps 1-4 for every world and tolerance, then the models of every world (module docstring).

    worlds : name -> (stage 02's artifacts table, its envelopes table), at least MIN_WORLDS; progress : print a
    progress line now and then.
    Returns {"predictions", "chosen", "risk", "importance", "modes": DataFrames; "hazard": the :class:`HazardSet` of
    every world}. ArgumentError (:class:`~poseintegrity.prediction.hazard.model.HazardFitError`) when a model cannot be
    fitted (too few worlds, no failure among their rows).
    """
    if len(worlds) < MIN_WORLDS:
        raise HazardFitError(f"the hazard needs at least {MIN_WORLDS} worlds in population.worlds (one held out, one "
                             f"more held out inside its training worlds to choose h, two left to fit and calibrate "
                             f"on), got {len(worlds)}")
    predictions, chosen, risk, importances, modes = [], [], [], [], []
    models_all, chosen_all = {}, {}
    lines = Progress(len(worlds) * len(protocol.tolerances), "hazard, each world held out once", enabled=progress)
    for tolerance, name in zip(protocol.tolerances, protocol.tolerance_names):
        population = [World(w, *tables, tolerance, name, protocol) for w, tables in worlds.items()]
        without = models_without(population, C, folds)
        for held in population:
            training = [w for w in population if w is not held]
            points = choose_h(held, population, without, protocol, name, levels, zero_incursion_worlds)
            chosen.append(points.assign(world=held.name))
            models = without(held.name)
            predictions.append(predicted(held, models, protocol, name, levels))
            for predictor, model in models.items():
                rows = held.rows[predictor]
                entry = rows[["world", "dataset", "theta_deg", "failed"]].assign(
                    predictor=predictor, tolerance=name, hazard=model.predict(rows))
                if predictor == NEXT_STEP:
                    entry = entry.assign(stop=rows["stop"].to_numpy(), **{c: rows[c].to_numpy() for c in EVIDENCE})
                    for label, columns in ONE_COLUMN.items():
                        entry[label] = _fit(training, predictor, columns, C, folds).predict(rows)
                risk.append(entry)
                rng = keyed_rng(seed, f"importance/{held.name}/{name}/{predictor}")
                importances.append(importance(model, rows, repeats, rng).assign(
                    world=held.name, tolerance=name, predictor=predictor))
            modes.append(failure_modes(held, protocol.envelope.max_failed_fraction).assign(tolerance=name))
            lines.update()
        held_out = pd.concat(predictions, ignore_index=True)
        held_out = held_out[held_out["tolerance"] == name]
        all_points = chosen_on({w.name: arc_curves(operating_curves(held_out[held_out["world"] == w.name]),
                                                   protocol.pnp_method) for w in population}, zero_incursion_worlds)
        for predictor, model in without().items():
            models_all[name, predictor] = model
            point = all_points[(all_points["predictor"] == predictor) & all_points["feasible"]]["operating_point"]
            chosen_all[name, predictor] = float(point.iloc[0]) if len(point) else float("nan")
    trained = tuple(sorted(set().union(*(set(w.artifacts["dataset"]) for w in population))))
    return {"predictions": pd.concat(predictions, ignore_index=True), "chosen": pd.concat(chosen, ignore_index=True),
            "risk": pd.concat(risk, ignore_index=True), "importance": pd.concat(importances, ignore_index=True),
            "modes": pd.concat(modes, ignore_index=True), "hazard": HazardSet(trained, models_all, chosen_all)}


def brier_table(risk: pd.DataFrame, n_draws: int, level: float, rng: np.random.Generator) -> pd.DataFrame:
    """Per tolerance and predictor, the held-out Brier score of the hazard, of the one-column hazards (next step
    only) and of the base rate (the training-free floor: the held-out rows' own failure share), the rows, and for each
    one-column hazard ``<label>_minus_hazard``: the interval of its Brier score minus the hazard's, the worlds
    resampled with replacement (``n_draws`` draws, percentile interval at ``level``): above 0, the hazard is better."""
    rows = []
    for (tolerance, predictor), group in risk.groupby(["tolerance", "predictor"], sort=True):
        failed = group["failed"].to_numpy(float)
        weights = cluster_weights(group["world"].to_numpy(), n_draws, rng)
        hazard_error = (group["hazard"].to_numpy(float) - failed) ** 2
        entry = {"tolerance": tolerance, "predictor": predictor, "n_rows": len(group), "n_failed": int(failed.sum()),
                 "hazard": brier_score(group["hazard"], failed),
                 "base_rate": brier_score(np.full(len(group), failed.mean()), failed)}
        for label in ONE_COLUMN:
            if label not in group or not group[label].notna().all():
                entry[label], entry[f"{label}_minus_hazard"] = float("nan"), [None, None]
                continue
            entry[label] = brier_score(group[label], failed)
            difference = (group[label].to_numpy(float) - failed) ** 2 - hazard_error
            entry[f"{label}_minus_hazard"] = percentile_interval(weights @ difference / weights.sum(axis=1), level)
        rows.append(entry)
    return pd.DataFrame(rows)


def reliability_table(risk: pd.DataFrame, edges: np.ndarray) -> pd.DataFrame:
    """:func:`~poseintegrity.prediction.hazard.model.reliability` of the held-out hazards per tolerance and
    predictor (and of the one-column hazards, column ``hazard_of``)."""
    tables = []
    for (tolerance, predictor), group in risk.groupby(["tolerance", "predictor"], sort=True):
        for column in ("hazard", *ONE_COLUMN):
            if column in group and group[column].notna().all():
                tables.append(reliability(group[column], group["failed"], edges).assign(
                    tolerance=tolerance, predictor=predictor, hazard_of=column))
    return pd.concat(tables, ignore_index=True)


def world_tables(artifacts: pd.DataFrame, envelopes: pd.DataFrame, protocol: ProtocolParams) -> tuple[pd.DataFrame,
                                                                                                         pd.DataFrame]:
    """A world's (artifacts, envelopes of the paper's failed-frame rule) as :func:`train_population` reads them."""
    return artifacts, headline(envelopes, protocol.envelope)


def failure_mode_counts(modes: pd.DataFrame) -> pd.DataFrame:
    """Arcs that failed per tolerance and mode (:func:`failure_modes`), every mode shown."""
    counts = modes.groupby(["tolerance", "mode"]).size().unstack(fill_value=0)
    return counts.reindex(columns=list(MODES), fill_value=0)


def hazard_metrics(trained: dict, brier: pd.DataFrame, note: str = "") -> dict:
    """hazard.json: per tolerance and predictor the held-out Brier scores (:func:`brier_table`), the evidence ranked by
    permutation importance (mean over the held-out worlds), the h chosen on the training worlds of each held-out world
    (and whether one qualified) and on all of them, and the held-out arcs it let past theta_a there
    (:func:`incursions`); per tolerance the arcs that failed by each mode."""
    result: dict = {"trained": True, "note": note, "n_worlds": int(trained["chosen"]["world"].nunique()),
                    "trained_on_arcs": len(trained["hazard"].trained_on), "tolerances": {}}
    ranked = trained["importance"].groupby(["tolerance", "predictor", "feature"])["importance"].mean()
    over = incursions(trained)
    for (tolerance, predictor), entry in brier.set_index(["tolerance", "predictor"]).iterrows():
        order = ranked.loc[tolerance, predictor].sort_values(ascending=False)
        chosen = trained["chosen"]
        folds = chosen[(chosen["tolerance"] == tolerance) & (chosen["predictor"] == predictor)]
        result["tolerances"].setdefault(tolerance, {})[predictor] = {
            "brier": entry.to_dict(), "importance": {str(k): float(v) for k, v in order.items()},
            "h_per_held_out_world": {str(r.world): {"h": float(r.operating_point), "qualified": bool(r.feasible)}
                                     for r in folds.itertuples(index=False)},
            "h_all_worlds": trained["hazard"].chosen.get((tolerance, predictor)),
            "incursions": over[(over["tolerance"] == tolerance) & (over["predictor"] == predictor)].drop(
                columns=["tolerance", "predictor"]).to_dict("records")}
    for tolerance, counts in failure_mode_counts(trained["modes"]).iterrows():
        result["tolerances"].setdefault(tolerance, {})["failure_modes"] = {k: int(v) for k, v in counts.items()}
    return result


SHOWN_EVIDENCE = ("log_inliers", "predicted_error", "kinematic_error", "stop_spread", "bootstrap_spread",
                  "rerun_elsewhere")  # what incursions() shows of the stop before theta_a


def incursions(trained: dict) -> pd.DataFrame:
    """Every held-out arc a hazard predictor let past theta_a at the h chosen on its world's training worlds: world,
    tolerance, predictor, dataset, h, theta_p, theta_a, its failure mode, and at the stop before theta_a (the last
    stop the next-step hazard judged) that hazard and the evidence of :data:`SHOWN_EVIDENCE`."""
    chosen = trained["chosen"][trained["chosen"]["feasible"]].rename(columns={"operating_point": "h"})
    rows = trained["predictions"].assign(h=trained["predictions"]["operating_point"].round(DECIMALS))
    at = rows.merge(chosen.assign(h=chosen["h"].round(DECIMALS))[["world", "tolerance", "predictor", "h"]],
                    on=["world", "tolerance", "predictor", "h"])
    over = at[at["incursion"] == 1][["world", "tolerance", "predictor", "dataset", "h", "theta_p", "theta_a"]]
    risk = trained["risk"]
    before = risk[(risk["predictor"] == NEXT_STEP) & (risk["failed"] == 1)]
    before = before[["world", "tolerance", "dataset", "stop", "hazard", *SHOWN_EVIDENCE]].rename(
        columns={"stop": "stop_before", "hazard": "hazard_before"})
    modes = trained["modes"][["world", "tolerance", "dataset", "mode"]]
    return over.merge(modes, on=["world", "tolerance", "dataset"], how="left").merge(
        before, on=["world", "tolerance", "dataset"], how="left").sort_values(
        ["tolerance", "predictor", "world", "dataset"]).reset_index(drop=True)
