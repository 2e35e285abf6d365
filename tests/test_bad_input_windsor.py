"""Bad input never crashes raw or lies (localization, artifact models, prediction, CLIs): each class of bad input
gives a PoseIntegrityError naming the thing, or a flagged result, and valid input the same result as before."""

import json
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

sys.path.insert(0, str(Path(__file__).parent / "localization"))
import loc_synthetic as synthetic  # noqa: E402

from poseintegrity.artifact_models.base_functions import LEAST_SQUARES  # noqa: E402
from poseintegrity.artifact_models.fitted import valid_samples  # noqa: E402
from poseintegrity.boards import board_from_dict  # noqa: E402
from poseintegrity.dataset_meta import BoardMeta  # noqa: E402
from poseintegrity.errors import PoseIntegrityError  # noqa: E402
from poseintegrity.lens import Camera  # noqa: E402
from poseintegrity.localization import envelope as envelope_module  # noqa: E402
from poseintegrity.localization.features import ImageReadError, as_gray8, read_gray  # noqa: E402
from poseintegrity.localization.ground_truth import board_pose  # noqa: E402
from poseintegrity.localization.pnp import solve_pnp_ransac  # noqa: E402
from poseintegrity.localization.target_model import triangulate  # noqa: E402
from poseintegrity.poses import pose_errors  # noqa: E402
from poseintegrity.prediction.metrics import incursion, safe_path_length  # noqa: E402
from poseintegrity.prediction.predictors import boundaries, next_step_stops, sampling_interval  # noqa: E402
from poseintegrity.stage_timing import StageTiming  # noqa: E402
from poseintegrity.table_checks import check_artifacts, check_envelopes, read_envelopes  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def image():
    plane, _ = synthetic.canvas(np.random.default_rng(0))
    return synthetic.render(plane, synthetic.arc_pose(0.0, 0.0))


# --- intrinsics ---------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("K", [np.zeros((3, 3)), np.full((3, 3), np.nan), np.diag([0.0, 600.0, 1.0]),
                               np.diag([1e300, 1e300, 1.0])])
def test_bad_intrinsics_are_refused_naming_K(K):
    with pytest.raises(PoseIntegrityError, match=r"Camera\.K"):
        Camera(K, np.zeros(5), *synthetic.IMAGE_SIZE)
    X, x = np.random.default_rng(1).uniform(0, 50, (10, 3)), np.random.default_rng(2).uniform(0, 500, (10, 2))
    with pytest.raises(PoseIntegrityError, match=r"^K: "):
        solve_pnp_ransac(X, x, K, "usac_magsac", 2.0, 0.99, 100, 0, True)
    with pytest.raises(PoseIntegrityError, match=r"^K: "):
        triangulate(K, np.eye(4), x, x)


def test_bad_distortion_and_size_are_refused():
    with pytest.raises(PoseIntegrityError, match=r"Camera\.dist"):
        Camera(synthetic.K, np.full(5, np.nan), *synthetic.IMAGE_SIZE)
    with pytest.raises(PoseIntegrityError, match=r"Camera\.width"):
        Camera(synthetic.K, np.zeros(5), 0, 400)


def test_valid_board_pose_is_unchanged(image):
    pose = board_pose(image, synthetic.BOARD, synthetic.CAMERA, synthetic.CHECKS)
    assert pose.status == "ok"
    E_t, E_r = pose_errors(pose.T_cam_board, synthetic.arc_pose(0.0, 0.0))
    assert E_t < 1.0 and E_r < 0.5


# --- images -------------------------------------------------------------------------------------------------------
def test_colour_and_16_bit_images_are_converted_as_documented(image):
    board = synthetic.BOARD
    assert as_gray8("image", image) is image  # the pipeline's own images: untouched
    colour = np.dstack([image] * 3)
    np.testing.assert_array_equal(as_gray8("image", colour), image)
    np.testing.assert_array_equal(as_gray8("image", image.astype(np.uint16) * 257), image)
    assert board_pose(image.astype(np.uint16) * 257, board, synthetic.CAMERA, synthetic.CHECKS).status == "ok"


