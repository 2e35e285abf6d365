"""Why each envelope ends (issue 30): per dataset and tolerance, the limit that ends theta_a and what caused it.

theta_a (IV-E, :mod:`.envelope`) ends where a stop's criterion first exceeds its bound. This table says, for the
headline PnP method and failed-frame rule:

- ``limit``: the criterion that crosses first: ``translation`` (mean E_t), ``rotation`` (mean E_r), ``no_pose`` (the
  share of frames without a pose), ``censored`` (none: the envelope lasts to the trajectory's end), ``unmeasured``
  (theta_a could not be read);
- ``cause``: ``no_pose`` when localization gave no pose; for an error limit, whether the estimate was off or its
  ground truth was: at the first stop where that limit's criterion exceeds its bound (the failing stop) the
  criterion is taken against the renderer's exact pose (``E_*_exact``) *on the same frames* (those whose board pose
  was trusted). If it exceeds the bound too, the envelope ended on the estimate (``estimate``). If it stays within, the ground truth moved the criterion across the
  bound by ``truth_shift`` (criterion against the ground truth minus against the exact pose): by more than the
  ground truth's own accuracy bar (R11, :data:`~poseintegrity.localization.truth_accuracy.R11_BAR`, scaled for a
  looser tolerance as its ground truth is, :func:`~.envelope.tolerance_loosening`) that is a fault of
  the ground truth (``ground_truth``); by no more, the ground truth was as good as R11 asks and the estimate's error
  lay within its resolution of the bound (``resolution``): no ground truth of that accuracy can say on which side of
  the bound that stop falls. Recorded data have no exact pose: the board's own consistency at that stop stands in
  (``ground_truth`` when its frames' board poses were not trusted or dropped markers, ``estimate`` otherwise; the
  ``board_*`` columns give the numbers);
- ``theta_a`` beside ``theta_a_exact`` (the same envelope against the exact pose, a diagnostic), and the mean n_i
  at theta_a (linearly interpolated between the stops' means);
- ``unmeasured_stops``: how many stops up to the first failing one had no error to average (no trusted ground truth
  in any posed frame): theta_a was read across them (:func:`~.envelope.actual_envelope` skips them); a looser
  tolerance is judged by the board poses fine enough for it (:func:`~.envelope.judged_errors`), and its
  ``board_untrusted_share`` counts the frames whose pose is not;
- ``E_t_at_end``, ``sigma_t_pred_at_end``: at the first failing stop, the mean measured E_t and the mean predicted
  RMS E_t of its posed frames (issue 38, :mod:`.pose_covariance`): how far the predicted error saw the end coming.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.localization.envelope import (CRITERIA, EXACT_ERRORS, GROUND_TRUTH_ERRORS, actual_envelope,
                                                 judged_errors, judges, stop_criteria, tolerance_loosening)
from poseintegrity.localization.truth_accuracy import R11_BAR
from poseintegrity.params.protocol import EnvelopeParams, tolerance_name

CAUSES = ("estimate", "ground_truth", "resolution", "no_pose", "censored", "unmeasured")  # every value of ``cause``
COLUMNS = ["world", "dataset", "trajectory", "tolerance", "theta_a", "censored", "theta_a_exact", "limit", "cause",
           "truth_shift", "n_inliers_at_theta_a", "unmeasured_stops", "board_untrusted_share", "board_dropped_share",
           "board_sigma_t_mm", "E_t_at_end", "sigma_t_pred_at_end"]


def envelope_causes(table: pd.DataFrame, tolerances: list[tuple[float, float]], envelope: EnvelopeParams,
                    method: str) -> pd.DataFrame:
    """One row per dataset and tolerance (:data:`COLUMNS`, module docstring) of ``method``'s usable artifact rows
    ``table`` under the headline rule ``envelope.failed_frames``. The ``board_*`` columns describe the frames of the
    first failing stop (the last stop when the envelope is censored)."""
    rows = []
    for (world, dataset, trajectory), everything in table[table["method"] == method].groupby(
            ["world", "dataset", "trajectory"], sort=True):
        position = "x_mm" if trajectory == "line" else "theta_deg"
        per_stop = everything.groupby("stop", sort=True)
        stops, theta = per_stop[position].mean().index.to_numpy(), per_stop[position].mean().to_numpy()
        n_inliers = per_stop["n_inliers"].mean().to_numpy()
        has_exact = bool(everything[list(EXACT_ERRORS)].notna().any().any())
        for tolerance in tolerances:
            frames = judged_errors(everything, tolerance, tolerances)
            criteria, bounds = stop_criteria(frames, tolerance, envelope.failed_frames, envelope)
            theta_a, censored, _, criterion = actual_envelope(theta, criteria, bounds)
            exact = (stop_criteria(frames, tolerance, envelope.failed_frames, envelope, EXACT_ERRORS)
                     if has_exact else None)
            same_frames = (stop_criteria(_exact_where_truth(frames), tolerance, envelope.failed_frames, envelope,
                                         EXACT_ERRORS)[0] if has_exact else None)
            with np.errstate(invalid="ignore"):  # the failing stop: where the criterion ending theta_a first fails
                over = (criteria[:, criterion] > bounds[criterion] if criterion >= 0
                        else np.any(criteria > bounds, axis=1))
            failing = int(np.flatnonzero(over)[0]) if over.any() else len(stops) - 1
            at_stop = frames[frames["stop"] == stops[failing]]
            row = dict(world=world, dataset=dataset, trajectory=trajectory, tolerance=tolerance_name(tolerance),
                       theta_a=theta_a, censored=censored,
                       theta_a_exact=actual_envelope(theta, *exact).theta_a if exact is not None else float("nan"),
                       n_inliers_at_theta_a=float(np.interp(theta_a, theta, n_inliers)) if np.isfinite(theta_a)
                       else float("nan"),
                       unmeasured_stops=int(np.isnan(criteria[: failing + 1, :2]).all(axis=1).sum()),
                       board_untrusted_share=float((~judges(at_stop, tolerance_loosening(tolerance,
                                                                                          tolerances))).mean()),
                       board_dropped_share=float((at_stop["board_n_dropped"] > 0).mean()),
                       board_sigma_t_mm=float(at_stop["board_sigma_t_mm"].median()),
                       E_t_at_end=float(at_stop["E_t_mm"].mean()),
                       sigma_t_pred_at_end=float(at_stop["sigma_t_pred_mm"].mean()) if "sigma_t_pred_mm" in at_stop
                       else float("nan"))  # a table without the predicted error (written before issue 38)
            bar = tolerance_loosening(tolerance, tolerances) * np.asarray(R11_BAR)  # R11's bar for this tolerance
            row["limit"], row["cause"], row["truth_shift"] = _limit_and_cause(theta_a, censored, criterion, failing,
                                                                              criteria, bounds, same_frames, row, bar)
            rows.append(row)
    return pd.DataFrame(rows, columns=COLUMNS)


def _exact_where_truth(frames: pd.DataFrame) -> pd.DataFrame:
    """``frames`` with the exact-pose errors blanked where the ground truth's are missing (board not trusted): the
    criterion against the exact pose taken over the frames that the ground truth's criterion was taken over."""
    blank = frames[list(GROUND_TRUTH_ERRORS)].isna().to_numpy()
    exact = frames[list(EXACT_ERRORS)].to_numpy(dtype=float, copy=True)
    exact[blank] = np.nan
    return frames.assign(**dict(zip(EXACT_ERRORS, exact.T)))


