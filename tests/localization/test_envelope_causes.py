"""Why each envelope ends (localization/envelope_causes.py): the criterion that ends it and whether the estimate,
the ground truth or its resolution moved it across the bound, read at the failing stop, per tolerance against its
own bar."""

import numpy as np
import pandas as pd
import pytest

from loc_envelope_tables import RULES, judged_table
from poseintegrity.localization.envelope_causes import envelope_causes


def _causes_table(truth_errors, exact_errors, posed=None, board_status="ok"):
    """One arc, 4 stops of 2 frames: E_t against the ground truth and against the exact pose per stop."""
    rows = []
    for s, (truth, exact) in enumerate(zip(truth_errors, exact_errors)):
        for image in range(2):
            ok = True if posed is None else posed[s]
            rows.append(dict(world="main", dataset="d", trajectory="arc", stop=s, image=image, theta_deg=2.25 * s,
                             x_mm=0.0, method="usac_magsac", status="ok" if ok else "no_consensus",
                             E_t_mm=truth if ok else np.nan, E_r_deg=0.1 if ok else np.nan,
                             E_t_exact_mm=exact if ok else np.nan,
                             E_r_exact_deg=0.1 if ok and np.isfinite(exact) else np.nan,
                             n_inliers=100 - 20 * s, board_status=board_status, board_n_dropped=0,
                             board_sigma_t_mm=0.1))
    return pd.DataFrame(rows)


@pytest.mark.parametrize("truth, exact, posed, cause, limit", [
    ([0.5, 1.0, 3.0, 4.0], [0.5, 1.0, 3.0, 4.0], None, "estimate", "translation"),
    ([0.5, 1.0, 3.0, 4.0], [0.4, 0.5, 0.6, 0.7], None, "ground_truth", "translation"),
    ([0.5, 1.0, 2.2, 4.0], [0.5, 1.0, 1.9, 1.9], None, "resolution", "translation"),  # moved by 0.3 <= R11's 0.5 mm
    ([0.5, 1.0, 2.6, 4.0], [0.5, 1.0, 1.9, 1.9], None, "ground_truth", "translation"),  # moved by 0.7 > 0.5 mm
    ([0.5, 0.5, 0.5, 0.5], [0.5, 0.5, 0.5, 0.5], [True, True, False, False], "no_pose", "no_pose"),
    ([0.5, 0.5, 0.5, 0.5], [0.5, 0.5, 0.5, 0.5], None, "censored", "censored"),
])
def test_each_envelope_end_gets_its_limit_and_cause(truth, exact, posed, cause, limit):
    causes = envelope_causes(_causes_table(truth, exact, posed), [(2.0, 3.0)], RULES, "usac_magsac")
    row = causes.iloc[0]
    assert (row["limit"], row["cause"]) == (limit, cause)
    if cause in ("ground_truth", "resolution"):  # against the exact pose the envelope lasts to the arc's end
        assert row["theta_a_exact"] == pytest.approx(6.75)
        assert row["truth_shift"] == pytest.approx(truth[2] - exact[2])
    if truth == [0.5, 1.0, 3.0, 4.0] and cause == "ground_truth":
        assert row["theta_a"] == pytest.approx(2.25 + 2.25 / 2) and row["n_inliers_at_theta_a"] == pytest.approx(70.0)


def test_the_exact_pose_judges_the_frames_the_ground_truth_judged():
    # stop 2: image 0's board pose is not trusted (no E_t), image 1's is, and the estimate there is off by 2.4 mm
    # against either pose; image 0 is fine against the exact pose and would pull the exact mean to 1.45 mm
    table = _causes_table([0.5, 1.0, 2.5, 4.0], [0.5, 1.0, 2.4, 4.0])
    at = (table.stop == 2) & (table.image == 0)
    table.loc[at, ["E_t_mm", "E_t_exact_mm", "board_status"]] = [np.nan, 0.5, "bad_ground_truth"]
    row = envelope_causes(table, [(2.0, 3.0)], RULES, "usac_magsac").iloc[0]
    assert (row["cause"], row["truth_shift"], row["unmeasured_stops"]) == ("estimate", pytest.approx(0.1), 0)
    table.loc[table.stop == 1, ["E_t_mm", "E_r_deg", "board_status"]] = [np.nan, np.nan, "bad_ground_truth"]
    row = envelope_causes(table, [(2.0, 3.0)], RULES, "usac_magsac").iloc[0]  # theta_a read across stop 1
    assert row["unmeasured_stops"] == 1 and row["theta_a"] == pytest.approx(1.5 / 2.0 * 4.5)  # 0.5 at 0, 2.5 at 4.5


