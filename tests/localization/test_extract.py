import shutil

import numpy as np
import pytest
from scipy.stats import spearmanr

from poseintegrity.localization import extract as E
from poseintegrity.localization.envelope import envelopes
from poseintegrity.localization.features import ImageReadError

METHODS = ["usac_magsac", "epnp"]


@pytest.fixture(scope="module")
def table(synthetic_data_dir, extract_params):
    params = extract_params.model_copy(update=dict(datasets=["arc_a", "line_a"]))
    return E.extract_all(synthetic_data_dir, params, METHODS, progress=False)


def test_one_row_per_frame_and_method_with_the_schema(table):
    assert len(table) == (4 * 2 + 2 * 2) * len(METHODS)
    for column in ["dataset", "trajectory", "stop", "image", "theta_deg", "x_mm", "method", "n_inliers", "n_matches",
                   "inlier_ratio", "reproj_error_px", "inlier_spread_px", "E_t_mm", "E_r_deg", "E_t_board_mm",
                   "E_r_board_deg", "status", "board_status"]:
        assert column in table.columns
    assert set(table["trajectory"]) == {"arc", "line"}


def test_accurate_near_the_model_view_and_inliers_fall_with_theta(table):
    arc = table[(table.dataset == "arc_a") & (table.method == "usac_magsac")]
    first = arc[arc.stop == 0]
    assert (first.status == "ok").all() and first.n_inliers.min() > 100
    assert first.E_t_mm.max() < 1.0 and first.E_r_deg.max() < 0.5
    assert first.E_t_board_exact_mm.max() < 1.5  # ArUco ground truth is close to the exact pose
    per_stop = arc.groupby("stop").agg(theta=("theta_deg", "mean"), n_i=("n_inliers", "mean"))
    assert spearmanr(per_stop.theta, per_stop.n_i).statistic < -0.9


def test_features_are_cached_per_image(table, synthetic_data_dir, extract_params):
    cache = synthetic_data_dir / extract_params.features_dir / "arc_a"
    assert len(list((cache / "images").glob("*.npz"))) == 8 and len(list((cache / "model").glob("*.npz"))) == 2


def test_runs_repeat_exactly(table, synthetic_data_dir, extract_params):
    again = E.extract_dataset(synthetic_data_dir, "datasets/line_a", extract_params, METHODS, progress=False)
    first = table[table.dataset == "line_a"].reset_index(drop=True)
    np.testing.assert_array_equal(again["n_inliers"], first["n_inliers"])
    np.testing.assert_array_equal(again["E_t_mm"], first["E_t_mm"])


def test_envelope_of_the_synthetic_arc(table, protocol):
    env = envelopes(table, protocol.tolerances)
    assert len(env) == 2 * len(METHODS) * len(protocol.tolerances)
    arc = env[env.dataset == "arc_a"]
    assert ((arc.theta_a > 10.0) & (arc.theta_a <= 55.0)).all()


def test_bad_frames_give_flagged_rows_not_crashes(synthetic_data_dir, extract_params):
    rows = E.extract_dataset(synthetic_data_dir, "datasets/bad", extract_params, METHODS, progress=False)
    by_image = rows[rows.method == "usac_magsac"].set_index("image")
    blank, no_board, few_blobs = by_image.loc[0], by_image.loc[1], by_image.loc[2]
    assert blank.status == "no_keypoints" and blank.n_inliers == 0 and np.isnan(blank.E_t_mm)
    assert blank.board_status == "board_not_detected" and np.isnan(blank.E_t_board_mm)
    assert no_board.status == "ok" and no_board.E_t_mm < 1.0
    assert no_board.board_status == "board_not_detected" and np.isnan(no_board.E_r_board_deg)
    assert few_blobs.status == "too_few_matches" and few_blobs.n_inliers == 0 and np.isnan(few_blobs.E_r_deg)
    assert few_blobs.n_keypoints > 0 and few_blobs.n_matches < 4


@pytest.mark.parametrize("damage", ["delete", "garble"])
def test_missing_or_unreadable_image_stops_with_the_file_name(synthetic_data_dir, extract_params, tmp_path, damage):
    data_dir = tmp_path / "data"
    shutil.copytree(synthetic_data_dir / "datasets" / "line_a", data_dir / "datasets" / "line_a")
    image = data_dir / "datasets" / "line_a" / "images" / "s01_i00.png"
    image.unlink() if damage == "delete" else image.write_bytes(b"\x89PNG broken")
    with pytest.raises(ImageReadError, match="s01_i00.png"):
        E.extract_dataset(data_dir, "datasets/line_a", extract_params, METHODS, progress=False)


def test_unknown_dataset_in_params_is_named(synthetic_data_dir, extract_params):
    with pytest.raises(ValueError, match="nope"):
        E.extract_all(synthetic_data_dir, extract_params.model_copy(update=dict(datasets=["nope"])), METHODS)
