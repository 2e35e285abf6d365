"""The actual envelope theta_a (localization/envelope.py, IV-E): interpolated between stops, under every failed-frame
rule, unmeasured stops skipped, and each tolerance judged by the board poses fine enough for it."""

import numpy as np
import pandas as pd
import pytest

from loc_envelope_tables import RULES, judged_table
from poseintegrity.localization.envelope import (
    CRITERIA, actual_envelope, envelopes, headline, stop_criteria, tolerance_loosening,
)
from poseintegrity.params.protocol import FAILED_FRAME_RULES

THETA = np.array([0.0, 2.25, 4.5, 6.75])  # IV-D: the first stop is the model view
TOLERANCE = np.array([2.0, 3.0])


def test_linear_interpolation_between_the_last_passing_and_first_failing_stop():
    errors = np.array([[0.5, 0.1], [1.0, 0.2], [3.0, 0.3], [5.0, 9.0]])  # E_t crosses 2 mm halfway 2.25 -> 4.5
    assert actual_envelope(THETA, errors, TOLERANCE)[:3] == (pytest.approx(3.375), False, ())


def test_either_bound_fails_and_the_earlier_crossing_wins():
    errors = np.array([[0.5, 1.0], [1.0, 2.0], [2.5, 7.0], [5.0, 9.0]])
    # E_t crosses at 2.25 + 1/1.5 * 2.25 = 3.75, E_r at 2.25 + 1/5 * 2.25 = 2.7
    assert actual_envelope(THETA, errors, TOLERANCE)[0] == pytest.approx(2.7)


def test_failing_model_view_leaves_no_envelope():
    errors = np.array([[4.0, 0.0], [9.0, 9.0], [9.0, 9.0], [9.0, 9.0]])
    assert actual_envelope(THETA, errors, TOLERANCE)[:3] == (0.0, False, ())


def test_never_failing_dataset_is_censored_at_the_end():
    errors = np.full((4, 2), 0.5)
    assert actual_envelope(THETA, errors, TOLERANCE)[:3] == (6.75, True, ())


def test_an_infinite_criterion_crosses_at_the_previous_stop_and_nan_never_fails():
    errors = np.array([[0.5, 0.1], [0.5, 0.1], [np.inf, np.inf], [0.5, 0.1]])
    assert actual_envelope(THETA, errors, TOLERANCE)[:3] == (2.25, False, ())
    unscored = np.array([[0.5, 0.1], [np.nan, np.nan], [0.5, 0.1], [0.5, 0.1]])
    assert actual_envelope(THETA, unscored, TOLERANCE)[:3] == (6.75, True, (2.25,))  # skipped, and said


def test_an_unmeasured_stop_is_skipped_interpolating_from_the_last_measured_one():
    # E_t 0.5 mm at 0 deg, unmeasured at 2.25 and 4.5 (no board in any posed frame), 5 mm at 6.75: the 2 mm bound is
    # crossed at 0 + (2 - 0.5) / (5 - 0.5) * 6.75 = 2.25 deg by IV-E's interpolation between sampled points, not at
    # the unmeasured 4.5 deg (where the envelope would be read as 100 % longer than the measurements say)
    errors = np.array([[0.5, 0.1], [np.nan, np.nan], [np.nan, np.nan], [5.0, 0.1]])
    assert actual_envelope(THETA, errors, TOLERANCE)[:3] == (pytest.approx(2.25), False, (2.25, 4.5))
    infinite = errors.copy()
    infinite[3] = np.inf  # a frame without a pose at the failing stop: the crossing is the last measured stop
    assert actual_envelope(THETA, infinite, TOLERANCE)[:3] == (0.0, False, (2.25, 4.5))
    # unmeasured last stops and no failure: no end was seen, so none is read (neither the unmeasured end nor a
    # censoring at 2.25, which would score every prediction beyond 2.25 deg as an incursion)
    theta_a, censored, unmeasured, _ = actual_envelope(THETA, errors[[0, 3, 1, 2]] * [0.1, 1], TOLERANCE)
    assert np.isnan(theta_a) and not censored and unmeasured == (4.5, 6.75)
    # measured stops only: the paper's definition, unchanged (the interpolation of the first test)
    assert actual_envelope(THETA[[0, 3]], errors[[0, 3]], TOLERANCE)[:2] == (pytest.approx(2.25), False)


def test_a_criterion_measured_only_where_it_fails_gives_no_envelope():
    errors = np.array([[np.nan, 0.1], [np.nan, 0.2], [5.0, 0.3], [5.0, 0.4]])
    theta_a, censored, unmeasured, _ = actual_envelope(THETA, errors, TOLERANCE)
    assert np.isnan(theta_a) and not censored and unmeasured == (0.0, 2.25)


def stop(errors_mm: list[float], failed: int) -> list[tuple[str, float]]:
    """Frames of one stop: posed frames with these E_t (E_r 0), then ``failed`` frames without a pose."""
    return [("ok", e) for e in errors_mm] + [("pnp_failed", np.nan)] * failed


