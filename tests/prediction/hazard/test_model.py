"""The hazard model (prediction/hazard/model.py): scikit-learn's logistic regression calibrated on held-out worlds,
its Brier score and reliability, and the rows it cannot be fitted on."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.linear_model import LogisticRegression

from poseintegrity.prediction.hazard.model import HazardFitError, brier_score, fit_hazard, reliability
from prediction.hazard.hazard_synthetic import synthetic_rows


def test_the_hazard_is_scikit_learn_s_logistic_regression_calibrated_on_held_out_worlds():
    rows = synthetic_rows(6, 400, 1)
    model = fit_hazard(rows, ("a", "b", "noise"), C=1.0, calibration_folds=3)
    X = rows[["a", "b", "noise"]].to_numpy()
    reference = LogisticRegression(C=1.0).fit((X - X.mean(0)) / X.std(0), rows["failed"])
    np.testing.assert_allclose(model.coef, reference.coef_[0], rtol=1e-4)
    # the held-out calibration of a well specified model is near the identity
    assert model.slope_a == pytest.approx(1.0, abs=0.15) and model.offset_c == pytest.approx(0.0, abs=0.15)
    fresh = synthetic_rows(2, 2000, 2)
    p = model.predict(fresh)
    assert np.abs(p - fresh["p_true"]).mean() < 0.03
    assert brier_score(p, fresh["failed"]) < brier_score(np.full(len(p), fresh["failed"].mean()), fresh["failed"])
    table = reliability(p, fresh["failed"], np.linspace(0, 1, 6))
    busy = table[table["n"] > 200]
    np.testing.assert_allclose(busy["failure_rate"], busy["mean_hazard"], atol=0.05)
    assert table["n"].sum() == len(p)


def test_a_missing_column_is_filled_with_its_training_median():
    rows = synthetic_rows(4, 200, 3)
    model = fit_hazard(rows, ("a", "b"), C=1.0, calibration_folds=2)
    without = rows.drop(columns="b")
    filled = rows.assign(b=model.fill[1])
    np.testing.assert_allclose(model.predict(without), model.predict(filled))


def test_rows_a_hazard_cannot_be_fitted_on_are_refused_by_name(monkeypatch):
    from poseintegrity.prediction.hazard import model

    rows = synthetic_rows(3, 100, 4)
    with pytest.raises(HazardFitError, match="no failures"):
        fit_hazard(rows.assign(failed=0), ("a",), 1.0, 2)
    with pytest.raises(HazardFitError, match="at least 2 worlds"):
        fit_hazard(rows.assign(world="w0"), ("a",), 1.0, 2)
    monkeypatch.setattr(model, "MAX_ITERATIONS", 1)
    with pytest.raises(HazardFitError, match="did not converge in 1 iterations"):
        fit_hazard(rows, ("a", "b"), 1.0, 2)
