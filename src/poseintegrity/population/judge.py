"""Every predictor judged across the population's worlds (ours, issue 49), as a held-out test set judges a model.

Per world (its SPL vs R_i curves on the arcs of ``protocol.pnp_method``, stage 04 run on it), per predictor and
tolerance, three operating points:

- **own**: the world's own max mean SPL at zero incursion (Tables I-III, the paper's protocol: the point chosen on the
  arcs it is scored on);
- **main**: the point chosen on the main world (Tables I-III there), applied unchanged;
- **others**: the point chosen on the other worlds of the population (leave one world out), applied unchanged.

Each with its mean SPL, incursion rate R_i (eq. 4) and share of the world's ceiling (:mod:`~poseintegrity.prediction.
ceiling`: (SPL - the world's own static SPL) / (its mean theta_a - that static SPL); at a transferred point the SPL is
what the robot got, incursions included: R_i says what it cost).

**How a point is chosen on several worlds.** Zero incursion over the pooled 200+ arcs of a dozen worlds is a far
stricter rule than over one world's 21: it asks that the worst arc of all the worlds be safe, an extreme value of a much
larger sample, so the point slides to the most conservative end and says little about a world's 21 arcs. The question a
lab asks is "will a world like mine have zero incursion at this point?". So the point is the one of largest mean SPL
(over the other worlds, each world weighed once) among the points with zero incursion in at least a share
``population.transfer.zero_incursion_worlds`` (0.9) of the other worlds; where none qualifies, the most conservative
point (flagged). The share of held-out worlds with zero incursion then checks the rule where it was not chosen.

Across the worlds, per predictor: the median share and its 10-90 % range at each kind of point, at the transferred
points the share of worlds with zero incursion and the mean R_i; and for two predictors, in how many worlds A's mean SPL
beats B's (the same world: the same ceiling) and the two-sided sign test of those wins against the losses (ties left
out). A world where a predictor has no zero-incursion point has no SPL there: it ranks lowest (a loss, the low end of a
range), as in :mod:`~poseintegrity.prediction.intervals`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.stats import binomtest

from poseintegrity.prediction.ceiling import ceiling, ceiling_share
from poseintegrity.prediction.intervals import PAIRED
from poseintegrity.prediction.paper_tables import best_table
from poseintegrity.prediction.sweeps import CONSERVATIVE_HIGH
from poseintegrity.prediction.transfer import DECIMALS

# the paper's predictors and ours (issue 38). Not error_combined: its next-step half stops at the n_t each world's own
# Tables I-III chose (sweeps.combined_rows), a hindsight no transferred point removes (on the first run of 12 worlds
# its share and its zero-incursion worlds were the same at every kind of point at 4 mm / 10 deg: 14 %, 100 %)
JUDGED = ("static", "long_range", "mlp", "next_step", "error_long_range", "error_next_step",
          "error_next_step_observed", "hazard_next_step", "hazard_long_range")
# ours (issue 50): the hazard predictors' rows of a world come from models trained without it (population/hazard.py),
# and their ``others`` point is the h chosen on the training worlds' held-out curves (:func:`judge_population`)
KEYS = ["predictor", "tolerance"]


def arc_curves(curves: pd.DataFrame, method: str) -> pd.DataFrame:
    """The SPL vs R_i curves of the judged predictors on the arcs of ``method`` (rows of
    :func:`~poseintegrity.prediction.metrics.operating_curves`), their operating points rounded to DECIMALS so that
    the grids of two worlds meet exactly."""
    rows = curves[(curves["trajectory"] == "arc") & (curves["method"] == method) & curves["predictor"].isin(JUDGED)]
    return rows.assign(operating_point=rows["operating_point"].round(DECIMALS))


def chosen_on(curves: dict[str, pd.DataFrame], zero_incursion_worlds: float) -> pd.DataFrame:
    """The operating point chosen on several worlds (module docstring): one row per predictor and tolerance with
    ``operating_point`` and ``feasible`` (False: no point had zero incursion in enough worlds; the most conservative
    was taken). curves : world -> :func:`arc_curves`."""
    stacked = pd.concat([c.assign(world=w) for w, c in curves.items()], ignore_index=True)
    n_worlds = len(curves)
    rows = []
    for (predictor, tolerance), group in stacked.groupby(KEYS, sort=True):
        per_point = group.assign(safe=(group["incursion_rate"] <= 0) & (group["n"] > 0)).groupby("operating_point")
        table = per_point.agg(mean_spl=("mean_spl", "mean"), safe=("safe", "sum"), worlds=("world", "nunique"))
        table = table[table["worlds"] == n_worlds]  # a point every world swept
        high = CONSERVATIVE_HIGH.get(predictor, True)
        qualified = table[table["safe"] >= zero_incursion_worlds * n_worlds - 1e-9]
        if qualified.empty:
            point, feasible = (table.index.max() if high else table.index.min()), False
        else:
            best = qualified[qualified["mean_spl"] >= qualified["mean_spl"].max() - 1e-9].index
            point, feasible = (best.max() if high else best.min()), True
        rows.append({"predictor": predictor, "tolerance": tolerance, "operating_point": float(point),
                     "feasible": feasible})
    return pd.DataFrame(rows, columns=[*KEYS, "operating_point", "feasible"])


def read_at(curves: pd.DataFrame, points: pd.DataFrame) -> pd.DataFrame:
    """One world's curves read at ``points`` (predictor, tolerance, operating_point): mean_spl, incursion_rate (NaN
    where the world has no such curve point)."""
    merged = points[[*KEYS, "operating_point"]].assign(operating_point=points["operating_point"].round(DECIMALS))
    return merged.merge(curves[[*KEYS, "operating_point", "mean_spl", "incursion_rate"]],
                        on=[*KEYS, "operating_point"], how="left")


def judge_world(table: pd.DataFrame, curves: pd.DataFrame, points: dict[str, pd.DataFrame], method: str,
                tolerances: list[str]) -> pd.DataFrame:
    """One world at every kind of operating point: one row per predictor, tolerance and kind (``point``: own, main,
    others) with operating_point, mean_spl, incursion_rate, share (of this world's ceiling) and gain (SPL - this
    world's own static SPL, deg).

    table : the world's prediction table (stage 04's predictions.parquet, its theta_a); curves : :func:`arc_curves`;
    points : kind -> the operating points to read (predictor, tolerance, operating_point); "own" is the world's
    Tables I-III (NaN where it has no zero-incursion point).
    """
    best = best_table(curves)  # Tables I-III of the world: its own points, and its static baseline for the ceiling
    limits = ceiling(table, best, method, tolerances)
    own = best.rename(columns={"best_operating_point": "operating_point"})[[*KEYS, "operating_point"]]
    rows = []
    for kind, chosen in {"own": own, **points}.items():
        read = read_at(curves, chosen.dropna(subset=["operating_point"]))
        read = chosen[KEYS].merge(read, on=KEYS, how="left")
        for row in read.itertuples(index=False):
            entry = limits.get(row.tolerance, {})
            spl = float(row.mean_spl) if pd.notna(row.mean_spl) else np.nan
            rows.append({"predictor": row.predictor, "tolerance": row.tolerance, "point": kind,
                         "operating_point": float(row.operating_point) if pd.notna(row.operating_point) else np.nan,
                         "mean_spl": spl, "incursion_rate": float(row.incursion_rate) if pd.notna(
                             row.incursion_rate) else np.nan,
                         "share": ceiling_share(spl, entry) if entry else np.nan,
                         "gain": spl - entry["static_spl"] if entry else np.nan,
                         "mean_theta_a": entry.get("mean_theta_a", np.nan),
                         "static_spl": entry.get("static_spl", np.nan)})
    return pd.DataFrame(rows)


def _ranked(values: pd.Series) -> np.ndarray:
    """No SPL (no zero-incursion point) ranks lowest."""
    return np.where(values.isna(), -np.inf, values.to_numpy(float))


def _quantiles(values: pd.Series, q: tuple[float, ...]) -> list[float | None]:
    """Quantiles over the worlds (linear between them), a world without a value ranked lowest; -inf shown as None."""
    found = np.quantile(_ranked(values), q) if len(values) else np.full(len(q), np.nan)
    return [float(v) if np.isfinite(v) else None for v in found]


def across_worlds(judged: pd.DataFrame) -> dict:
    """``<tolerance>.<predictor>.<point>``: {n_worlds, median_share, share_10_90, median_gain, gain_10_90} and, at the
    transferred points, zero_incursion_worlds (share of worlds with R_i = 0) and mean_incursion_rate; judged : the
    :func:`judge_world` rows of every world (column ``world``)."""
    result: dict = {}
    for (tolerance, predictor, kind), rows in judged.groupby(["tolerance", "predictor", "point"], sort=True):
        entry = {"n_worlds": int(rows["world"].nunique()),
                 "median_share": _quantiles(rows["share"], (0.5,))[0],
                 "share_10_90": _quantiles(rows["share"], (0.1, 0.9)),
                 "median_gain": _quantiles(rows["gain"], (0.5,))[0], "gain_10_90": _quantiles(rows["gain"], (0.1, 0.9))}
        if kind != "own":
            rate = rows["incursion_rate"]
            entry |= {"zero_incursion_worlds": float((rate == 0).mean()), "mean_incursion_rate": float(rate.mean())}
        result.setdefault(tolerance, {}).setdefault(predictor, {})[kind] = entry
    return result


def paired(judged: pd.DataFrame, point: str = "own") -> dict:
    """``<tolerance>."<A> vs <B>"``: {wins, losses, ties, sign_test_p} of A's mean SPL against B's over the worlds at
    their ``point`` operating points, for the pairs of :data:`~poseintegrity.prediction.intervals.PAIRED` (A - B read
    as there); a world without a zero-incursion point for one of them is that one's loss, for both a tie."""
    rows = judged[judged["point"] == point]
    spl = rows.pivot_table(index=["tolerance", "world"], columns="predictor", values="mean_spl", dropna=False)
    result: dict = {}
    for tolerance, table in spl.groupby(level="tolerance"):
        entry = {}
        for i, a in enumerate(PAIRED):
            for b in PAIRED[i + 1:]:
                if a not in table or b not in table:
                    continue
                spl_a, spl_b = _ranked(table[a]), _ranked(table[b])
                wins, losses = int((spl_a > spl_b).sum()), int((spl_a < spl_b).sum())
                entry[f"{a} vs {b}"] = {"wins": wins, "losses": losses, "ties": int(len(table) - wins - losses),
                                        "sign_test_p": float(binomtest(wins, wins + losses).pvalue) if wins + losses
                                        else 1.0}
        result[str(tolerance)] = entry
    return result