def frames_of(stops: list[list[tuple[str, float]]]) -> pd.DataFrame:
    return pd.DataFrame([dict(stop=s, status=status, E_t_mm=e, E_r_deg=0.0 if status == "ok" else np.nan)
                         for s, rows in enumerate(stops) for status, e in rows])


# stop 1 has 1 frame of 10 without a pose, stop 2 has 6 of 10, stop 3 all: posed errors stay small
FAILING = frames_of([stop([0.5] * 10, 0), stop([0.5] * 9, 1), stop([0.5] * 4, 6), stop([], 10)])


def test_fail_fraction_rule_interpolates_the_share_of_frames_without_a_pose():
    criteria, bounds = stop_criteria(FAILING, (2.0, 3.0), "fail_fraction", RULES)
    np.testing.assert_allclose(criteria[:, 2], [0.0, 0.1, 0.6, 1.0])
    np.testing.assert_allclose(bounds, [2.0, 3.0, 0.5])
    assert np.isnan(criteria[3, 0])  # nothing to average where no frame has a pose
    # the share crosses 0.5 at 2.25 + (0.5 - 0.1) / (0.6 - 0.1) * 2.25 = 4.05, between the stops
    assert actual_envelope(THETA, criteria, bounds)[:3] == (pytest.approx(4.05), False, ())


def test_capped_rule_counts_a_missing_pose_as_cap_factor_times_the_tolerance():
    criteria, bounds = stop_criteria(FAILING, (2.0, 3.0), "capped", RULES)
    np.testing.assert_allclose(criteria[:, 0], [0.5, 0.9 * 0.5 + 0.1 * 20.0, 0.4 * 0.5 + 0.6 * 20.0, 20.0])
    # E_t: 0.5 -> 2.45 crosses 2 mm at 2.25 * (1.5 / 1.95); E_r: 0 -> 3.0 never exceeds 3 deg at stop 1
    assert actual_envelope(THETA, criteria, bounds)[0] == pytest.approx(2.25 * 1.5 / 1.95)


def test_infinite_rule_snaps_to_the_stop_before_any_frame_without_a_pose():
    criteria, bounds = stop_criteria(FAILING, (2.0, 3.0), "infinite", RULES)
    assert actual_envelope(THETA, criteria, bounds)[:3] == (0.0, False, ())


def test_a_frame_without_ground_truth_is_left_out_of_the_mean():
    frames = frames_of([stop([0.5, 0.5], 0), stop([0.5, np.nan], 0), stop([3.0, 3.0], 0)])
    criteria, _ = stop_criteria(frames, (2.0, 3.0), "infinite", RULES)
    np.testing.assert_allclose(criteria[:, 0], [0.5, 0.5, 3.0])


def test_table_envelopes_use_theta_for_arcs_and_x_for_lines_under_every_rule():
    rows = []
    for dataset, trajectory in (("arc", "arc"), ("line", "line")):
        for s, E_t in enumerate([0.5, 1.5, 2.5]):
            for image, offset in enumerate([-0.1, 0.1]):  # stop means 0.5, 1.5, 2.5 mm
                rows.append(dict(world="main", dataset=dataset, trajectory=trajectory, stop=s, image=image, status="ok",
                                 theta_deg=10.0 * s if trajectory == "arc" else 0.0,
                                 x_mm=20.0 * s if trajectory == "line" else 0.0,
                                 method="usac_magsac", E_t_mm=E_t + offset, E_r_deg=0.0))
    rows[-1].update(status="pnp_failed", E_t_mm=np.nan, E_r_deg=np.nan)  # half the last line stop has no pose
    table = envelopes(pd.DataFrame(rows), [(2.0, 3.0), (4.0, 10.0)], RULES)
    assert set(table["rule"]) == set(FAILED_FRAME_RULES) and len(table) == 2 * 2 * len(FAILED_FRAME_RULES)
    ours = headline(table, RULES).set_index(["dataset", "tolerance"])
    assert ours.loc[("arc", "2mm_3deg"), "theta_a"] == pytest.approx(15.0)
    assert not ours.loc[("arc", "2mm_3deg"), "censored"]
    assert ours.loc[("arc", "4mm_10deg"), ["theta_a", "censored"]].tolist() == [20.0, True]
    # line: the one posed frame of the last stop has 2.4 mm, crossing 2 mm at 20 + 0.5 / 0.9 * 20
    assert ours.loc[("line", "2mm_3deg"), "theta_a"] == pytest.approx(20.0 + 20.0 * 0.5 / 0.9)
    snapped = table[(table.rule == "infinite") & (table.dataset == "line")].set_index("tolerance")
    assert snapped.loc["2mm_3deg", "theta_a"] == pytest.approx(20.0)  # the previous stop
    assert list(ours.reset_index().columns) == ["dataset", "tolerance", "world", "trajectory", "method", "theta_a",
                                                "censored", "status", "reason"]
    assert set(table["status"]) == {"ok"} and set(table["reason"]) == {""}