@pytest.mark.parametrize(("bad", "words"), [
    (None, "expected an image array"), (np.zeros((0, 0), np.uint8), "non-empty"),
    (np.full((40, 60), np.nan, np.float32), "float32 image holding NaN"), (np.zeros((40, 60)), "float64"),
    (np.zeros((40, 60, 2), np.uint8), r"shape \(40, 60, 2\)"), (np.zeros((40, 60), np.int32), "int32"),
])
def test_unusable_images_are_refused_naming_argument_shape_dtype(bad, words, image):
    with pytest.raises(PoseIntegrityError, match=rf"^image: .*{words}"):
        as_gray8("image", bad)
    with pytest.raises(PoseIntegrityError, match=rf"^image: .*{words}"):
        board_pose(bad, synthetic.BOARD, synthetic.CAMERA)


@pytest.mark.parametrize("damage", ["empty", "truncated", "junk", "missing"])
def test_damaged_image_files_name_the_file(tmp_path, image, damage):
    cv2.imwrite(str(tmp_path / "ok.png"), image)
    data = (tmp_path / "ok.png").read_bytes()
    path = tmp_path / "bad.png"
    if damage != "missing":
        path.write_bytes({"empty": b"", "truncated": data[: len(data) // 2], "junk": b"not a png"}[damage])
    with pytest.raises(ImageReadError, match=str(path)):
        read_gray(path)


# --- readers ------------------------------------------------------------------------------------------------------
def test_unknown_aruco_dictionary_is_refused_on_read():
    with pytest.raises(Exception, match="unknown ArUco dictionary 'DICT_9X9_1'"):
        BoardMeta.model_validate(dict(synthetic.BOARD, dictionary="DICT_9X9_1"))
    with pytest.raises(PoseIntegrityError, match="board.dictionary"):
        board_from_dict(dict(synthetic.BOARD, dictionary="DICT_9X9_1"))
    with pytest.raises(Exception, match="do not fit DICT_4X4_50"):
        BoardMeta.model_validate(dict(synthetic.BOARD, first_id=48))


@pytest.mark.parametrize(("content", "words"), [
    ("{corrupt", "not valid JSON"), ('{"stage": "x"}', r"field\(s\) \['wall_time_s'"),
    ('{"stage": "x", "wall_time_s": "fast", "backend": "local", "n_jobs": 1, "address": null, '
     '"finished_at": "2025-01-01T00:00:00"}', "field wall_time_s has the wrong type"),
])
def test_timing_cli_says_one_line_and_exits_2(tmp_path, content, words):
    (tmp_path / "02_extract.json").write_text(content)
    run = subprocess.run([sys.executable, "-m", "poseintegrity.stage_timing", str(tmp_path)], capture_output=True,
                         text=True, env={"PYTHONPATH": str(ROOT / "src")})
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and str(tmp_path / "02_extract.json") in run.stderr
    assert __import__("re").search(words, run.stderr)


def test_timing_files_still_round_trip(tmp_path):
    record = StageTiming("02_x", 12.5, "local", 2, None, "2025-11-23T14:02:00")
    record.write(tmp_path / "02_x.json")
    assert StageTiming.read(tmp_path / "02_x.json") == record


def test_stage_cli_on_a_missing_notebook_says_one_line_and_exits_2(tmp_path):
    run = subprocess.run([sys.executable, "-m", "poseintegrity.stage", str(tmp_path / "nope.ipynb")],
                         capture_output=True, text=True, env={"PYTHONPATH": str(ROOT / "src")})
    assert run.returncode == 2 and run.stderr.strip() == f"{tmp_path / 'nope.ipynb'}: no such notebook"


# --- stage tables -------------------------------------------------------------------------------------------------
def _artifacts() -> pd.DataFrame:
    stops = np.repeat(np.arange(4), 2)
    return pd.DataFrame(dict(world="main", dataset="arc_00", trajectory="arc", stop=stops, image=np.tile([0, 1], 4),
                             theta_deg=stops * 5.0, x_mm=0.0, method="usac_magsac", status="ok",
                             n_inliers=100 - 20 * stops, E_t_mm=0.5 + stops, E_r_deg=0.1 * stops))


def _envelopes() -> pd.DataFrame:
    return pd.DataFrame(dict(world="main", dataset=["arc_00", "arc_01"], trajectory="arc", tolerance="2mm_3deg",
                             method="usac_magsac", rule="fail_fraction", theta_a=[7.5, 10.0], censored=False))


@pytest.mark.parametrize(("spoil", "words"), [
    (lambda t: pd.concat([t, t.iloc[[3]]]), r"2 rows repeat a key .*dataset arc_00 \(stop 1, image 1"),
    (lambda t: t.iloc[:0], "has no rows"),
    (lambda t: t.drop(columns="E_t_mm"), r"lacks columns \['E_t_mm'\]"),
    (lambda t: t.assign(stop=t.stop.astype(float)), "column stop must hold integers"),
    (lambda t: t.assign(E_t_mm=-t.E_t_mm), "below 0 E_t_mm"),
    (lambda t: t.assign(consensus_t_mm=-1.0), "below 0 consensus_t_mm"),  # checked where present (stage 02's)
    (lambda t: t.assign(stop_spread_r_deg=np.inf), "non-finite stop_spread_r_deg"),
    (lambda t: t.assign(x_mm=t.x_mm.astype(object).where(t.index != 3, "20.0 mm")),
     r"column x_mm must hold numbers, got dtype object: '20.0 mm' in dataset arc_00 \(stop 1, image 1"),
])
def test_spoiled_artifacts_tables_are_refused_naming_table_and_row(spoil, words):
    assert check_artifacts(_artifacts()) is not None  # the valid table passes
    with pytest.raises(PoseIntegrityError, match=rf"^the artifacts table: .*{words}"):
        check_artifacts(spoil(_artifacts()))


def test_spoiled_envelopes_are_refused_and_expected_datasets_checked(tmp_path):
    check_envelopes(_envelopes(), datasets=["arc_00", "arc_01"])
    with pytest.raises(PoseIntegrityError, match=r"repeat a key"):
        check_envelopes(pd.concat([_envelopes(), _envelopes().iloc[[0]]]))
    with pytest.raises(PoseIntegrityError, match=r"dataset\(s\) \['arc_02'\] missing"):
        check_envelopes(_envelopes(), datasets=["arc_00", "arc_02"])
    with pytest.raises(PoseIntegrityError, match=r"dataset arc_01 .*non-finite theta_a nan"):
        check_envelopes(_envelopes().assign(theta_a=[7.5, np.nan]))
    with pytest.raises(PoseIntegrityError, match=str(tmp_path / "envelopes.parquet")):
        read_envelopes(tmp_path / "envelopes.parquet")
    _envelopes().to_parquet(tmp_path / "envelopes.parquet")
    pd.testing.assert_frame_equal(read_envelopes(tmp_path / "envelopes.parquet"), _envelopes())


# --- envelopes ----------------------------------------------------------------------------------------------------
THETA = np.array([0.0, 5.0, 10.0, 15.0])
CRITERIA = np.array([[0.5, 0.5], [1.0, 1.0], [3.0, 1.0], [9.0, 9.0]])
BOUNDS = np.array([2.0, 3.0])


def test_valid_envelope_is_unchanged():
    assert envelope_module.actual_envelope(THETA, CRITERIA, BOUNDS)[:3] == (7.5, False, ())


@pytest.mark.parametrize(("theta", "criteria", "words"), [
    (np.array([0.0, np.nan, 10.0, 15.0]), CRITERIA, "^theta: entries must be finite"),
    (THETA[::-1], CRITERIA, "^theta: must increase"),
    (THETA[:3], CRITERIA, "lengths must agree: theta 3, criteria 4"),
    (THETA[:0], CRITERIA[:0], "^theta: needs at least one stop"),
])
def test_bad_stops_are_refused_naming_the_argument(theta, criteria, words):
    with pytest.raises(PoseIntegrityError, match=words):
        envelope_module.actual_envelope(theta, criteria, BOUNDS)


def test_unmeasured_errors_are_flagged_not_read_as_within_tolerance():
    nothing = np.full((4, 2), np.nan)
    theta_a, censored, unmeasured, _ = envelope_module.actual_envelope(THETA, nothing, BOUNDS)
    assert np.isnan(theta_a) and not censored and unmeasured == tuple(THETA)
    failed_at_once = np.column_stack([nothing, np.ones(4)])  # no pose anywhere: fails at the first stop, known
    assert envelope_module.actual_envelope(THETA, failed_at_once, np.append(BOUNDS, 0.5))[:3] == (0.0, False, ())
    frames = _artifacts().assign(E_t_mm=np.nan, E_r_deg=np.nan)
    from poseintegrity.params.protocol import EnvelopeParams
    params = EnvelopeParams.model_validate(dict(failed_frames="fail_fraction", cap_factor=2.0, max_failed_fraction=0.5))
    with pytest.warns(UserWarning, match=r"arc_00.*NaN: not measured up to their end"):
        table = envelope_module.envelopes(frames, [(2.0, 3.0)], params)
    assert table.theta_a.isna().all() and not table.censored.any() and set(table.status) == {"not_measured"}


# --- fits ---------------------------------------------------------------------------------------------------------
TH = np.repeat([0.0, 5.0, 10.0, 15.0], 3)
N = np.repeat([100.0, 80.0, 50.0, 20.0], 3) + np.tile([-2.0, 0.0, 2.0], 4)


@pytest.mark.parametrize(("theta_end", "words"), [(np.nan, "^theta_end: expected a finite number"),
                                                  (-5.0, "^theta_end: the range end -5 lies before")])
def test_bad_theta_end_is_refused(theta_end, words):
    with pytest.raises(PoseIntegrityError, match=words):
        LEAST_SQUARES["emg"].fit(TH, N, theta_end=theta_end, max_nfev=2000)


def test_a_fit_that_does_not_follow_its_samples_is_flagged_and_a_good_one_is_not():
    rising = np.repeat([10.0, 40.0, 80.0, 150.0], 3)
    poor = LEAST_SQUARES["power_law"].fit(TH, rising, theta_end=45.0, max_nfev=2000)
    assert poor.status == "non_physical" and "lack of fit" in poor.reason
    good = LEAST_SQUARES["emg"].fit(TH, N, theta_end=45.0, max_nfev=2000)
    assert "lack of fit" not in good.reason


def test_mismatched_samples_are_refused():
    with pytest.raises(PoseIntegrityError, match="differ in length"):
        valid_samples(TH, N[:3])


# --- predictors and metrics ---------------------------------------------------------------------------------------
def line(theta):
    return 100.0 - 2.0 * np.asarray(theta)


@pytest.mark.parametrize("n_grid", [0, 1, 2.5, True])
def test_a_grid_of_fewer_than_2_points_is_refused(n_grid):
    with pytest.raises(PoseIntegrityError, match="^n_grid: "):
        boundaries(line, np.array([50.0]), 0.0, 45.0, n_grid)


def test_boundaries_refuse_a_nan_range_and_keep_valid_answers():
    with pytest.raises(PoseIntegrityError, match="^theta_start: "):
        boundaries(line, np.array([50.0]), np.nan, 45.0, 100)
    found = boundaries(line, np.array([50.0, np.nan]), 0.0, 45.0, 100)
    assert found.theta_p[0] == pytest.approx(25.0) and list(found.status) == ["root", "bad_threshold"]


def test_unknown_theta_a_gives_no_incursion_value():
    assert np.isnan(incursion(np.array([10.0]), np.array([np.nan]))[0])
    np.testing.assert_array_equal(incursion(np.array([10.0, 5.0, np.nan]), np.array([8.0, 8.0, 8.0])), [1.0, 0.0, np.nan])
    with pytest.raises(PoseIntegrityError, match="theta_p 3, theta_a 2"):
        safe_path_length(np.ones(3), np.ones(2))


def test_next_step_arguments_are_checked():
    with pytest.raises(PoseIntegrityError, match="^theta_b: "):
        next_step_stops(np.array([10.0]), 0.0, np.nan)
    with pytest.raises(PoseIntegrityError, match="^theta_stops: a sampling interval needs at least 2"):
        sampling_interval(np.array([0.0]))
    with pytest.raises(PoseIntegrityError, match="^theta_stops: must increase"):
        sampling_interval(np.array([0.0, 5.0, 4.0]))
    assert sampling_interval(np.array([0.0, 2.25, 4.5])) == 2.25


def test_check_meta_of_stage_01_refuses_what_stage_02_would():
    from poseintegrity.scenes.dataset_files import check_meta
    meta = json.loads(json.dumps(dict(dataset="d", world="main", trajectory="arc", board=synthetic.BOARD,
                                      model=dict(images=["a.png", "b.png"], masks=["c.png", "d.png"],
                                                 T_cam1_cam0=np.eye(4).tolist()))))
    check_meta(meta, "d")
    meta["board"]["dictionary"] = "DICT_9X9_1"
    with pytest.raises(PoseIntegrityError, match="(?s)dataset d: .*board.dictionary"):
        check_meta(meta, "d")
