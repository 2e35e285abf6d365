"""R11 (localization/truth_accuracy.py): the ground truth's own error over the frames it is trusted on, the model
placement's, and the bar, on tables whose numbers are known."""

import numpy as np
import pandas as pd
import pytest

from poseintegrity.localization.truth_accuracy import R11_BAR, truth_accuracy


def table(E_t_truth, statuses, method_rows=2):
    """One row per frame and PnP method (the board does not depend on the method): frames of two datasets."""
    rows = []
    for i, (error, status) in enumerate(zip(E_t_truth, statuses)):
        for method in range(method_rows):
            rows.append(dict(dataset=f"d{i % 2}", stop=i, image=0, method=f"m{method}", board_status=status,
                             board_n_dropped=int(i == 0), board_rms_px=0.05, board_sigma_t_mm=0.1,
                             board_sigma_r_deg=0.05, board_n_points=20, E_t_truth_mm=error, E_r_truth_deg=error / 4,
                             E_t_placement_mm=0.2 + 0.1 * (i % 2), E_r_placement_deg=0.05))
    return pd.DataFrame(rows)


def test_the_quantiles_are_taken_over_trusted_frames_once_each():
    errors = np.linspace(0.0, 0.99, 100)
    statuses = ["ok"] * 100 + ["bad_ground_truth"] * 10
    result = truth_accuracy(table([*errors, *[9.0] * 10], statuses))
    assert result["n_frames"] == 110 and result["trusted_share"] == pytest.approx(100 / 110)
    assert result["median_E_t_truth_mm"] == pytest.approx(np.median(errors))
    assert result["p99_E_t_truth_mm"] == pytest.approx(np.quantile(errors, 0.99))
    assert result["p99_E_r_truth_deg"] == pytest.approx(np.quantile(errors, 0.99) / 4)
    assert result["placement_max_E_t_mm"] == pytest.approx(0.3) and result["dropped_share"] == pytest.approx(1 / 110)
    assert result["status_shares"]["bad_ground_truth"] == pytest.approx(10 / 110)
    assert result["r11_passed"] is False  # p99 0.98 mm > 0.5 mm


def test_the_bar_passes_below_a_quarter_of_the_tightest_tolerance():
    assert R11_BAR == (0.5, 0.5)
    assert truth_accuracy(table(np.linspace(0.0, 0.45, 50), ["ok"] * 50))["r11_passed"] is True


def test_recorded_data_without_exact_poses_describe_the_board_and_judge_nothing():
    result = truth_accuracy(table([np.nan] * 10, ["ok"] * 9 + ["bad_ground_truth"]))
    assert result["r11_passed"] is None and np.isnan(result["p99_E_t_truth_mm"])
    assert result["trusted_share"] == pytest.approx(0.9) and result["median_rms_px"] == pytest.approx(0.05)


def test_a_looser_tolerance_has_its_bar_over_the_frames_that_judge_it():
    # 100 trusted frames within 0.45 mm, and 20 refused by the limits alone at 1.5 x them whose error is 0.8 mm
    # (deg / 4): 4 mm / 10 deg (2 x and 3.3 x looser) takes them, against its bar of 1.0 mm / 1.67 deg
    tolerances = [(2.0, 3.0), (4.0, 10.0)]
    frames = table([*np.linspace(0.0, 0.45, 100), *[0.8] * 20], ["ok"] * 100 + ["bad_ground_truth"] * 20)
    refused = frames["board_status"] == "bad_ground_truth"
    frames = frames.assign(truth_scale_t=np.where(refused, 1.5, 0.5), truth_scale_r=np.where(refused, 1.5, 0.5))
    result = truth_accuracy(frames, tolerances)
    loose = result["by_tolerance"]["4mm_10deg"]
    assert loose["k"] == pytest.approx([2.0, 10.0 / 3.0]) and loose["bar"] == pytest.approx([1.0, 5.0 / 3.0])
    assert loose["judged_share"] == pytest.approx(1.0) and loose["p99_E_t_truth_mm"] == pytest.approx(0.8)
    assert loose["passed"] is True and result["r11_passed"] is True
    assert result["p99_E_t_truth_mm"] <= 0.45  # the tightest tolerance's quantile is over the trusted frames alone
    worse = truth_accuracy(frames.assign(E_t_truth_mm=np.where(refused, 1.2, frames["E_t_truth_mm"])), tolerances)
    assert worse["by_tolerance"]["4mm_10deg"]["passed"] is False and worse["r11_passed"] is False
    beyond = truth_accuracy(frames.assign(truth_scale_t=np.where(refused, 2.5, 0.5)), tolerances)
    assert beyond["by_tolerance"]["4mm_10deg"]["judged_share"] == pytest.approx(100 / 120)
    assert "by_tolerance" in truth_accuracy(frames) and truth_accuracy(frames)["by_tolerance"] == {}
