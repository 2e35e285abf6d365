"""Synthetic inputs of the failure hazard's tests (prediction/hazard, population/hazard.py): stage 02's rows of an
arc, rows whose failure follows a known logistic law, and the paper-scale protocol of params.yaml."""

from __future__ import annotations

import numpy as np
import pandas as pd

THETA = np.arange(8) * 2.25  # deg


def arc_frames(world: str, dataset: str, counts: list[float], images: int = 2) -> pd.DataFrame:
    """Stage 02's rows of one arc: ``counts`` mean inliers per stop (0: no pose), errors falling with the count."""
    rows = []
    for stop, count in enumerate(counts):
        for image in range(images):
            posed = count > 0
            rows.append({"world": world, "dataset": dataset, "trajectory": "arc", "method": "usac_magsac",
                         "stop": stop, "image": image, "theta_deg": THETA[stop], "x_mm": 0.0,
                         "status": "ok" if posed else "no_pose", "n_inliers": count + image if posed else np.nan,
                         "n_matches": 2 * count + 10, "inlier_ratio": 0.5, "reproj_error_px": 0.3,
                         "inlier_hull_area_px2": 100.0 * count, "model_coverage": 0.01 * count,
                         "sigma_t_pred_mm": 2.0 / np.sqrt(max(count, 1)), "sigma_r_pred_deg": 0.5})
    return pd.DataFrame(rows)


def synthetic_rows(n_worlds: int, n: int, seed: int) -> pd.DataFrame:
    """Rows whose failure follows a known logistic law of two columns (the third is noise)."""
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(n_worlds * n, 3))
    p = 1 / (1 + np.exp(-(-1.5 + 2.0 * x[:, 0] - 1.0 * x[:, 1])))
    return pd.DataFrame({"a": x[:, 0], "b": x[:, 1], "noise": x[:, 2], "failed": (rng.random(len(p)) < p).astype(int),
                         "world": np.repeat([f"w{i}" for i in range(n_worlds)], n), "p_true": p})


def load_protocol() -> dict:
    import yaml

    from repository import ROOT

    return yaml.safe_load((ROOT / "params.yaml").read_text())["protocol"]
