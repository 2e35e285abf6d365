"""R11 (localization/truth_accuracy.py): the ground truth's own error over the frames it is trusted on, the model
placement's, and the bar, on tables whose numbers are known."""

import numpy as np
import pandas as pd
import pytest

from poseintegrity.localization.truth_accuracy import R11_BAR, truth_accuracy


def table(E_t_truth, statuses, method_rows=2):
    """One row per frame and PnP method (the board does not depend on the method): frames of two datasets."""
    rows = []
    for k, (error, status) in enumerate(zip(E_t_truth, statuses)):
        for method in range(method_rows):
            rows.append(dict(dataset=f"d{k % 2}", stop=k, image=0, method=f"m{method}", board_status=status,
                             board_n_dropped=int(k == 0), board_rms_px=0.05, board_sigma_t_mm=0.1,
                             board_sigma_r_deg=0.05, board_n_points=20, E_t_truth_mm=error, E_r_truth_deg=error / 4,
                             E_t_placement_mm=0.2 + 0.1 * (k % 2), E_r_placement_deg=0.05))
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
