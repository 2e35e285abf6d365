"""Actual localization envelope theta_a (Windsor et al. IV-E).

IV-E: theta_a is "the viewing angle change at which the mean localization error exceeds a specified error
threshold, calculated using linear interpolation between discrete sampled points" (for straight-line datasets the
camera translation x_i, V-A). The error is measured against the ground truth, the ArUco board (IV-C): a frame
whose board was not detected has no error to average and is left out of the stop's mean.

The paper leaves open what a frame *without a pose* (PnP-RANSAC returned none) adds to a stop's mean. That is a
named choice, ``protocol.envelope.failed_frames``; stage 02 computes theta_a under every rule (column ``rule``) and
stage 04 reports Tables I-III under each, so that the choice is seen:

- ``fail_fraction`` (the headline): the mean error is taken over the frames with a pose, and the share of frames
  without one is a criterion of its own, bounded by ``max_failed_fraction``. Both are interpolated like the errors.
  A robot that cannot localize in most frames at a stop has lost the target even if the few poses it gets are good;
  one unlucky frame among ten does not end the envelope.
- ``capped``: a frame without a pose counts as an error of ``cap_factor`` times the tolerance (per bound), so a stop
  fails once about 1 / cap_factor of its frames have no pose; interpolated like any error.
- ``infinite``: a frame without a pose is an infinite error, so one such frame fails its stop and theta_a is the
  previous stop, never a point between stops (the rule of our first reproduction; it snaps theta_a to the stops).

Rules common to all: a tolerance is a pair (E_t mm, E_r deg) and a stop fails when any criterion exceeds its bound;
theta_a is the earliest crossing, each criterion linearly interpolated between the last stop where it was measured
and passed and the first stop where it fails (a criterion that is infinite at the failing stop crosses at that last
passing stop); a dataset whose first stop (the model view, IV-D; x = 0 on lines) already fails has theta_a = that
stop; one that never fails is censored (``censored`` True) at its last stop. When none fails but the last stops are
unmeasured, no end was seen: theta_a is NaN (``not_measured``, below). Censoring it at the last measured stop would
read a ground truth that stopped being trusted as the end of the trajectory, and every prediction beyond it as an
incursion.

A criterion is *unmeasured* at a stop when it is NaN there: every frame of the stop lacks the error (no trusted
board pose in its posed frames). An unmeasured stop is no sampled point of that criterion (IV-E interpolates "between
discrete sampled points"): it is skipped, never read as within tolerance, and the row is flagged (``status``
``unmeasured_stops``, ``reason`` naming the stops) when such a stop lies before the first failing stop. Placing theta_a
at the unmeasured stop (our first reading) made the envelope end where nothing was measured, later than the
measured stops say: an optimistic envelope. A criterion not measured before the stop where it fails, or at no stop at
all, leaves no envelope to read: theta_a is then NaN (``censored`` False, ``status`` ``not_measured``), warned about
naming the dataset, unless the first stop already fails; the prediction stage leaves such a dataset out of the
scoring, naming it (prediction.sweeps.attach_envelopes), and any other NaN theta_a is refused
(table_checks.check_envelopes).

Each tolerance is judged by the board poses fine enough for it (:func:`judged_errors`, ours, issue 39): the trust
rule's limits keep the ground truth's error within a quarter of the tightest tolerance (R11), and a tolerance k_t
times looser in E_t and k_r times in E_r also takes the frames whose pose was refused by those limits alone, up to
(k_t, k_r) times them (:func:`~poseintegrity.localization.ground_truth.truth_scale`). The tightest tolerance's errors
are ``E_t_mm`` and ``E_r_deg`` themselves; a table without the ``LOOSE_ERRORS`` columns (written before) judges every
tolerance by them.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np
import pandas as pd

from poseintegrity.errors import ArgumentError, check_array, check_increasing, check_same_length
from poseintegrity.params.protocol import FAILED_FRAME_RULES, EnvelopeParams, tolerance_name
from poseintegrity.table_checks import NOT_MEASURED, check_artifacts

ENVELOPE_INPUT = ("world", "dataset", "trajectory", "stop", "image", "theta_deg", "x_mm", "method", "status",
                  "E_t_mm", "E_r_deg")  # what envelopes reads of an artifacts table
COLUMNS = ["world", "dataset", "trajectory", "tolerance", "method", "rule", "theta_a", "censored", "status", "reason"]


class Envelope(NamedTuple):
    """theta_a (deg or mm; NaN: none can be read), whether it is censored, and the positions of the stops before
    the first failing one (every stop when none fails) at which a criterion was unmeasured (NaN) and skipped, and
    the index of the criterion that ends it (-1 when none does: censored, or nothing measured)."""

    theta_a: float
    censored: bool
    unmeasured: tuple[float, ...]
    criterion: int = -1


def actual_envelope(theta: np.ndarray, criteria: np.ndarray, bounds: np.ndarray) -> Envelope:
    """theta_a, whether it is censored, and the unmeasured stops skipped (IV-E; module docstring).

    theta : (m,) increasing stop positions (deg or mm), the first one the trajectory start
    criteria : (m, b) per stop, each criterion (mean E_t, mean E_r, share of frames without a pose, ...); inf fails
               the stop and crosses at the last stop before it where the criterion was measured; NaN (nothing to
               average: unmeasured) never fails a stop and is no sampled point of its criterion
    bounds : (b,) the bound of each criterion
    theta_a is the earliest of the criteria's crossings, each interpolated between the criterion's last measured
    stop before its first failing stop and that stop; censored at the last stop when none fails. (NaN, False) when
    none fails but the last stops are unmeasured, or when a criterion is measured at no stop before the one where it
    fails (or at no stop) and the first stop does not fail: no end was seen, no envelope can be read. Refused
    (:class:`~poseintegrity.errors.ArgumentError` naming the argument): theta empty, not finite or not increasing;
    criteria not (m, b) of theta's length; bounds not b finite numbers.
    """
    theta = check_increasing("theta", theta)
    values = check_array("criteria", criteria, shape=(None, None), finite=False)
    bounds = check_array("bounds", bounds, shape=(None,))
    if not len(theta):
        raise ArgumentError("theta: needs at least one stop, got none")
    check_same_length(theta=theta, criteria=values)
    if values.shape[1] != len(bounds):
        raise ArgumentError(f"criteria, bounds: {values.shape[1]} criteria per stop but {len(bounds)} bounds")
    with np.errstate(invalid="ignore"):
        exceeded = values > bounds  # (m, b); NaN never exceeds
    measured = ~np.isnan(values)
    failing = exceeded.any(axis=1)
    first_failing_stop = int(np.argmax(failing)) if failing.any() else len(theta)  # m: none fails
    unmeasured = tuple(float(t) for t in theta[:first_failing_stop][~measured[:first_failing_stop].all(axis=1)])
    if first_failing_stop == 0:
        return Envelope(float(theta[0]), False, (), int(np.argmax(exceeded[0])))
    ends = []  # (position, censored, criterion) per criterion: its crossing, or how far it was measured to pass
    for c, bound in enumerate(bounds):
        fails, seen = np.flatnonzero(exceeded[:, c]), np.flatnonzero(measured[:, c])
        passed = seen[seen < fails[0]] if len(fails) else seen
        if not len(passed):
            return Envelope(float("nan"), False, unmeasured)
        j = int(passed[-1])  # the criterion's last measured stop before it fails
        if not len(fails):
            # A criterion that never fails ends the envelope (censored) only when none fails: when another crosses
            # between the first failing stop and the stop before it, what this one is past that stop is not read
            # (no pose there, say).
            if first_failing_stop == len(theta):
                ends.append((float(theta[j]), True, -1))
            continue
        after = int(fails[0])
        fraction = (bound - values[j, c]) / (values[after, c] - values[j, c]) if np.isfinite(values[after, c]) else 0.0
        ends.append((float(theta[j] + fraction * (theta[after] - theta[j])), False, c))
    # the earliest end; a crossing comes before a censored end at the same position
    theta_a, censored, criterion = min(ends, key=lambda end: end[:2])
    if censored and theta_a < theta[-1]:  # none failed, but the measurements stop short of the trajectory's end
        return Envelope(float("nan"), False, unmeasured)
    return Envelope(theta_a, censored, unmeasured, criterion)


GROUND_TRUTH_ERRORS = ("E_t_mm", "E_r_deg")  # against the ground truth (IV-C): the paper's metric
EXACT_ERRORS = ("E_t_exact_mm", "E_r_exact_deg")  # against the renderer's exact pose: a diagnostic, not the paper's
CRITERIA = ("translation", "rotation", "no_pose")  # what each column of stop_criteria bounds
LOOSE_ERRORS = ("E_t_loose_mm", "E_r_loose_deg")  # against poses refused by the trust rule's limits alone
TRUTH_SCALES = ("truth_scale_t", "truth_scale_r")  # their predicted uncertainty over those limits


def tolerance_loosening(tolerance: tuple[float, float], tolerances: list[tuple[float, float]]) -> np.ndarray:
    """(2,) how many times looser ``tolerance`` is than the tightest of ``tolerances`` in E_t and in E_r (their
    smallest E_t, their smallest E_r), at least 1: its ground truth may be that many times as uncertain (module
    docstring)."""
    tightest = np.min(np.asarray(tolerances, dtype=float).reshape(-1, 2), axis=0)
    return np.maximum(1.0, np.asarray(tolerance, dtype=float) / tightest)


def judges(frames: pd.DataFrame, loosening: np.ndarray) -> np.ndarray:
    """(n,) whether each frame's board pose is fine enough for a tolerance ``loosening`` (2,) times the tightest in
    E_t and E_r (:func:`tolerance_loosening`): trusted (board status "ok"), or refused by the trust rule's limits
    alone with truth scales within ``loosening`` (NaN scales never are; a table without the TRUTH_SCALES columns has
    the trusted ones alone)."""
    trusted = (frames["board_status"] == "ok").to_numpy()
    if not set(TRUTH_SCALES) <= set(frames.columns):
        return trusted
    return trusted | ((frames[TRUTH_SCALES[0]].to_numpy(dtype=float) <= loosening[0])
                      & (frames[TRUTH_SCALES[1]].to_numpy(dtype=float) <= loosening[1]))


def judged_errors(frames: pd.DataFrame, tolerance: tuple[float, float],
                  tolerances: list[tuple[float, float]]) -> pd.DataFrame:
    """``frames`` with E_t_mm and E_r_deg as ``tolerance`` is judged (module docstring): where they are NaN, the
    errors against a pose (refused by the trust rule's limits alone) that :func:`judges` it. Unchanged for the tightest
    tolerance, or without the LOOSE_ERRORS and TRUTH_SCALES columns (a table written before them)."""
    loosening = tolerance_loosening(tolerance, tolerances)
    if np.all(loosening == 1.0) or not {*LOOSE_ERRORS, *TRUTH_SCALES} <= set(frames.columns):
        return frames
    fine = frames["E_t_mm"].isna().to_numpy() & judges(frames, loosening)
    return frames.assign(E_t_mm=np.where(fine, frames["E_t_loose_mm"], frames["E_t_mm"]),
                         E_r_deg=np.where(fine, frames["E_r_loose_deg"], frames["E_r_deg"]))


def stop_criteria(frames: pd.DataFrame, tolerance: tuple[float, float], rule: str,
                  envelope: EnvelopeParams, errors: tuple[str, str] = GROUND_TRUTH_ERRORS) -> tuple[np.ndarray, np.ndarray]:
    """Per stop of one dataset and PnP method: the criteria of ``rule`` and their bounds.

    frames : usable artifact rows (``status`` "ok" = a pose; the ``errors`` columns, E_t and E_r against the
             ground truth by default, NaN where the board gave no trusted pose or there is no pose), with ``stop``
    Returns criteria (m, b) in stop order and bounds (b,): mean E_t, mean E_r, and for ``fail_fraction`` the share
    of frames without a pose.
    """
    if rule not in FAILED_FRAME_RULES:
        raise ArgumentError(f"rule: unknown failed-frame rule {rule!r}; expected one of {FAILED_FRAME_RULES}")
    tol = np.asarray(tolerance, dtype=float)
    posed = (frames["status"] == "ok").to_numpy()
    errors = frames[list(errors)].to_numpy(dtype=float, copy=True)
    if rule == "infinite":
        errors[~posed] = np.inf
    elif rule == "capped":
        errors[~posed] = envelope.cap_factor * tol
    else:
        errors[~posed] = np.nan
    per_frame = pd.DataFrame(errors, columns=["E_t", "E_r"]).assign(stop=frames["stop"].to_numpy(),
                                                                     failed=~posed)
    per_stop = per_frame.groupby("stop", sort=True).agg(E_t=("E_t", "mean"), E_r=("E_r", "mean"),
                                                         failed=("failed", "mean"))
    if rule == "fail_fraction":
        return per_stop[["E_t", "E_r", "failed"]].to_numpy(), np.append(tol, envelope.max_failed_fraction)
    return per_stop[["E_t", "E_r"]].to_numpy(), tol


def envelopes(table: pd.DataFrame, tolerances: list[tuple[float, float]], envelope: EnvelopeParams,
              errors: tuple[str, str] = GROUND_TRUTH_ERRORS) -> pd.DataFrame:
    """theta_a per dataset, tolerance, PnP method and failed-frame rule from an artifacts table (columns
    :data:`COLUMNS`; theta_a in deg for arcs (``theta_deg``), mm for lines (``x_mm``)), the errors of the ``errors``
    columns (:data:`GROUND_TRUTH_ERRORS`, the paper's; :data:`EXACT_ERRORS`, against the exact pose: a diagnostic).

    table : usable artifact rows (:func:`~poseintegrity.localization.frame_rows.usable`), checked
        (:func:`~poseintegrity.table_checks.check_artifacts`: columns, one row per frame and method, ...)
    A theta_a that cannot be read (a criterion never measured, :func:`actual_envelope`) is NaN and warned about.
    """
    check_artifacts(table, "the artifacts table given to envelopes", columns=tuple(dict.fromkeys((*ENVELOPE_INPUT, *errors))))
    rows = []
    for (world, dataset, trajectory, method), frames in table.groupby(["world", "dataset", "trajectory", "method"],
                                                                      sort=True):
        position = "x_mm" if trajectory == "line" else "theta_deg"
        theta = frames.groupby("stop", sort=True)[position].mean().to_numpy()
        for tolerance in tolerances:
            judged = judged_errors(frames, tolerance, tolerances) if errors == GROUND_TRUTH_ERRORS else frames
            for rule in FAILED_FRAME_RULES:
                criteria, bounds = stop_criteria(judged, tolerance, rule, envelope, errors)
                theta_a, censored, unmeasured, _ = actual_envelope(theta, criteria, bounds)
                rows.append(dict(world=world, dataset=dataset, trajectory=trajectory, tolerance=tolerance_name(tolerance),
                                 method=method, rule=rule, theta_a=theta_a, censored=censored,
                                 **flag(theta_a, unmeasured, "mm" if trajectory == "line" else "deg")))
    result = pd.DataFrame(rows, columns=COLUMNS)
    unknown = result[result["theta_a"].isna()]
    if len(unknown):
        names = sorted(set(unknown["dataset"]))
        warnings.warn(f"envelopes: {len(unknown)} theta_a of dataset(s) {names[:5]}{' ...' if len(names) > 5 else ''} "
                      f"are NaN: not measured up to their end (board not detected or not trusted)", stacklevel=2)
    return result


def flag(theta_a: float, unmeasured: tuple[float, ...], unit: str) -> dict[str, str]:
    """``status`` and ``reason`` of an envelope row: ``ok``; ``unmeasured_stops`` when stops without a measured
    error were skipped (named, in ``unit``); ``not_measured`` when theta_a could not be read (NaN)."""
    stops = ", ".join(f"{t:g}" for t in unmeasured)
    if np.isnan(theta_a):
        return dict(status=NOT_MEASURED, reason="theta_a cannot be read: no pose error measured before the first "
                                                  "failing stop, or none fails and the last stops are unmeasured "
                                                  "(board not detected or not trusted)"
                                                  + (f"; unmeasured stops at {stops} {unit}" if stops else ""))
    if unmeasured:
        return dict(status="unmeasured_stops", reason=f"no pose error measured at the stop(s) at {stops} {unit} (no "
                                                      f"trusted board pose in their posed frames): skipped, theta_a read "
                                                      f"from the measured stops")
    return dict(status="ok", reason="")


def headline(envelope_table: pd.DataFrame, envelope: EnvelopeParams) -> pd.DataFrame:
    """The rows of ``protocol.envelope.failed_frames``, the rule of the paper's tables (without the rule column)."""
    return envelope_table[envelope_table["rule"] == envelope.failed_frames].drop(columns="rule")
