"""The filter runs of section III, each made once over the recordings that need it (:class:`FilterRun`): accuracy
with and without the gyro, the SR-UKF against the plain UKF, the process-noise sweep, the published sigmas against
ours on motion (a) and at the paper's pace. Each experiment draws from its own generator, ``keyed_rng(params.seed, name)``."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from poseintegrity.seeding import keyed_rng
from poseintegrity.params.track import PAPER_SIGMAS, FilterParams, TrackParams
from poseintegrity.tracking.simulation.simulate import Simulation, run_filter
from poseintegrity.tracking.filter.srukf import SquareRootUKF
from poseintegrity.tracking.filter.tracker import MarkerTracker
from poseintegrity.tracking.filter.ukf import UnscentedKalmanFilter
from poseintegrity.tracking.filter.unscented import UnscentedMarkerFilter


def experiment_rng(params: TrackParams, name: str) -> np.random.Generator:
    """The generator of one experiment: keyed_rng(params.seed, name)."""
    return keyed_rng(params.seed, name)


@dataclass(frozen=True)
class FilterRun:
    """One run of the tracker over a recording (:func:`~poseintegrity.tracking.simulation.simulate.run_filter`).

    recording : "accuracy" (the accuracy recording), "hand" (motion (a), 4 markers) or "pace" (motion (c), the
    paper's pace); settings : the filter's
    constants; filter_cls : the filter (SR-UKF of Alg. 5, or the plain UKF it is checked against).  Equal runs
    are equal keys: two experiments that need the same run share one.
    """

    recording: str
    use_gyro: bool
    settings: FilterParams
    filter_cls: type[UnscentedMarkerFilter] = SquareRootUKF


FilterResults = Mapping[FilterRun, tuple[pd.DataFrame, MarkerTracker]]


def accuracy_runs(params: TrackParams) -> dict[str, FilterRun]:
    """The filter runs of the accuracy recording: the UKF without and with the gyro."""
    return {"ukf": FilterRun("accuracy", False, params.filter), "ukf_gyro": FilterRun("accuracy", True, params.filter)}


def agreement_runs(params: TrackParams) -> dict[str, tuple[FilterRun, FilterRun]]:
    """SR-UKF against the plain UKF (gyro fused) on the accuracy recording, at alpha 1 and at params' alpha."""
    runs = {}
    for alpha in (1.0, params.filter.alpha):
        settings = params.filter.model_copy(update={"alpha": alpha})
        runs[f"alpha_{alpha:g}"] = (FilterRun("accuracy", True, settings), FilterRun("accuracy", True, settings, UnscentedKalmanFilter))
    return runs


def sweep_runs(params: TrackParams) -> dict[float, FilterRun]:
    """The noise-vs-lag runs (UKF, no gyro, accuracy recording): sigma_c and sigma_alpha times each of
    evaluation.sigma_scales."""
    fp = params.filter
    return {scale: FilterRun("accuracy", False, fp.model_copy(update={"sigma_c": fp.sigma_c * scale, "sigma_alpha": fp.sigma_alpha * scale}))
            for scale in params.evaluation.sigma_scales}


def sigma_variants(params: TrackParams) -> dict[str, FilterParams]:
    """The filter constants compared on motion (a) (:func:`~.accuracy.published_against_our_sigmas`): the published sigmas,
    ours, the two halves swapped, and the published process sigmas read as per-second intensities."""
    process = ("sigma_c", "sigma_alpha")
    fp = params.filter
    return {
        "published": fp.model_copy(update=PAPER_SIGMAS),
        "ours": fp,
        "published_measurement_our_process": fp.model_copy(update={k: v for k, v in PAPER_SIGMAS.items() if k not in process}),
        "our_measurement_published_process": fp.model_copy(update={k: v for k, v in PAPER_SIGMAS.items() if k in process}),
        "published_per_second": fp.model_copy(update={**PAPER_SIGMAS, **{k: PAPER_SIGMAS[k] / np.sqrt(fp.dt) for k in process}}),
    }


def sigma_runs(params: TrackParams) -> dict[str, FilterRun]:
    """The runs of :func:`sigma_variants` on motion (a), 4 markers, UKF without gyro."""
    return {name: FilterRun("hand", False, settings) for name, settings in sigma_variants(params).items()}


def pace_runs(params: TrackParams) -> dict[str, FilterRun]:
    """The runs of motion (c), the paper's pace (:mod:`~.paper_pace`), UKF without gyro as the paper's accuracy
    figures: the published sigmas (the claim's row) and ours."""
    variants = sigma_variants(params)
    return {name: FilterRun("pace", False, variants[name]) for name in ("published", "ours")}


def study_filter_runs(params: TrackParams) -> list[FilterRun]:
    """Every distinct filter run of the study, the long motion (a) runs first (they set the critical path)."""
    runs = [*sigma_runs(params).values(), *pace_runs(params).values(), *accuracy_runs(params).values(), *sweep_runs(params).values()]
    runs += [run for pair in agreement_runs(params).values() for run in pair]
    return list(dict.fromkeys(runs))


def run_filter_task(sim: Simulation, params: TrackParams, run: FilterRun) -> tuple[pd.DataFrame, MarkerTracker]:
    """:func:`~poseintegrity.tracking.simulation.simulate.run_filter` of one :class:`FilterRun` on its recording ``sim``."""
    return run_filter(sim, params, run.use_gyro, run.settings, run.filter_cls)


def filter_agreement(runs: FilterResults, pair: tuple[FilterRun, FilterRun]) -> float:
    """Largest relative difference of the filtered positions of the SR-UKF and another filter on the same
    recording: max |x_sr - x_other| / max |x_other| over the events where both run.  pair : (SR-UKF run, other)."""
    (a, _), (b, _) = runs[pair[0]], runs[pair[1]]
    xa, xb = a[["x_mm", "y_mm", "z_mm"]].to_numpy(), b[["x_mm", "y_mm", "z_mm"]].to_numpy()
    both = np.isfinite(xa).all(axis=1) & np.isfinite(xb).all(axis=1)
    if not both.any():  # the two never ran at the same event: nothing to compare
        return float("nan")
    return float(np.abs(xa[both] - xb[both]).max() / np.abs(xb[both]).max())
