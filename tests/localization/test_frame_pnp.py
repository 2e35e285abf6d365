"""The per-frame PnP cache (localization/frame_pnp.py): served only under the key of everything that decides a
result, the same results as computing them, what a changed key reaches recomputed, damaged files recomputed, writes
atomic. The end-to-end rerun of stages 02/05 on it: tests/localization/test_extract.py."""

import numpy as np
import pytest

from poseintegrity.localization import frame_pnp as FP
from poseintegrity import cache_entry
from poseintegrity.localization.pnp import solve_checked
from pnp_scenes import K, scene

METHODS = ("usac_magsac", "epnp", "sqpnp", "iterative")
CAPS = {"usac_magsac": 200, "epnp": 150, "sqpnp": 150, "iterative": 150, "p3p": 60}


@pytest.fixture(scope="module")
def frame():
    X, x, _, _ = scene(seed=12, n=80, outlier_fraction=0.5, noise_px=0.4)
    return X, x


def solve(path, frame, params, methods=METHODS, caps=CAPS, seed=4, digest="m" * 40):
    return FP.frame_pnp(path, *frame, K, digest, methods, caps, params, seed)


def assert_same(results, expected):
    assert list(results) == list(expected)
    for method, result in results.items():
        other = expected[method]
        assert (result.status, result.reason, result.n_inliers_reported) == (other.status, other.reason,
                                                                             other.n_inliers_reported), method
        assert np.array_equal(result.T_cam_model, other.T_cam_model, equal_nan=True), method
        assert np.array_equal(result.inliers, other.inliers) and result.inliers.dtype == other.inliers.dtype, method


@pytest.fixture
def computed(monkeypatch):
    """The methods frame_pnp asks solve_methods for, call by call."""
    calls = []
    original = FP.solve_methods
    monkeypatch.setattr(FP, "solve_methods", lambda *args, **kw: calls.append(tuple(args[3])) or original(*args, **kw))
    return calls


def test_cached_results_are_the_computed_ones_and_a_rerun_computes_nothing(tmp_path, frame, extract_params, computed):
    path = tmp_path / "s00_i00.pnp.npz"
    first = solve(path, frame, extract_params)
    expected = {method: solve_checked(*frame, K, method, extract_params.reprojection_threshold_px,
                                      extract_params.ransac_confidence, CAPS[method], 4, extract_params.usac_refine_lm)
                for method in METHODS}
    assert_same(first, expected)
    assert {result.status for result in first.values()} == {"ok"}
    again = solve(path, frame, extract_params)
    assert computed == [METHODS]  # the second call was served from the file
    assert_same(again, expected)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no staging file left


@pytest.mark.parametrize("change, recomputed", [
    (dict(reprojection_threshold_px=0.9), METHODS),
    (dict(ransac_confidence=0.99), METHODS),
    (dict(usac_refine_lm=False), ("usac_magsac",)),  # the classic path refits by itself: its results stay
    (dict(usac_max_iterations=999, ransac_budget_inlier_ratio=0.3), ()),  # caps enter as the caps passed
])
def test_a_changed_setting_recomputes_the_methods_it_decides(tmp_path, frame, extract_params, computed, change,
                                                             recomputed):
    path = tmp_path / "f.pnp.npz"
    solve(path, frame, extract_params)
    solve(path, frame, extract_params.model_copy(update=change))
    assert computed[1:] == ([recomputed] if recomputed else [])


@pytest.mark.parametrize("argument, value, recomputed", [
    ("seed", 5, METHODS),
    ("digest", "n" * 40, METHODS),
    ("caps", CAPS | {"epnp": 151}, ("epnp",)),
    ("methods", METHODS + ("p3p",), ("p3p",)),  # only the new method, the others stay in the file
])
def test_a_changed_argument_recomputes_what_it_reaches(tmp_path, frame, extract_params, computed, argument, value,
                                                       recomputed):
    path = tmp_path / "f.pnp.npz"
    solve(path, frame, extract_params)
    solve(path, frame, extract_params, **{argument: value})
    assert computed[1:] == [recomputed]
    solve(path, frame, extract_params)  # the file still holds every method of the first call, unless recomputed
    assert computed[2:] == ([] if argument == "methods" else [recomputed])


def test_changed_correspondences_camera_or_library_recompute(tmp_path, frame, extract_params, computed, monkeypatch):
    path = tmp_path / "f.pnp.npz"
    X, x = frame
    solve(path, frame, extract_params)
    moved = x.copy()
    moved[0, 0] = np.nextafter(moved[0, 0], np.inf)  # one coordinate, one ulp
    solve(path, (X, moved), extract_params)
    assert computed[1:] == [METHODS]
    FP.frame_pnp(path, X, moved, K * [[1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.0, 0.0, 1.0]] + 0.0, "m" * 40, METHODS,
                 CAPS, extract_params, 4)
    assert len(computed) == 2  # the same K, rebuilt: served
    K_other = K.copy()
    K_other[0, 2] += 1e-9
    FP.frame_pnp(path, X, moved, K_other, "m" * 40, METHODS, CAPS, extract_params, 4)
    assert computed[2:] == [METHODS]
    monkeypatch.setattr(cache_entry, "provenance", lambda: "another OpenCV")  # other code computes it
    solve(path, (X, moved), extract_params)
    assert computed[3:] == [METHODS]


@pytest.mark.parametrize("damage", ["truncated", "not an npz", "foreign arrays", "empty"])
def test_a_damaged_file_is_recomputed_not_an_error(tmp_path, frame, extract_params, computed, damage):
    path = tmp_path / "f.pnp.npz"
    first = solve(path, frame, extract_params)
    if damage == "truncated":
        path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    elif damage == "not an npz":
        path.write_text("not an npz")
    elif damage == "foreign arrays":  # the right keys beside a pose array of another shape
        arrays = cache_entry.read_entry(path, FP.FILE_KEY)
        cache_entry.write_entry(path, FP.FILE_KEY, arrays | {"T_cam_model": arrays["T_cam_model"][:, :3]})
    else:
        path.write_bytes(b"")
    again = solve(path, frame, extract_params)
    assert_same(again, first)
    assert computed[1:] == [METHODS]
    assert_same(solve(path, frame, extract_params), first)  # rewritten whole
    assert len(computed) == 2
