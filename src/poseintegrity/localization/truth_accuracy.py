"""R11 (issue 30): the ground truth's own accuracy, so that a measurement is finer than what it judges.

E_t and E_r (IV-C) compare an estimate with the board's pose in each frame; the board pose has errors of its own. What
they add to E_t and E_r is the board pose relative to that of model image 0 (where M_t was placed) against the same
relative exact pose (:func:`~poseintegrity.localization.ground_truth.truth_error`: columns ``E_t_truth_mm``,
``E_r_truth_deg``). The bar: its 99th percentile over the frames whose board pose is trusted is at most a quarter of
the tightest tolerance, 0.5 mm and 0.5 deg; a tolerance k_t times looser in E_t and k_r in E_r is judged by the
poses of truth scales within (k_t, k_r) too (:func:`~poseintegrity.localization.envelope.judged_errors`), and over
them its bar is (k_t x 0.5 mm, k_r x 0.5 deg) (``by_tolerance``; ``r11_passed`` asks every tolerance's). Beside
it, the absolute error of model image 0's board pose (the model placement, ``E_*_placement``), and how the board's
own checks went (frames not trusted and why, markers or corners dropped, residuals, predicted uncertainty): on
recorded data, where there is no exact pose, these describe the ground truth alone.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from poseintegrity.localization.envelope import TRUTH_SCALES, judges, tolerance_loosening
from poseintegrity.params.protocol import tolerance_name

R11_BAR = (0.5, 0.5)  # mm, deg: a quarter of the tightest tolerance (2 mm / 3 deg), rounded down in rotation
FRAME_KEYS = ["dataset", "stop", "image"]


def truth_accuracy(table: pd.DataFrame, tolerances: list[tuple[float, float]] = ()) -> dict[str, Any]:
    """R11 and the board's checks over an artifacts table's frames (one row per frame is used: the board does not
    depend on the PnP method). ``tolerances``: the protocol's, whose looser ones are checked too (``by_tolerance``:
    per tolerance name ``k``, its loosening (k_t, k_r) (:func:`~.envelope.tolerance_loosening`), ``judged_share``
    of the frames, ``p99_E_t_truth_mm``, ``p99_E_r_truth_deg``, ``bar`` and ``passed``). Keys: ``n_frames``;
    ``trusted_share`` (board status "ok"); ``status_shares``; ``untrusted_share_by_dataset``; ``dropped_share``
    (frames whose check dropped a marker or corner); ``median_rms_px``, ``median_sigma_t_mm``,
    ``median_sigma_r_deg``, ``median_points``; with exact poses: ``median_E_t_truth_mm``, ``p99_E_t_truth_mm``,
    ``max_E_t_truth_mm`` and the same in deg, ``placement_*`` (median and max over datasets), ``r11_passed``; without
    them (recorded data) those are NaN and ``r11_passed`` None."""
    frames = table.drop_duplicates(FRAME_KEYS)
    trusted = frames[frames["board_status"] == "ok"]
    exact = bool(trusted["E_t_truth_mm"].notna().any())
    per_dataset = frames.groupby("dataset")
    placement = per_dataset[["E_t_placement_mm", "E_r_placement_deg"]].first()

    def quantile(column: str, q: float) -> float:
        values = trusted[column].dropna()
        return float(values.quantile(q)) if len(values) else float("nan")

    result = dict(
        n_frames=int(len(frames)),
        trusted_share=float(len(trusted) / len(frames)) if len(frames) else float("nan"),
        status_shares={str(status): float(share) for status, share in
                       frames["board_status"].value_counts(normalize=True).items()},
        untrusted_share_by_dataset={str(dataset): float(share) for dataset, share in
                                    per_dataset["board_status"].apply(lambda s: (s != "ok").mean()).items()},
        dropped_share=float((frames["board_n_dropped"] > 0).mean()) if len(frames) else float("nan"),
        median_rms_px=float(trusted["board_rms_px"].median()),
        median_sigma_t_mm=float(trusted["board_sigma_t_mm"].median()),
        median_sigma_r_deg=float(trusted["board_sigma_r_deg"].median()),
        median_points=float(trusted["board_n_points"].median()),
        median_E_t_truth_mm=quantile("E_t_truth_mm", 0.5), p99_E_t_truth_mm=quantile("E_t_truth_mm", 0.99),
        max_E_t_truth_mm=quantile("E_t_truth_mm", 1.0),
        median_E_r_truth_deg=quantile("E_r_truth_deg", 0.5), p99_E_r_truth_deg=quantile("E_r_truth_deg", 0.99),
        max_E_r_truth_deg=quantile("E_r_truth_deg", 1.0),
        placement_median_E_t_mm=float(placement["E_t_placement_mm"].median()),
        placement_max_E_t_mm=float(placement["E_t_placement_mm"].max()),
        placement_median_E_r_deg=float(placement["E_r_placement_deg"].median()),
        placement_max_E_r_deg=float(placement["E_r_placement_deg"].max()),
    )
    result["by_tolerance"] = {}
    for tolerance in tolerances:
        loosening = tolerance_loosening(tolerance, tolerances)
        if np.all(loosening == 1.0) or not set(TRUTH_SCALES) <= set(frames.columns):
            continue
        judging = frames[judges(frames, loosening)]
        p99 = [float(judging[c].dropna().quantile(0.99)) if judging[c].notna().any() else float("nan")
               for c in ("E_t_truth_mm", "E_r_truth_deg")]
        bar = (float(loosening[0] * R11_BAR[0]), float(loosening[1] * R11_BAR[1]))
        result["by_tolerance"][tolerance_name(tolerance)] = dict(
            k=loosening.tolist(), judged_share=float(len(judging) / len(frames)) if len(frames) else float("nan"),
            p99_E_t_truth_mm=p99[0], p99_E_r_truth_deg=p99[1], bar=list(bar),
            passed=bool(p99[0] <= bar[0] and p99[1] <= bar[1]) if exact else None)
    result["r11_passed"] = (bool(result["p99_E_t_truth_mm"] <= R11_BAR[0] and result["p99_E_r_truth_deg"] <= R11_BAR[1]
                                 and all(t["passed"] for t in result["by_tolerance"].values()))
                            if exact else None)
    return result
