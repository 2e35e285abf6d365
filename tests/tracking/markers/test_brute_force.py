import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from poseintegrity.tracking.markers.brute_force import match_brute_force

from tracking.marker_scenes import scene
from tracking.track_section import GEOMETRY, TRACK


@settings(deadline=None, max_examples=40)
@given(seed=st.integers(0, 2**32 - 1), n_missing=st.integers(0, 1), n_phantoms=st.integers(0, 2))
def test_brute_force_alone_recovers_the_correspondence(seed, n_missing, n_phantoms):
    points, truth, _ = scene(seed, n_missing, n_phantoms, noise=0.0002)  # 0.2 mm: see marker_scenes.scene
    np.testing.assert_array_equal(match_brute_force(points, GEOMETRY, tolerance_m=TRACK.matching.tolerance_m, min_markers=3), truth)
