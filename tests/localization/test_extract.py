import io
import json
import shutil

import numpy as np
import pytest
from scipy.stats import spearmanr

import loc_synthetic as synthetic
from poseintegrity import cache_entry as C
from poseintegrity.localization import extract as E
from poseintegrity.localization.dataset import DatasetError, load_dataset
from poseintegrity.localization.envelope import envelopes
from poseintegrity.localization.frame_rows import usable
from poseintegrity.localization.model_store import dataset_model
from poseintegrity.params.protocol import FAILED_FRAME_RULES
from poseintegrity.poses import pose_errors

METHODS = ["usac_magsac", "epnp"]


def parquet_bytes(table) -> bytes:
    """The bytes the stage would write for ``table`` (NaN-safe equality of every value and dtype)."""
    buffer = io.BytesIO()
    table.to_parquet(buffer, index=False)
    return buffer.getvalue()


@pytest.fixture(scope="module")
def table(synthetic_data_dir, extract_params, workers):
    params = extract_params.model_copy(update=dict(datasets=["arc_a", "line_a"]))
    return E.extract_all(synthetic_data_dir, params, METHODS, workers, progress=False)


def test_one_row_per_frame_and_method_with_the_schema(table):
    assert len(table) == (4 * 2 + 2 * 2) * len(METHODS)
    for column in ["dataset", "trajectory", "stop", "image", "theta_deg", "x_mm", "method", "n_inliers", "n_matches",
                   "inlier_ratio", "reproj_error_px", "inlier_spread_px", "E_t_mm", "E_r_deg", "E_t_exact_mm",
                   "E_r_exact_deg", "status", "reason", "board_status", "world", "consensus_t_mm", "consensus_r_deg",
                   "consensus_elsewhere", "consensus_rerun_t_mm", "stop_spread_t_mm", "stop_spread_r_deg"]:
        assert column in table.columns
    assert set(table["trajectory"]) == {"arc", "line"}
    assert (table["reason"] == "").all()  # nothing flagged in good datasets


def test_accurate_near_the_model_view_and_inliers_fall_with_theta(table):
    arc = table[(table.dataset == "arc_a") & (table.method == "usac_magsac")]
    first = arc[arc.stop == 0]
    assert (first.status == "ok").all() and first.n_inliers.min() > 100
    assert first.E_t_mm.max() < 1.0 and first.E_r_deg.max() < 0.5  # against the ArUco ground truth (IV-C)
    assert first.E_t_exact_mm.max() < 1.5 and first.E_t_board_exact_mm.max() < 1.5  # it is close to the exact pose
    per_stop = arc.groupby("stop").agg(theta=("theta_deg", "mean"), n_i=("n_inliers", "mean"))
    assert spearmanr(per_stop.theta, per_stop.n_i).statistic < -0.9