def judge_population(worlds: dict[str, tuple[pd.DataFrame, pd.DataFrame]], main_curves: pd.DataFrame,
                     zero_incursion_worlds: float, method: str, tolerances: list[str],
                     held_out_points: pd.DataFrame | None = None) -> pd.DataFrame:
    """:func:`judge_world` of every world (column ``world``) at its own points, at the main world's (``main_curves``:
    its :func:`arc_curves`) and at the points chosen on the other worlds (:func:`chosen_on`, column ``feasible`` of
    that choice). worlds : name -> (prediction table, :func:`arc_curves`). held_out_points : (world, predictor,
    tolerance, operating_point, feasible) rows that replace the others' point of a predictor whose rows on the other
    worlds were made knowing this one (the hazard's: chosen on models fitted without it)."""
    main = best_table(main_curves).rename(columns={"best_operating_point": "operating_point"})[[*KEYS,
                                                                                                "operating_point"]]
    judged = []
    for name, (table, curves) in worlds.items():
        others = chosen_on({w: c for w, (_, c) in worlds.items() if w != name}, zero_incursion_worlds)
        if held_out_points is not None and len(held_out_points):
            own = held_out_points[held_out_points["world"] == name][[*KEYS, "operating_point", "feasible"]]
            others = pd.concat([others, own], ignore_index=True).drop_duplicates(KEYS, keep="last")
        rows = judge_world(table, curves, {"main": main, "others": others}, method, tolerances)
        feasible = others.assign(point="others")[[*KEYS, "point", "feasible"]]
        judged.append(rows.merge(feasible, on=[*KEYS, "point"], how="left").assign(world=name))
    return pd.concat(judged, ignore_index=True)


