"""A clear word when a dataset's board cannot judge the tolerance (issue 39): stage 02 names each dataset whose board
pose is trusted in fewer than half its frames, says why, what tolerance the board could judge, and what would fix it.

The trust rule (:mod:`~poseintegrity.localization.ground_truth`) refuses a board pose whose predicted RMS error at the
board origin exceeds ``extract.ground_truth.max_sigma_t_mm``: that limit keeps the ground truth's own error as E_t sees
it within R11's bar, a quarter of the tightest tolerance (the 99th percentile of the error is 2-4 x the predicted
sigma_t; docs/references.md, "Ground-truth boards"). The same ratio maps a board's predicted sigma_t to the tightest
tolerance it can judge: ``sigma_t / max_sigma_t_mm`` times the tightest E_t tolerance of ``protocol.tolerances``.
A user whose board is too small (a 3 x 2 ArUco grid at 260 mm is predicted to 0.2-0.4 mm) learns that tolerance: a
looser tolerance of that size beside the tightest is judged by these poses as they are
(:func:`~poseintegrity.localization.envelope.judged_errors`), and loosening ``max_sigma_t_mm`` judges only tolerances
that large.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from poseintegrity.params.extract import GroundTruthParams

WARN_BELOW = 0.5  # a dataset whose board is trusted in fewer than this share of its frames is warned about
FRAME_KEYS = ["dataset", "stop", "image"]


def board_warnings(table: pd.DataFrame, params: GroundTruthParams,
                   tolerances: list[tuple[float, float]]) -> list[dict[str, Any]]:
    """One warning per dataset with board ground truth whose board is trusted in fewer than WARN_BELOW of its frames
    (pose ground truth, ``no_board``, is never warned about). ``table``: artifact rows (one row per frame is used);
    ``params``: ``extract.ground_truth``; ``tolerances``: ``protocol.tolerances`` (E_t mm, E_r deg).

    Each warning: ``dataset``, ``world``, ``trusted_share``, ``sigma_t_mm`` (the median predicted RMS error at the
    board origin over the frames it does not judge whose pose was fitted; NaN when none), ``max_sigma_t_mm``,
    ``tightest_tolerance_mm`` (the tightest E_t tolerance at which the board would judge half of those, NaN without
    a fit) and ``message``, the paragraph stage 02 prints."""
    frames = table.drop_duplicates(FRAME_KEYS)
    frames = frames[frames["board_status"] != "no_board"]
    tightest, tightest_deg = min(float(t) for t, _ in tolerances), min(float(r) for _, r in tolerances)
    warnings = []
    for (world, dataset), rows in frames.groupby(["world", "dataset"], sort=False):
        trusted = float((rows["board_status"] == "ok").mean())
        if trusted >= WARN_BELOW:
            continue
        fitted = rows[(rows["board_status"] != "ok") & np.isfinite(rows["board_sigma_t_mm"].astype(float))]
        sigma_t = float(fitted["board_sigma_t_mm"].median()) if len(fitted) else math.nan
        sigma_r = float(fitted["board_sigma_r_deg"].median()) if len(fitted) else math.nan
        judges = sigma_t / params.max_sigma_t_mm * tightest
        warnings.append(dict(dataset=str(dataset), world=str(world), trusted_share=trusted, sigma_t_mm=sigma_t,
                             max_sigma_t_mm=params.max_sigma_t_mm, tightest_tolerance_mm=judges,
                             message=_message(str(dataset), str(world), rows, trusted, sigma_t, sigma_r, judges,
                                              tightest, tightest_deg, params)))
    return warnings


def _message(dataset: str, world: str, rows: pd.DataFrame, trusted: float, sigma_t: float, sigma_r: float,
             judges: float, tightest: float, tightest_deg: float, params: GroundTruthParams) -> str:
    """What is wrong with the dataset's board (the commonest reason its frames are not judged), the tightest
    tolerance it can judge and what would fix it."""
    untrusted = rows[rows["board_status"] != "ok"]
    not_found = untrusted["board_status"].isin(["board_not_detected", "board_pnp_failed"]).sum()
    too_few = untrusted["board_reason"].str.contains("fewer than", regex=False).sum()
    head = (f"Dataset {dataset} ({world} world): its ground-truth board judges {round(trusted * len(rows))} of its "
            f"{len(rows)} frames ({trusted:.0%}); a frame it does not judge has no E_t / E_r.")
    limit = (f"extract.ground_truth.max_sigma_t_mm = {params.max_sigma_t_mm:g} mm (and max_sigma_r_deg = "
             f"{params.max_sigma_r_deg:g} deg), the limit that keeps the ground truth's own error within a quarter "
             f"of the tightest tolerance, {tightest:g} mm / {tightest_deg:g} deg (R11)")
    if not_found >= max(too_few, len(untrusted) - not_found - too_few):
        return (f"{head} The board was not found in {not_found} of them (no marker or corner read, or no pose): "
                f"keep it whole in view, uncovered and in focus at every stop, with markers of at least 3 px per bit "
                f"in the image.")
    if too_few >= len(untrusted) - not_found - too_few:
        return (f"{head} In {too_few} of them fewer than extract.ground_truth.min_markers ({params.min_markers}) "
                f"markers or min_corners ({params.min_corners}) ChArUco corners were found and consistent: the board "
                f"is partly out of view, covered by the target, or too small to read. Keep it whole in view and "
                f"uncovered at every stop, with larger markers.")
    rotation = f" and max_sigma_r_deg to {sigma_r:.2f}" if sigma_r > params.max_sigma_r_deg else ""
    degrees = sigma_r / params.max_sigma_r_deg * tightest_deg
    return (f"{head} Its poses there are predicted to {sigma_t:.2f} mm / {sigma_r:.2f} deg at the board origin "
            f"(median), above {limit}. The tightest tolerance this board can judge is about {judges:.1f} mm / "
            f"{max(degrees, tightest_deg):.1f} deg. To judge "
            f"{tightest:g} mm: a larger board, nearer the camera, with more markers or corners (a ChArUco board: its "
            f"corners are located more precisely), turned away from facing the camera by 20-40 deg. A looser "
            f"tolerance of protocol.tolerances, {judges:.1f} mm / {max(degrees, tightest_deg):.1f} deg or more, is "
            f"judged by these poses as they are (each tolerance by the poses within the limits times how much looser "
            f"it is than the tightest); to judge no tighter one, set extract.ground_truth.max_sigma_t_mm to "
            f"{sigma_t:.2f}{rotation} and judge tolerances of {judges:.1f} mm or more (protocol.tolerances).")