def test_an_exact_robot_observes_the_error_against_the_placed_board(table, synthetic_data_dir, extract_params):
    """The synthetic robot reports where the camera was: the kinematic disagreement is then exactly the estimate's
    error against the true pose carried by M_t's placement (model image 0's board pose), T_true T_true0^-1 T_anchor
    (no robot in that formula: the frames' true poses instead)."""
    rows = table[(table.dataset == "arc_a") & (table.method == "usac_magsac") & (table.status == "ok")]
    assert len(rows) == 8
    dataset = load_dataset(synthetic_data_dir, "datasets/arc_a")
    _, anchor = dataset_model(dataset, extract_params, synthetic_data_dir / extract_params.features_dir / "arc_a")
    T_true0 = np.asarray(dataset.meta["model"]["exact_T_cam_board"][0])
    truth = dataset.frames.set_index(["stop", "image"]).T_cam_board
    placed = np.stack([np.reshape(truth[(row.stop, row.image)], (4, 4)) @ np.linalg.inv(T_true0) @ anchor.T_cam_board
                       for row in rows.itertuples()])
    E_t, E_r = pose_errors(np.stack([np.reshape(T, (4, 4)) for T in rows.T_cam_board_est]), placed)
    np.testing.assert_allclose(rows.E_t_kinematic_mm, E_t, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(rows.E_r_kinematic_deg, E_r, rtol=1e-5, atol=1e-6)
    assert rows.E_t_kinematic_mm.max() > 1.0  # the far stops' errors are seen


def test_features_evidence_and_model_are_cached_per_image(table, synthetic_data_dir, extract_params):
    cache = synthetic_data_dir / extract_params.features_dir / "arc_a"
    assert len(list((cache / "images").glob("s*_i*[0-9].npz"))) == 8  # SIFT
    assert len(list((cache / "images").glob("*.evidence.npz"))) == 8  # matches to M_t and the ArUco pose
    assert len(list((cache / "images").glob("*.pnp.npz"))) == 8  # every method's PnP result
    assert len(list((cache / "images").glob("*.consensus.npz"))) == 8  # every method's consensus columns
    assert sorted(p.name for p in (cache / "model").glob("*.npz")) == ["0.npz", "1.npz", "M_t.npz"]


def test_a_second_run_reuses_every_frame_evidence_and_gives_the_same_rows(
        table, synthetic_data_dir, extract_params, workers, monkeypatch):
    """Stage 05 on stage 02's frames: no decoding, SIFT, matching or board detection again; a rerun with the same
    methods and settings (after an edit of the package or of ``parallel``) no PnP either; the same values."""
    import poseintegrity.localization.evidence as evidence
    import poseintegrity.localization.consensus as consensus
    import poseintegrity.localization.frame_pnp as frame_pnp

    def never(*args, **kwargs):
        raise AssertionError("recomputed what the evidence cache holds")

    for name in ("decode_gray", "cached_features", "correspondences", "board_pose"):
        monkeypatch.setattr(evidence, name, never)
    monkeypatch.setattr(frame_pnp, "solve_methods", never)
    monkeypatch.setattr(consensus, "_computed", never)
    params = extract_params.model_copy(update=dict(datasets=["arc_a", "line_a"]))
    again = E.extract_all(synthetic_data_dir, params, METHODS, workers, progress=False)
    assert parquet_bytes(again) == parquet_bytes(table)


def test_damaged_cache_files_are_recomputed_said_so_and_none_survives(
        table, synthetic_data_dir, extract_params, workers, tmp_path, capsys):
    """A cut SIFT file behind whole evidence (which alone would not read it), bits flipped in another frame's PnP
    results and in a third's evidence, a stale consensus file and a killed writer's staging file: the rerun names the
    dataset, how many files it recomputed and why, gives the same rows, and leaves every cache file as a clean run
    wrote it."""
    shutil.copytree(synthetic_data_dir / "datasets" / "line_a", tmp_path / "datasets" / "line_a")
    shutil.copytree(synthetic_data_dir / extract_params.features_dir / "line_a",
                    tmp_path / extract_params.features_dir / "line_a")
    images = tmp_path / extract_params.features_dir / "line_a" / "images"
    clean = {path.name: path.read_bytes() for path in images.iterdir()}
    frames = sorted(name.removesuffix(".evidence.npz") for name in clean if name.endswith(".evidence.npz"))
    assert len(frames) >= 4
    cut, flipped, flipped_evidence = (images / f"{frames[0]}.npz", images / f"{frames[1]}.pnp.npz",
                                      images / f"{frames[2]}.evidence.npz")
    cut.write_bytes(clean[cut.name][:len(clean[cut.name]) // 2])
    for path in (flipped, flipped_evidence):
        data = bytearray(clean[path.name])
        data[len(data) // 3: len(data) // 3 + 64] = bytes(b ^ 0x5A for b in data[len(data) // 3: len(data) // 3 + 64])
        path.write_bytes(data)
    old_format = images / f"{frames[3]}.consensus.npz"
    old_format.write_bytes(clean[old_format.name][:-C.TRAILER])  # a whole .npz of the format before trailers
    (images / ".s00_i01.npz.a1b2.partial").write_bytes(b"PK half")
    again = E.extract_dataset(tmp_path, "datasets/line_a", extract_params, METHODS, workers)
    assert parquet_bytes(again) == parquet_bytes(table[table.dataset == "line_a"].reset_index(drop=True))
    said = [line for line in capsys.readouterr().out.splitlines() if line.startswith("cache of")]
    n_checked = 3 + 4 * len(again.drop_duplicates(["stop", "image"]))  # M_t and its 2 SIFT files; 4 files per frame
    assert said == [f"cache of line_a: 4 of {n_checked} cache files recomputed (3 damaged: cut short or altered, "
                    f"1 stale: other inputs, params, code or file format); 1 unfinished write(s) of a stopped run removed",
                    f"cache of 1 dataset(s): 4 of {n_checked} cache files recomputed (3 damaged: cut short or altered, "
                    f"1 stale: other inputs, params, code or file format)"]
    assert {path.name: path.read_bytes() for path in images.iterdir()} == clean  # every file whole, as written clean


def test_consensus_columns_of_posed_frames(table):
    posed = table[table.status == "ok"]
    assert len(posed) == len(table)
    assert (posed[["consensus_t_mm", "consensus_r_deg", "stop_spread_t_mm", "stop_spread_r_deg"]] >= 0).all().all()
    assert posed.consensus_elsewhere.between(0, 1).all()
    near = posed[(posed.dataset == "arc_a") & (posed.stop == 0)]  # a well-posed view: a few tenths of a mm at most
    assert (near.consensus_t_mm < 1.0).all() and (near.consensus_elsewhere == 0).all()


def test_stop_spread_is_the_same_on_every_row_of_a_stop(table):
    per_stop = table.groupby(["dataset", "method", "stop"])[["stop_spread_t_mm", "stop_spread_r_deg"]]
    assert (per_stop.nunique(dropna=False) == 1).all().all()


def test_without_consensus_its_columns_are_nan_and_the_rest_unchanged(table, synthetic_data_dir, extract_params,
                                                                      workers):
    params = extract_params.model_copy(update=dict(datasets=["line_a"]))
    bare = E.extract_all(synthetic_data_dir, params, METHODS, workers, progress=False, consensus=False)
    columns = ["consensus_t_mm", "consensus_r_deg", "consensus_elsewhere", "consensus_rerun_t_mm"]
    assert bare[columns].isna().all().all()
    expected = table[table.dataset == "line_a"].reset_index(drop=True)
    assert parquet_bytes(bare.drop(columns=columns)) == parquet_bytes(expected.drop(columns=columns))


def test_runs_repeat_exactly(table, synthetic_data_dir, extract_params, workers, tmp_path):
    """From scratch (no cache) the rows are those of the cached run."""
    shutil.copytree(synthetic_data_dir / "datasets" / "line_a", tmp_path / "datasets" / "line_a")
    again = E.extract_dataset(tmp_path, "datasets/line_a", extract_params, METHODS, workers, progress=False)
    assert parquet_bytes(again) == parquet_bytes(table[table.dataset == "line_a"].reset_index(drop=True))


def test_envelope_of_the_synthetic_arc(table, protocol):
    env = envelopes(table, protocol.tolerances, protocol.envelope)
    assert len(env) == 2 * len(METHODS) * len(protocol.tolerances) * len(FAILED_FRAME_RULES)
    arc = env[env.dataset == "arc_a"]
    assert ((arc.theta_a > 10.0) & (arc.theta_a <= 55.0)).all()


def test_bad_frames_give_flagged_rows_not_crashes(synthetic_data_dir, extract_params, workers):
    rows = E.extract_dataset(synthetic_data_dir, "datasets/bad", extract_params, METHODS, workers, progress=False)
    by_image = rows[rows.method == "usac_magsac"].set_index("image")
    blank, no_board, few_blobs, text, no_truth = (by_image.loc[i] for i in range(5))
    assert blank.status == "no_keypoints" and blank.n_inliers == 0 and np.isnan(blank.E_t_mm)
    assert blank.board_status == "board_not_detected" and np.isnan(blank.E_t_exact_mm)
    assert no_board.status == "ok" and no_board.E_t_exact_mm < 1.0  # localized, but without ground truth:
    assert no_board.board_status == "board_not_detected" and np.isnan(no_board.E_t_mm)  # no error to average
    assert few_blobs.status == "too_few_matches" and few_blobs.n_inliers == 0 and np.isnan(few_blobs.E_r_deg)
    assert few_blobs.n_keypoints > 0 and few_blobs.n_matches < 4
    assert text.status == "bad_image" and "s00_i03.png" in text.reason and "not a readable image" in text.reason
    assert text.n_inliers == 0 and np.isnan(text.E_t_mm) and text.board_status == "bad_image"
    assert no_truth.status == "bad_pose" and "NaN" in no_truth.reason and np.isnan(no_truth.E_t_mm)
    assert no_truth.n_inliers > 100 and no_truth.board_status == "ok"  # localized: only the exact pose is damaged
    assert set(usable(rows)["image"]) == {0, 1, 2}
    assert (rows.loc[rows.status != "ok", "reason"] != "").all()  # every row without a pose says why
    assert "SIFT found no keypoints" in blank.reason and "matches, a pose needs 4" in few_blobs.reason
    consensus = ["consensus_t_mm", "consensus_r_deg", "consensus_elsewhere", "consensus_rerun_t_mm"]
    assert rows.loc[rows.T_cam_board_est.map(lambda T: np.isnan(T).all()), consensus].isna().all().all()
    assert np.isfinite(no_board[consensus].astype(float)).all()  # a pose without ground truth: its evidence is
    assert no_board.stop_spread_t_mm >= 0  # what needs none (the stop's 2 posed images: its own and no_truth's)


def test_unknown_dataset_in_params_is_named(synthetic_data_dir, extract_params, workers):
    with pytest.raises(DatasetError, match="nope"):
        E.extract_all(synthetic_data_dir, extract_params.model_copy(update=dict(datasets=["nope"])), METHODS, workers)


def test_a_frame_whose_board_is_hidden_is_judged_by_the_handover_board(tmp_path, extract_params, workers):
    """Two boards in the plane; from stop 2 on the dataset's own board is out of the images. Those frames are judged
    by the handover board (truth_board 1, trusted): what it adds to E_t (against the exact motion since model image 0,
    carried to where M_t was placed) is within 3 x its predicted sigma_t; the frames where the own board is seen keep
    it (truth_board 0). Without handover_boards in meta.json the hidden frames are not judged; a handover board with
    the own board's marker ids is refused, naming the key."""

    row = synthetic.write_dataset(tmp_path, "two", np.random.default_rng(21), stops=(5.0, 15.0, 25.0, 35.0),
                                  second_board=True, hidden_from_stop=2)
    synthetic.write_index(tmp_path, [row])
    rows = E.extract_all(tmp_path, extract_params, ["usac_magsac"], workers, progress=False)
    seen, hidden = rows[rows.stop < 2], rows[rows.stop >= 2]
    assert (seen.truth_board == 0).all() and (seen.board_status == "ok").all()
    assert (hidden.truth_board == 1).all() and (hidden.board_status == "ok").all()
    assert (hidden.E_t_truth_mm < 3 * hidden.board_sigma_t_mm).all() and hidden.E_t_mm.notna().all()

    meta_path = tmp_path / "datasets" / "two" / "meta.json"
    meta = json.loads(meta_path.read_text())
    meta_path.write_text(json.dumps(meta | dict(handover_boards=[])))
    alone = E.extract_all(tmp_path, extract_params, ["usac_magsac"], workers, progress=False)
    assert (alone[alone.stop >= 2].board_status != "ok").all() and alone[alone.stop >= 2].E_t_mm.isna().all()
    meta_path.write_text(json.dumps(meta | dict(handover_boards=[synthetic.BOARD])))
    with pytest.raises(DatasetError, match=r"handover_boards\[0\].*overlap"):
        E.extract_all(tmp_path, extract_params, ["usac_magsac"], workers, progress=False)