def test_without_exact_poses_the_boards_own_checks_stand_in():
    table = _causes_table([0.5, 1.0, 3.0, 4.0], [np.nan] * 4)
    assert envelope_causes(table, [(2.0, 3.0)], RULES, "usac_magsac").iloc[0]["cause"] == "estimate"
    table.loc[table.stop == 2, "board_n_dropped"] = 1
    row = envelope_causes(table, [(2.0, 3.0)], RULES, "usac_magsac").iloc[0]
    assert row["cause"] == "ground_truth" and row["board_dropped_share"] == 1.0 and np.isnan(row["theta_a_exact"])


def test_the_cause_is_read_where_the_ending_criterion_fails_not_where_another_one_does():
    # stop 1: posed, board not trusted; stop 2: no pose at all (the no-pose share fails there, crossing at 3.375 deg);
    # E_t is read across both, 0.5 at 0 deg to 4.0 at 6.75 deg: translation ends first (2.89 deg), failing at stop 3,
    # where the exact pose says 1.0 mm: the ground truth moved it by 3 mm
    table = _causes_table([0.5, 0.5, 0.5, 4.0], [0.5, 0.5, 0.5, 1.0], posed=[True, True, False, True])
    table.loc[table.stop == 1, ["E_t_mm", "E_r_deg", "board_status"]] = [np.nan, np.nan, "bad_ground_truth"]
    row = envelope_causes(table, [(2.0, 3.0)], RULES, "usac_magsac").iloc[0]
    assert row["theta_a"] == pytest.approx(1.5 / 3.5 * 6.75) and row["limit"] == "translation"
    assert (row["cause"], row["truth_shift"], row["unmeasured_stops"]) == ("ground_truth", pytest.approx(3.0), 2)


def test_the_causes_of_a_looser_tolerance_count_only_the_poses_that_cannot_judge_it():
    causes = envelope_causes(judged_table((1.8, 3.0)), [(2.0, 3.0), (4.0, 10.0)], RULES, "usac_magsac")
    row = causes.set_index("tolerance").loc["4mm_10deg"]
    assert (row["cause"], row["limit"]) == ("estimate", "translation") and row["board_untrusted_share"] == 0.0
    assert row["theta_a"] == pytest.approx(2.25 + 0.75 * 4.5) == row["theta_a_exact"]
    assert causes.set_index("tolerance").loc["2mm_3deg", "cause"] == "unmeasured"


def test_a_looser_tolerances_ground_truth_is_judged_against_its_own_bar():
    # 4 mm / 10 deg fails at stop 2 against the ground truth (4.4 mm) but not against the exact pose (3.7 mm): the
    # ground truth moved it across by 0.7 mm, beyond R11's 0.5 mm for 2 mm / 3 deg but within 2 x 0.5 mm for 4 mm
    table = _causes_table([0.5, 1.0, 4.4, 6.0], [0.5, 1.0, 3.7, 3.7])
    causes = envelope_causes(table, [(2.0, 3.0), (4.0, 10.0)], RULES, "usac_magsac").set_index("tolerance")
    assert causes.loc["4mm_10deg", "cause"] == "resolution"
    assert causes.loc["4mm_10deg", "truth_shift"] == pytest.approx(0.7)
    alone = envelope_causes(table, [(4.0, 10.0)], RULES, "usac_magsac").iloc[0]  # the tightest: its bar is 0.5 mm
    assert alone["cause"] == "ground_truth"