GROUND_TRUTH = ("trusted_share", "p99_E_t_truth_mm", "p99_E_r_truth_deg", "r11_passed")  # realism.truth_accuracy


def world_realism(artifacts: dict) -> dict:
    """What one world's stage-02 metrics (artifacts.json) say of its ground truth and realism: the share of frames
    whose board pose is trusted, R11 (what the board adds to E_t and E_r, 99th percentile; passed: within the bar
    of a quarter of the tightest tolerance) and how many of the realism bars it passes. A world's predictors are
    judged against that ground truth: where R11 fails, a theta_a within its error of the tolerance is not known."""
    realism = artifacts.get("realism", {})
    truth = realism.get("truth_accuracy", {})
    return {key: truth.get(key) for key in GROUND_TRUTH} | {
        "realism_bars_passed": realism.get("n_bars_passed"),
        "realism_bars": sum(isinstance(v, bool) for v in realism.get("passed", {}).values())}


def population_metrics(judged: pd.DataFrame, chosen: pd.DataFrame, applied: dict[str, pd.DataFrame],
                       zero_incursion_worlds: float, realism: dict[str, dict] | None = None) -> dict:
    """The content of ``reports/metrics/population.json``: n_worlds, worlds, the rule, ``across``
    (:func:`across_worlds`), ``paired`` at the own and at the others' points (:func:`paired`), ``per_world``
    (``<world>.<tolerance>.<predictor>.<point>``: operating_point, mean_spl, incursion_rate, share, gain), the points
    chosen on the whole population (``chosen_on_population``) and those points ``applied`` to other worlds (the main
    and validation worlds: :func:`judge_world` rows at point "population"); ``realism``: per world
    :func:`world_realism` (``ground_truth``), with the number of worlds whose R11 passed."""
    figures = ["operating_point", "mean_spl", "incursion_rate", "share", "gain"]

    def nested(rows: pd.DataFrame) -> dict:
        out: dict = {}
        for row in rows.itertuples(index=False):
            out.setdefault(row.tolerance, {}).setdefault(row.predictor, {})[row.point] = {
                key: getattr(row, key) for key in figures}
        return out

    return {
        "n_worlds": int(judged["world"].nunique()), "worlds": sorted(judged["world"].unique()),
        "rule": {"zero_incursion_worlds": zero_incursion_worlds,
                 "text": "the point of largest mean SPL over the other worlds among those with zero incursion in at "
                         f"least {zero_incursion_worlds:.0%} of them (population/judge.py)"},
        "across": across_worlds(judged),
        "paired": {"own": paired(judged, "own"), "others": paired(judged, "others")},
        "chosen_on_population": {t: {p: {"operating_point": float(row.operating_point), "feasible": bool(row.feasible)}
                                     for p, row in group.set_index("predictor").iterrows()}
                                 for t, group in chosen.groupby("tolerance")},
        "applied": {world: nested(rows) for world, rows in applied.items()},
        "per_world": {world: nested(rows) for world, rows in judged.groupby("world")},
        "ground_truth": (realism or {}) | {"r11_passed_worlds": sum(bool(r.get("r11_passed")) for r in
                                                                    (realism or {}).values())},
    }