def test_table_envelopes_flag_a_stop_whose_frames_all_lack_errors():
    rows = [dict(world="main", dataset="arc", trajectory="arc", stop=s, image=i, status="ok", theta_deg=10.0 * s,
                 x_mm=0.0, method="usac_magsac", E_t_mm=E_t, E_r_deg=0.0 if np.isfinite(E_t) else np.nan)
            for s, E_t in enumerate([0.5, np.nan, 5.0]) for i in range(2)]  # stop 1: posed, board never detected
    table = envelopes(pd.DataFrame(rows), [(2.0, 3.0)], RULES).set_index("rule")
    for rule in FAILED_FRAME_RULES:  # every frame has a pose: every rule reads the same stops
        # 0 + (2 - 0.5) / (5 - 0.5) * 20 deg, not the unmeasured stop at 10 deg
        assert table.loc[rule, "theta_a"] == pytest.approx(20.0 / 3)
        assert table.loc[rule, "status"] == "unmeasured_stops"
        assert "stop(s) at 10 deg" in table.loc[rule, "reason"]


def test_the_crossing_names_the_criterion_that_ends_the_envelope():
    errors = np.array([[0.5, 1.0], [1.0, 2.0], [2.5, 7.0], [5.0, 9.0]])  # E_r crosses first (2.7 before 3.75)
    assert actual_envelope(THETA, errors, TOLERANCE) == (pytest.approx(2.7), False, (), 1)
    assert actual_envelope(THETA, np.full((4, 2), 0.5), TOLERANCE) == (6.75, True, (), -1)
    criteria, bounds = stop_criteria(FAILING, (2.0, 3.0), "fail_fraction", RULES)
    assert actual_envelope(THETA, criteria, bounds).criterion == 2  # the share without a pose
    assert CRITERIA[2] == "no_pose"


def test_a_looser_tolerance_is_judged_by_the_poses_fine_enough_for_it():
    tolerances = [(2.0, 3.0), (4.0, 10.0)]  # 4 mm / 10 deg is 2 x looser in E_t and 3.3 x in E_r
    np.testing.assert_allclose(tolerance_loosening((4.0, 10.0), tolerances), [2.0, 10.0 / 3.0])
    np.testing.assert_allclose(tolerance_loosening((2.0, 3.0), tolerances), [1.0, 1.0])
    with pytest.warns(UserWarning, match="not measured"):  # 2 mm / 3 deg
        fine = headline(envelopes(judged_table((1.8, 3.0)), tolerances, RULES), RULES).set_index("tolerance")
    # 2 mm / 3 deg: stops 2-3 unmeasured and none failed before: no envelope; 4 mm: 1.0 mm at 2.25 deg and 5.0 mm
    # at 6.75 deg read from the poses within 2 x / 3.3 x the limits, crossing at 2.25 + 3 / 4 x 4.5 deg
    assert np.isnan(fine.loc["2mm_3deg", "theta_a"]) and fine.loc["2mm_3deg", "status"] == "not_measured"
    assert fine.loc["4mm_10deg", "theta_a"] == pytest.approx(2.25 + 0.75 * 4.5)
    assert fine.loc["4mm_10deg", "status"] == "ok"
    with pytest.warns(UserWarning, match="not measured"):  # a pose too uncertain in either axis judges nothing
        for scales in ((2.1, 1.0), (1.0, 3.4), (np.nan, np.nan)):
            coarse = headline(envelopes(judged_table(scales), tolerances, RULES), RULES).set_index("tolerance")
            assert coarse["theta_a"].isna().all()


def test_the_tightest_tolerance_and_tables_without_the_loose_columns_are_judged_as_before():
    tolerances = [(2.0, 3.0), (4.0, 10.0)]
    table = judged_table((1.5, 1.5))
    table.loc[table.stop == 3, ["E_t_mm", "E_r_deg", "board_status"]] = [5.0, 0.5, "ok"]  # measured: 2 mm readable
    with_loose = envelopes(table, tolerances, RULES)
    without = envelopes(table.drop(columns=["E_t_loose_mm", "E_r_loose_deg", "truth_scale_t", "truth_scale_r"]),
                        tolerances, RULES)
    tight = with_loose["tolerance"] == "2mm_3deg"
    pd.testing.assert_frame_equal(with_loose[tight], without[tight])
    # 4 mm without the loose columns reads across the refused stop 2: 1.0 at 2.25, 5.0 at 6.75 deg
    loose = with_loose[~tight & (with_loose.rule == "fail_fraction")]["theta_a"].iloc[0]
    assert loose == pytest.approx(2.25 + 0.75 * 4.5)
    assert without[~tight & (without.rule == "fail_fraction")]["theta_a"].iloc[0] == pytest.approx(2.25 + 0.75 * 4.5)
    assert without[~tight & (without.rule == "fail_fraction")]["status"].iloc[0] == "unmeasured_stops"
    assert with_loose[~tight & (with_loose.rule == "fail_fraction")]["status"].iloc[0] == "ok"
