"""The ceiling of any predictor's gain over static and a predictor's share of it (prediction/ceiling.py), on a
table whose answers are known."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from poseintegrity.prediction.ceiling import ceiling, ceiling_share


def test_ceiling_and_share_known_answers():
    table = pd.DataFrame({"dataset": ["a", "b", "c", "c"], "trajectory": "arc", "method": "m",
                          "tolerance": ["t", "t", "t", "t"], "theta_a": [10.0, 20.0, 30.0, 30.0]})
    best = pd.DataFrame({"predictor": ["static"], "trajectory": ["arc"], "method": ["m"], "tolerance": ["t"],
                         "max_mean_spl": [9.5]})
    limits = ceiling(table, best, "m", ["t", "u"])
    assert limits["t"] == {"n_arcs": 3, "mean_theta_a": 20.0, "min_theta_a": 10.0, "static_spl": 9.5, "gain": 1.0}
    assert limits["u"]["n_arcs"] == 0 and np.isnan(limits["u"]["gain"])
    assert ceiling_share(20.0, limits["t"]) == pytest.approx(1.0)  # knew every envelope
    assert ceiling_share(9.5, limits["t"]) == 0.0 and ceiling_share(4.25, limits["t"]) == pytest.approx(-0.5)
    assert np.isnan(ceiling_share(np.nan, limits["t"])) and np.isnan(ceiling_share(15.0, limits["u"]))