def _limit_and_cause(theta_a: float, censored: bool, criterion: int, failing: int, criteria: np.ndarray,
                     bounds: np.ndarray, same_frames: np.ndarray | None, row: dict,
                     bar: np.ndarray) -> tuple[str, str, float]:
    """(limit, cause, truth_shift) of one envelope (module docstring); ``failing``: the first failing stop's index;
    ``criteria`` (m, b) against the ground truth, ``same_frames`` (m, b) against the exact pose on the same frames
    (None without exact poses); ``bar`` (2,): R11's bar of the tolerance (mm, deg). truth_shift is NaN where no
    error limit was compared with the exact pose."""
    if not np.isfinite(theta_a):
        return "unmeasured", "unmeasured", float("nan")
    if censored:
        return "censored", "censored", float("nan")
    limit = CRITERIA[criterion]
    if limit == "no_pose":
        return limit, "no_pose", float("nan")
    if same_frames is not None:
        value = same_frames[failing, criterion]
        shift = float(criteria[failing, criterion] - value)
        if not (np.isfinite(value) and value <= bounds[criterion]):
            return limit, "estimate", shift
        return limit, "ground_truth" if shift > bar[criterion] else "resolution", shift
    suspect = row["board_untrusted_share"] > 0 or row["board_dropped_share"] > 0
    return limit, "ground_truth" if suspect else "estimate", float("nan")
