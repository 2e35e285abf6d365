import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from poseintegrity.tracking.markers.frobenius import match_frobenius

from tracking.marker_scenes import small_motion


@settings(deadline=None, max_examples=50)
@given(seed=st.integers(0, 2**32 - 1), n_missing=st.integers(0, 1))
def test_frobenius_follows_a_small_motion(seed, n_missing):
    points, previous, _, truth = small_motion(seed, n_missing, 0)
    np.testing.assert_array_equal(match_frobenius(points, previous), truth)  # Alg. 1 with a missing marker