SEEN_BY = ("hazard_next_step", "hazard_long_range", "error_next_step", "error_next_step_observed", "error_long_range",
           "next_step", "long_range")  # the predictors whose failures-seen-ahead are counted (issue 50)


def seen_ahead(judged: pd.DataFrame, tables: dict[str, pd.DataFrame], modes: pd.DataFrame) -> dict:
    """Per tolerance, predictor and failure mode (population.hazard.failure_modes): of the held-out arcs that failed
    by that mode, how many the predictor stopped before (theta_p <= theta_a: it saw the failure a stop ahead) at its
    ``others`` point (chosen without the arc's world). tables : world -> its prediction table (the hazard's rows
    among them); judged : :func:`judge_population`. ``<tolerance>.<predictor>.<mode>: {seen, arcs, envelope_used}``,
    envelope_used the mean SPL / theta_a over those arcs: at a conservative point every predictor sees nearly every
    failure coming, and what tells them apart is how much of the envelope it kept."""
    result: dict = {}
    points = judged[(judged["point"] == "others") & judged["predictor"].isin(SEEN_BY)]
    for row in points.dropna(subset=["operating_point"]).itertuples(index=False):
        table = tables[row.world]
        at = table[(table["predictor"] == row.predictor) & (table["tolerance"] == row.tolerance)
                   & (table["trajectory"] == "arc") & np.isclose(table["operating_point"], row.operating_point)]
        failed = modes[(modes["world"] == row.world) & (modes["tolerance"] == row.tolerance)]
        scored = failed.merge(at[["dataset", "incursion", "spl"]], on="dataset", how="left")
        for mode, group in scored.groupby("mode"):
            entry = result.setdefault(row.tolerance, {}).setdefault(row.predictor, {}).setdefault(
                mode, {"seen": 0, "arcs": 0, "used": []})
            entry["seen"] += int((group["incursion"] == 0).sum())
            entry["arcs"] += len(group)
            entry["used"] += list(group["spl"] / group["theta_a"])
    for by_predictor in result.values():
        for by_mode in by_predictor.values():
            for entry in by_mode.values():
                entry["envelope_used"] = float(np.nanmean(entry.pop("used"))) if entry["arcs"] else None
    return result
