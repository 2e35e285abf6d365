import numpy as np

from poseintegrity.tracking.markers.summation import numpy_sum


def test_the_sum_of_squares_is_numpys_for_long_bodies():
    """Alg. 3's error is summed as numpy sums (pairwise beyond 8 terms, in halves beyond 128)."""
    rng = np.random.default_rng(4)
    for n in (0, 1, 7, 8, 9, 16, 17, 127, 128, 129, 300, 1025, 5000):
        a = rng.random(n) ** 4
        assert numpy_sum(a) == a.sum()
