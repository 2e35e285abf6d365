"""Where the hazard stops the robot, for every operating point h at once (issue 50).

    hazard_next_step   from the last sampled stop on, the robot stops where it stands at stop i once the hazard of
                       the next stop (evidence of stop i, :func:`~.risk_sets.next_step_rows`' model) reaches h:
                       theta_p = theta_i (III-E's supervision, with the hazard in place of theta_p < theta_i +
                       theta_b); never reached: the last stop ("end_of_path")
    hazard_long_range  after the sampled stops only, the hazards of every stop after the first (the evidence of the
                       last sampled stop and how far ahead, :func:`~.risk_sets.long_range_rows`' model) are
                       integrated into the probability of having failed by stop j, F_j = 1 - prod_{1 <= i <= j}
                       (1 - h_i); theta_p is the last stop before F first reaches h (as the paper's long range
                       predictor, it may lie among the sampled stops: theta_p from theta_1, III-E), or the last stop
                       ("censored") when F stays below h

The operating point is h in (0, 1): lower is more conservative (sweeps.CONSERVATIVE_HIGH). An arc with fewer stops
than are sampled gets NaN rows ("too_few_stops").
"""

from __future__ import annotations

import numpy as np

from poseintegrity.prediction.predictors import Boundaries, flagged


def first_reaching(risk: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """For each level h (T,), the first index where ``risk`` (J,) reaches it (running maximum), J if never."""
    running = np.maximum.accumulate(np.asarray(risk, float)) if len(risk) else np.empty(0)
    return np.searchsorted(running, np.asarray(levels, float), side="left")


def stop_on_next_hazard(theta: np.ndarray, hazard_next: np.ndarray, n_sampled_stops: int,
                        levels: np.ndarray) -> Boundaries:
    """hazard_next_step on one arc. theta : (m,) stop positions (deg); hazard_next : (m,) the hazard of stop i + 1
    seen from stop i (NaN at the last stop); n_sampled_stops : stops sampled first; levels : (T,) h -> theta_p,
    status (T,)."""
    if len(theta) < max(n_sampled_stops, 2):
        return flagged(levels, "too_few_stops")
    risk = np.asarray(hazard_next, float)[n_sampled_stops - 1:-1]
    first = first_reaching(risk, levels)
    reached = first < len(risk)
    theta_p = np.where(reached, theta[np.minimum(first + n_sampled_stops - 1, len(theta) - 1)], theta[-1])
    return Boundaries(theta_p, np.where(reached, "stopped", "end_of_path"))


def stop_on_failure_probability(theta: np.ndarray, hazard_ahead: np.ndarray, n_sampled_stops: int,
                                levels: np.ndarray) -> Boundaries:
    """hazard_long_range on one arc. theta : (m,) stop positions (deg); hazard_ahead : (m - 1,) the hazards of stops
    1 .. m - 1 seen from the ``n_sampled_stops`` sampled stops; levels : (T,) h -> theta_p, status (T,) ("root" /
    "censored")."""
    if len(theta) < max(n_sampled_stops, 2):
        return flagged(levels, "too_few_stops")
    failed_by = 1.0 - np.cumprod(1.0 - np.asarray(hazard_ahead, float))
    first = first_reaching(failed_by, levels)  # stop first + 1 is the first whose F reaches h: stop at stop first
    reached = first < len(failed_by)
    theta_p = np.where(reached, theta[np.minimum(first, len(theta) - 1)], theta[-1])
    return Boundaries(theta_p, np.where(reached, "root", "censored"))
