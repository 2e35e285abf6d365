"""Stage 02's artifact rows of made-up worlds whose answers are known (n_i a given function of theta, E_t = 50 / n_i),
for the realism and summary tests, with the pipeline's own realism settings and protocol."""

from __future__ import annotations

import numpy as np
import pandas as pd

from poseintegrity.config import load_params
from repository import ROOT

PARAMS = load_params(ROOT / "params.yaml")  # the pipeline's own realism settings and protocol
REALISM, PROTOCOL = PARAMS.extract.realism, PARAMS.protocol


def world(counts_by_dataset, trajectory="arc"):
    """Artifact rows with n_i = counts(theta) (theta = 0, 2.25, ... 42.75 deg, IV-D) and E_t = 50 / n_i (errors
    blow up with few inliers); lines use x = 10 mm per stop."""
    rows = []
    for dataset, counts in counts_by_dataset.items():
        for stop in range(20 if trajectory == "arc" else 15):
            theta = 2.25 * stop
            n_i = max(int(counts(theta)), 0)
            for image in range(2):
                rows.append(dict(world="main", dataset=dataset, trajectory=trajectory, stop=stop, image=image,
                                 theta_deg=theta if trajectory == "arc" else 0.0,
                                 x_mm=10.0 * stop if trajectory == "line" else 0.0, method="usac_magsac",
                                 n_inliers=n_i, status="ok" if n_i else "no_consensus",
                                 E_t_mm=50.0 / n_i if n_i else np.nan, E_r_deg=0.0, **BOARD))
    return pd.DataFrame(rows)


# every frame's board trusted, adding 0.1 mm / 0.05 deg to E_t / E_r (R11 passes), the model placed 0.3 mm off
BOARD = dict(board_status="ok", board_n_points=24, board_n_dropped=0, board_rms_px=0.05, board_sigma_t_mm=0.05,
             board_sigma_r_deg=0.02, E_t_truth_mm=0.1, E_r_truth_deg=0.05, E_t_placement_mm=0.3,
             E_r_placement_deg=0.1)


def linear(decay):
    return lambda theta: 100 - decay * theta
