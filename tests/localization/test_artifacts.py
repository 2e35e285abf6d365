import numpy as np
import pandas as pd
import pytest

from poseintegrity.localization.artifacts import frame_artifacts, json_ready, method_summary, realism_metrics
from poseintegrity.localization.envelope import envelopes
from poseintegrity.localization.pnp import PnPResult, failed

K = np.array([[500.0, 0.0, 0.0], [0.0, 500.0, 0.0], [0.0, 0.0, 1.0]])


def test_inlier_geometry_of_a_known_square():
    """Four inliers at the corners of a 100 px square (exact projections) and one outlier."""
    T = np.eye(4)
    T[2, 3] = 500.0
    X = np.array([[0, 0, 0], [100, 0, 0], [100, 100, 0], [0, 100, 0], [50, 50, 0]], dtype=float)
    x = X[:, :2].copy()
    x[4] += 40.0  # the outlier
    result = PnPResult(T, np.arange(4), 4, "ok")
    row = frame_artifacts(result, X, x, K, n_keypoints=10, model_size=8)
    assert row["n_inliers"] == 4 and row["n_matches"] == 5 and row["inlier_ratio"] == pytest.approx(0.8)
    assert row["reproj_error_px"] == pytest.approx(0.0)
    assert row["inlier_spread_px"] == pytest.approx(np.sqrt(2) * 50)
    assert row["inlier_hull_area_px2"] == pytest.approx(1e4)
    assert row["model_coverage"] == pytest.approx(0.5)


def test_failed_result_has_zero_inliers_and_nan_geometry():
    row = frame_artifacts(failed("pnp_failed"), np.zeros((2, 3)), np.zeros((2, 2)), K, 10, 8)
    assert row["n_inliers"] == 0 and row["inlier_ratio"] == 0.0 and np.isnan(row["inlier_spread_px"])


def world(decay_by_dataset):
    """Artifact rows where n_i = 100 - decay * theta and E_t = 50 / n_i (errors blow up with few inliers)."""
    rows = []
    for dataset, decay in decay_by_dataset.items():
        for stop in range(20):
            theta = 2.25 * (stop + 1)
            n_i = max(int(100 - decay * theta), 0)
            for image in range(2):
                rows.append(dict(dataset=dataset, trajectory="arc", stop=stop, image=image, theta_deg=theta,
                                 x_mm=0.0, method="usac_magsac", n_inliers=n_i, status="ok" if n_i else "pnp_failed",
                                 E_t_mm=50.0 / n_i if n_i else np.nan, E_r_deg=0.0))
    return pd.DataFrame(rows)


def test_realism_metrics_of_a_world_with_known_answers():
    table = world({"a": 1.5, "b": 2.0, "c": 0.8})  # strictly decreasing n_i, never 0
    metrics = realism_metrics(table, envelopes(table, [(2.0, 3.0), (4.0, 10.0)]))
    assert metrics["min_abs_spearman"] == pytest.approx(1.0)
    assert metrics["min_first_stop_mean_inliers"] == 95  # dataset b: int(100 - 2 * 2.25)
    low = 50.0 / table.loc[table.n_inliers < 15, "n_inliers"]
    high = 50.0 / table.loc[table.n_inliers > 50, "n_inliers"]
    assert metrics["error_ratio_low_vs_high_inliers"] == pytest.approx(low.median() / high.median())
    # E_t = 50 / n_i exceeds 2 mm once n_i < 25: only b (theta 36 -> 38.25) inside the arc; 4 mm: b only
    assert 36.0 < metrics["min_theta_a_2mm3deg"] == metrics["theta_a_2mm3deg"]["b"] < 38.25
    assert metrics["theta_a_2mm3deg"]["a"] == metrics["theta_a_2mm3deg"]["c"] == 45.0
    assert metrics["n_uncensored_4mm10deg"] == 1
    # b fails at 4 mm once E_t = 50 / n_i > 4, i.e. between the stops with mean n_i 14 and 10 (theta 42.75, 45)
    assert 10 < metrics["median_inliers_at_theta_a_4mm10deg"] == metrics["inliers_at_theta_a_4mm10deg"]["b"] <= 14
    assert set(metrics["inliers_at_theta_a_2mm3deg"]) == {"b"}
    assert metrics["passed"]["inliers_at_failure"]
    assert metrics["passed"]["spearman"] and metrics["passed"]["first_stop_inliers"]
    assert not metrics["passed"]["uncensored"]


def test_method_summary_and_json_ready():
    table = pd.concat([world({"a": 2.3}).assign(method=m) for m in ("epnp", "p3p")], ignore_index=True)
    table.loc[table.method == "p3p", "n_inliers"] += 10
    summary = method_summary(table, envelopes(table, [(2.0, 3.0)])).set_index("method")
    assert summary.loc["p3p", "mean_n_inliers_first_stop"] == summary.loc["epnp", "mean_n_inliers_first_stop"] + 10
    assert summary.loc["epnp", "n_frames"] == 40
    assert summary.loc["epnp", "failure_rate"] == pytest.approx(2 / 40)  # n_i = 0 at theta 45 only
    assert "mean_theta_a_arc_2mm_3deg" in summary.columns
    assert json_ready({"a": np.float64("nan"), "b": [np.int64(3), np.bool_(True)]}) == {"a": None, "b": [3, True]}
