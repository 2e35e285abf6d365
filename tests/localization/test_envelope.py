import numpy as np
import pandas as pd
import pytest

from poseintegrity.localization.envelope import actual_envelope, envelopes

THETA = np.array([0.0, 2.25, 4.5, 6.75])  # IV-D: the first stop is the model view
TOLERANCE = np.array([2.0, 3.0])


def test_linear_interpolation_between_the_last_passing_and_first_failing_stop():
    errors = np.array([[0.5, 0.1], [1.0, 0.2], [3.0, 0.3], [5.0, 9.0]])  # E_t crosses 2 mm halfway 2.25 -> 4.5
    assert actual_envelope(THETA, errors, TOLERANCE) == (pytest.approx(3.375), False)


def test_either_bound_fails_and_the_earlier_crossing_wins():
    errors = np.array([[0.5, 1.0], [1.0, 2.0], [2.5, 7.0], [5.0, 9.0]])
    # E_t crosses at 2.25 + 1/1.5 * 2.25 = 3.75, E_r at 2.25 + 1/5 * 2.25 = 2.7
    assert actual_envelope(THETA, errors, TOLERANCE)[0] == pytest.approx(2.7)


def test_failing_model_view_leaves_no_envelope():
    errors = np.array([[4.0, 0.0], [9.0, 9.0], [9.0, 9.0], [9.0, 9.0]])
    assert actual_envelope(THETA, errors, TOLERANCE) == (0.0, False)


def test_never_failing_dataset_is_censored_at_the_end():
    errors = np.full((4, 2), 0.5)
    assert actual_envelope(THETA, errors, TOLERANCE) == (6.75, True)


def test_failed_frames_count_as_infinite_error_at_their_stop():
    errors = np.array([[0.5, 0.1], [0.5, 0.1], [np.inf, np.inf], [0.5, 0.1]])
    assert actual_envelope(THETA, errors, TOLERANCE) == (2.25, False)


def test_table_envelopes_use_theta_for_arcs_and_x_for_lines():
    rows = []
    for dataset, trajectory in (("arc", "arc"), ("line", "line")):
        for stop, E_t in enumerate([0.5, 1.5, 2.5]):
            for image, offset in enumerate([-0.1, 0.1]):  # stop means 0.5, 1.5, 2.5 mm
                rows.append(dict(dataset=dataset, trajectory=trajectory, stop=stop, image=image,
                                 theta_deg=10.0 * stop if trajectory == "arc" else 0.0,
                                 x_mm=20.0 * stop if trajectory == "line" else 0.0,
                                 method="usac_magsac", E_t_mm=E_t + offset, E_r_deg=0.0))
    rows[-1]["E_t_mm"] = np.nan  # one failed frame in the last line stop: infinite error
    table = envelopes(pd.DataFrame(rows), [(2.0, 3.0), (4.0, 10.0)]).set_index(["dataset", "tolerance"])
    assert table.loc[("arc", "2mm_3deg"), "theta_a"] == pytest.approx(15.0)
    assert not table.loc[("arc", "2mm_3deg"), "censored"]
    assert table.loc[("arc", "4mm_10deg"), ["theta_a", "censored"]].tolist() == [20.0, True]
    assert table.loc[("line", "2mm_3deg"), "theta_a"] == pytest.approx(20.0)  # previous stop: infinite mean
    assert list(table.reset_index().columns) == ["dataset", "tolerance", "trajectory", "method", "theta_a", "censored"]
