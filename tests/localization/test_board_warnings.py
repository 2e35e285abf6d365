"""Which datasets stage 02 warns about (localization/board_warnings.py), on known tables: a board trusted in half its
frames or more, and pose ground truth, never; one mostly not found, or with too few consistent corners, is told so;
one too uncertain gets the tightest tolerance it can judge from its untrusted frames' predicted error."""

import numpy as np
import pandas as pd
import pytest

from poseintegrity.localization.board_warnings import board_warnings
from poseintegrity.params.extract import GroundTruthParams

TRUTH = GroundTruthParams(consistency_factor=4.0, noise_floor_px=0.05, min_markers=3, min_corners=6,
                          max_sigma_t_mm=0.15, max_sigma_r_deg=0.15)
TOLERANCES = [(2.0, 3.0), (4.0, 10.0)]


def frames(dataset: str, statuses: list[str], sigma_t: float = 0.1, reason: str = "") -> pd.DataFrame:
    n = len(statuses)
    return pd.DataFrame(dict(world="main", dataset=dataset, stop=np.arange(n), image=0, board_status=statuses,
                             board_reason=[reason if s == "bad_ground_truth" else "" for s in statuses],
                             board_sigma_t_mm=[sigma_t if s in ("ok", "bad_ground_truth") else np.nan
                                               for s in statuses],
                             board_sigma_r_deg=0.05))


def test_only_datasets_whose_board_judges_fewer_than_half_their_frames_are_named_once():
    table = pd.concat([frames("half", ["ok"] * 5 + ["board_not_detected"] * 5),
                       frames("poses", ["no_board"] * 10),
                       frames("lost", ["ok"] * 2 + ["board_not_detected"] * 8),
                       frames("hidden", ["ok"] * 4 + ["bad_ground_truth"] * 6, reason="4 consistent board corners "
                              "(2 dropped): fewer than 6 to check each against the others")])
    table = pd.concat([table, table])  # two methods' rows: still one warning a dataset
    warnings = {w["dataset"]: w for w in board_warnings(table, TRUTH, TOLERANCES)}
    assert sorted(warnings) == ["hidden", "lost"]
    assert warnings["lost"]["trusted_share"] == pytest.approx(0.2)
    assert "not found in 8" in warnings["lost"]["message"]
    assert "extract.ground_truth.min_markers" in warnings["hidden"]["message"]


def test_a_too_uncertain_board_names_the_tolerance_it_can_judge_from_its_untrusted_frames():
    table = pd.concat([frames("tight", ["ok"] * 3, sigma_t=0.1),
                       frames("tight", ["bad_ground_truth"] * 7, sigma_t=0.3, reason="predicted uncertainty")
                       .assign(stop=np.arange(3, 10))])
    (warning,) = board_warnings(table, TRUTH, TOLERANCES)
    assert warning["sigma_t_mm"] == pytest.approx(0.3)  # the frames it does not judge, not the trusted ones
    assert warning["tightest_tolerance_mm"] == pytest.approx(0.3 / 0.15 * 2.0)
    assert "set extract.ground_truth.max_sigma_t_mm to 0.30" in warning["message"]
    assert "judge tolerances of 4.0 mm or more" in warning["message"]
