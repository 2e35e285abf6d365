"""The hazard predictors' rows of stage 04, from a trained set of hazard models (issue 50).

Stage 04 runs ``hazard_next_step`` and ``hazard_long_range`` (:mod:`.stopping`) on the arcs of
``protocol.pnp_method`` with the models of the file ``predict.hazard.model``: one per tolerance and predictor,
trained on the population's worlds (population/hazard.py), never on the world they are applied to: the main and
validation worlds and recorded data get the models trained on every world of the population, each population world
the ones trained without it: rows are never made for a dataset a model was trained on (``trained_on`` names them),
so a population world's own stage 04 gets none from the file trained on every world. The file also holds, per tolerance and predictor, the h chosen on the training worlds
(``chosen``), which the reports read as the transferred operating point. Lines get no rows: the models are trained
on arcs.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from poseintegrity.atomic_write import write_text_atomically
from poseintegrity.errors import ArgumentError
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.prediction.hazard.model import HazardModel
from poseintegrity.prediction.hazard.risk_sets import long_range_features
from poseintegrity.prediction.hazard.stop_evidence import stop_evidence
from poseintegrity.prediction.hazard.stopping import stop_on_failure_probability, stop_on_next_hazard

NEXT_STEP, LONG_RANGE = "hazard_next_step", "hazard_long_range"
HAZARD_PREDICTORS = (NEXT_STEP, LONG_RANGE)
MODEL = "hazard_logistic"  # the ``model`` column of their rows
FORMAT = 1  # the file's layout version


@dataclass(frozen=True)
class HazardSet:
    """The hazard models of every tolerance (name) and predictor, and the h chosen on their training worlds.
    trained_on : the datasets they were trained on; models, chosen : keyed by (tolerance name, predictor); chosen
    NaN where no h qualified; note : why there is no model (empty when there are)."""

    trained_on: tuple[str, ...]
    models: dict[tuple[str, str], HazardModel]
    chosen: dict[tuple[str, str], float]
    note: str = ""

    def to_dict(self) -> dict:
        tolerances: dict = {}
        for (tolerance, predictor), model in sorted(self.models.items()):
            h = self.chosen.get((tolerance, predictor), float("nan"))
            tolerances.setdefault(tolerance, {})[predictor] = model.to_dict() | {
                "chosen_h": None if not np.isfinite(h) else float(h)}
        return {"format": FORMAT, "trained_on": list(self.trained_on), "tolerances": tolerances, "note": self.note}

    @classmethod
    def from_dict(cls, stored: dict, where: str) -> HazardSet:
        if not isinstance(stored, dict) or stored.get("format") != FORMAT:
            raise ArgumentError(f"{where}: not a hazard model file of format {FORMAT} (make population writes one)")
        models, chosen = {}, {}
        for tolerance, predictors in stored.get("tolerances", {}).items():
            for predictor, entry in predictors.items():
                models[tolerance, predictor] = HazardModel.from_dict(entry, f"{where}, {tolerance}.{predictor}")
                h = entry.get("chosen_h")
                chosen[tolerance, predictor] = float("nan") if h is None else float(h)
        return cls(tuple(stored.get("trained_on", ())), models, chosen, str(stored.get("note", "")))


def write_hazard(path: str | Path, hazard: HazardSet) -> None:
    """The file of ``hazard`` (JSON), written to a temporary name and renamed: never half a file."""
    write_text_atomically(path, json.dumps(hazard.to_dict(), indent=1, sort_keys=True) + "\n")


def hazard_models(path: str | Path) -> HazardSet | None:
    """:func:`read_hazard` of ``predict.hazard.model``, or None (warned: no hazard rows) where there is no file."""
    if not Path(path).exists():
        warnings.warn(f"predict.hazard.model: no file {path}: the hazard predictors are not run (make population "
                      f"trains them on the population's worlds)", stacklevel=2)
        return None
    return read_hazard(path)


def read_hazard(path: str | Path) -> HazardSet:
    """The hazard models of a file :func:`write_hazard` wrote; ArgumentError naming the file if it is missing,
    not JSON or not such a file."""
    try:
        stored = json.loads(Path(path).read_text())
    except OSError as error:
        raise ArgumentError(f"predict.hazard.model: cannot read {path}: {error.strerror} (make population trains "
                            f"the hazard models)") from None
    except json.JSONDecodeError as error:
        raise ArgumentError(f"predict.hazard.model: {path} is not JSON ({error})") from None
    return HazardSet.from_dict(stored, str(path))


def hazard_rows(artifacts: pd.DataFrame, hazard: HazardSet, protocol: ProtocolParams,
                levels: np.ndarray) -> pd.DataFrame:
    """theta_p of both hazard predictors on every arc of ``protocol.pnp_method`` in ``artifacts`` (stage 02's
    table), per tolerance and h in ``levels`` (T,): rows of stage 04's sweep (:data:`~poseintegrity.prediction.
    sweeps.COLUMNS`). A tolerance the file has no model for gets no rows, nor a dataset it was trained on."""
    artifacts = artifacts[~artifacts["dataset"].isin(hazard.trained_on)]
    tables = []
    for tolerance, name in zip(protocol.tolerances, protocol.tolerance_names):
        models = {predictor: hazard.models.get((name, predictor)) for predictor in HAZARD_PREDICTORS}
        if None not in models.values():
            tables.append(arc_rows(stop_evidence(artifacts, protocol.pnp_method, tolerance), models, protocol, name,
                                   levels))
    return pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()


def arc_rows(evidence: pd.DataFrame, models: dict[str, HazardModel], protocol: ProtocolParams, tolerance_name: str,
             levels: np.ndarray) -> pd.DataFrame:
    """The rows of :func:`hazard_rows` for one tolerance, from its stop evidence (:func:`~.stop_evidence.
    stop_evidence`) and its model per predictor."""
    n_sampled_stops, tables = protocol.stops_sampled("arc"), []
    evidence = evidence.assign(hazard_next=models[NEXT_STEP].predict(evidence))
    for dataset, arc in evidence.groupby("dataset", sort=True):
        theta = arc["theta_deg"].to_numpy()
        step = stop_on_next_hazard(theta, arc["hazard_next"].to_numpy(), n_sampled_stops, levels)
        sampled = len(theta) >= max(n_sampled_stops, 2)
        hazards = (models[LONG_RANGE].predict(long_range_features(arc.iloc[n_sampled_stops - 1], theta[1:]))
                   if sampled else None)
        ahead = stop_on_failure_probability(theta, hazards, n_sampled_stops, levels)
        for predictor, found in ((NEXT_STEP, step), (LONG_RANGE, ahead)):
            tables.append(pd.DataFrame({
                "predictor": predictor, "model": MODEL, "method": protocol.pnp_method, "trajectory": "arc",
                "dataset": dataset, "operating_point": levels, "theta_p": found.theta_p, "status": found.status,
                "fit_status": "ok", "reason": "", "tolerance": tolerance_name}))
    return pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()
