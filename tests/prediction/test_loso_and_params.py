"""Leave-one-scene-out threshold choice on a table with known answers; the ``predict`` schema rejects bad values."""

from __future__ import annotations

import pandas as pd
import pytest
from pydantic import ValidationError

from poseintegrity.prediction import PredictParams, loso_folds, loso_summary, scene_of


def test_scene_of_dataset_ids():
    assert scene_of("scene_3_arc090") == "scene_3"
    assert scene_of("scene_2_line05") == "scene_2"
    assert scene_of("other") == "other"


def test_loso_chooses_on_other_scenes_and_scores_the_held_out_one():
    # scenes a, b are safe at n_t = 10 (theta_p 5 < theta_a 6); scene c needs n_t = 20 (theta_p 3 < theta_a 4)
    rows = []
    for scene, theta_a in (("a", 6.0), ("b", 6.0), ("c", 4.0)):
        for n_t, theta_p in ((10.0, 5.0), (20.0, 3.0)):
            rows.append(dict(predictor="long_range", method="m", trajectory="arc", tolerance="t",
                             dataset=f"{scene}_arc0", operating_point=n_t, theta_p=theta_p, theta_a=theta_a,
                             spl=min(theta_p, theta_a), incursion=float(theta_p > theta_a)))  # fmt: skip
    folds = loso_folds(pd.DataFrame(rows), 0.0, conservative_high=True)
    assert dict(zip(folds.scene, folds.operating_point, strict=True)) == {"a": 20.0, "b": 20.0, "c": 10.0}
    assert list(folds.heldout_incursions) == [0.0, 0.0, 1.0]  # the threshold from a, b is unsafe on c
    summary = loso_summary(folds, 0.0)["long_range"]["t"]
    assert summary["heldout_incursion_rate"] == pytest.approx(1 / 3)
    assert summary["heldout_mean_spl"] == pytest.approx((3.0 + 3.0 + 4.0) / 3)


def test_params_thresholds_and_sizes(tiny_predict):
    assert tiny_predict.thresholds[0] == 4 and tiny_predict.thresholds[-1] == 100 and tiny_predict.thresholds.size == 97
    assert tiny_predict.static_sizes("line")[-1] == 150.0 and tiny_predict.long_range_stops("line") == 5


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("n_t_max", 3, "n_t_max"),
        ("n_t_min", 0, "n_t_min"),
        ("models", {"long_range": "spline", "next_step": "emg", "mlp": "mlp_pretrained"}, "models.long_range"),
        ("loso_target_rates", [1.5], "loso_target_rates"),
        ("uncertainty", {"method": "covariance", "level": 1.0, "n_bootstrap": 5}, "uncertainty.level"),
        ("unknown_key", 1, "unknown_key"),
    ],
)
def test_bad_values_raise_naming_the_key(tiny_predict_raw, key, value, message):
    tiny_predict_raw[key] = value
    with pytest.raises(ValidationError, match=message):
        PredictParams.model_validate(tiny_predict_raw)
