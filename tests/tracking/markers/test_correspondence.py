import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from poseintegrity.tracking.markers.brute_force import match_brute_force
from poseintegrity.tracking.markers.correspondence import match_markers
from poseintegrity.tracking.markers.frobenius import match_frobenius
from poseintegrity.tracking.markers.gated import match_gated
from poseintegrity.tracking.markers.voting import match_voting

from tracking.marker_scenes import scene, small_motion
from tracking.track_section import GEOMETRY, TRACK

G = GEOMETRY
MATCHING = TRACK.matching
TOL = MATCHING.tolerance_m


@settings(deadline=None, max_examples=50)
@given(seed=st.integers(0, 2**32 - 1), n_missing=st.integers(0, 1), n_phantoms=st.integers(0, 3))
def test_match_markers_finds_the_true_correspondence(seed, n_missing, n_phantoms):
    points, truth, _ = scene(seed, n_missing, n_phantoms, noise=0.0002)  # 0.2 mm: see marker_scenes.scene
    np.testing.assert_array_equal(match_markers(points, G, None, MATCHING), truth)


@settings(deadline=None, max_examples=50)
@given(seed=st.integers(0, 2**32 - 1), n_missing=st.integers(0, 1), n_phantoms=st.integers(0, 2))
def test_match_markers_follows_a_small_motion_among_phantoms(seed, n_missing, n_phantoms):
    _, previous, with_phantoms, truth = small_motion(seed, n_missing, n_phantoms)
    np.testing.assert_array_equal(match_markers(with_phantoms, G, previous, MATCHING), truth)


@settings(deadline=None, max_examples=30)
@given(points=st.lists(st.tuples(*[st.floats(-1, 1)] * 3), min_size=0, max_size=7), seed=st.integers(0, 1000))
def test_every_matcher_survives_arbitrary_points(points, seed):
    points = np.array(points, dtype=float).reshape(-1, 3)
    if len(points):
        points[np.random.default_rng(seed).random(len(points)) < 0.2] = np.nan
    previous = G + [0.0, 0.0, 0.5]
    for assignment in [
        match_markers(points, G, None, MATCHING),
        match_markers(points, G, previous, MATCHING),
        match_voting(points, G, tolerance_m=TOL)[0],
        match_brute_force(points, G, tolerance_m=TOL, min_markers=3),
        match_frobenius(points, previous),
        match_gated(points, previous, gate_m=MATCHING.gate_m),
    ]:
        assert assignment.shape == (4,) and assignment.dtype.kind == "i"
        used = assignment[assignment >= 0]
        assert len(set(used)) == len(used) and np.all(used < len(points))
        assert np.all(np.isfinite(points[used]))


def test_too_few_points_only_phantoms_and_duplicates():
    assert (match_markers(np.zeros((0, 3)), G, None, MATCHING) == -1).all()
    assert (match_markers(G[:2] + 0.5, G, None, MATCHING) == -1).all()  # two points: no unique match without a prediction
    assert (match_markers(np.random.default_rng(0).uniform(-1, 1, (5, 3)), G, None, MATCHING) == -1).all()  # only phantoms
    duplicated = np.vstack([G, G[:1]]) + [0, 0, 0.5]
    assignment = match_markers(duplicated, G, None, MATCHING)
    assert assignment[0] in (0, 4) and list(assignment[1:]) == [1, 2, 3]
