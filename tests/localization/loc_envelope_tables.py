"""Stage 02's rows of one arc for the envelope tests: the failed-frame rule they read theta_a under, and a table
whose looser tolerance is judged by board poses refused by the trust rule's limits alone."""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.params.protocol import EnvelopeParams

RULES = EnvelopeParams(failed_frames="fail_fraction", max_failed_fraction=0.5, cap_factor=10.0)


def judged_table(scales):
    """One arc of 4 stops, 2 frames each, E_t 0.5, 1.0, 3.0, 5.0 mm and E_r 0.5 deg; from stop 2 on the board pose
    is refused by the trust rule's limits alone, at truth scales ``scales`` (t, r): no E_t_mm there, only the
    errors against that pose (E_*_loose)."""
    rows = []
    for s, error in enumerate([0.5, 1.0, 3.0, 5.0]):
        for image in range(2):
            refused = s >= 2
            rows.append(dict(world="main", dataset="d", trajectory="arc", stop=s, image=image, theta_deg=2.25 * s,
                             x_mm=0.0, method="usac_magsac", status="ok", E_t_mm=np.nan if refused else error,
                             E_r_deg=np.nan if refused else 0.5, E_t_loose_mm=error, E_r_loose_deg=0.5,
                             truth_scale_t=scales[0] if refused else 0.5, truth_scale_r=scales[1] if refused else 0.5,
                             E_t_exact_mm=error, E_r_exact_deg=0.5, n_inliers=100 - 20 * s,
                             board_status="bad_ground_truth" if refused else "ok", board_n_dropped=0,
                             board_sigma_t_mm=0.15 * (scales[0] if refused else 0.5)))
    return pd.DataFrame(rows)
