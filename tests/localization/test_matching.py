import cv2
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from poseintegrity.localization.matching import match_ratio_test


def bf_reference(query, train, ratio):
    """OpenCV's brute-force matcher with the textbook ratio test."""
    knn = cv2.BFMatcher(cv2.NORM_L2).knnMatch(query, train, k=2)
    return sorted((a.queryIdx, a.trainIdx) for a, b in knn if a.distance < ratio * b.distance)


@settings(deadline=None, max_examples=30)
@given(n=st.integers(1, 60), m=st.integers(2, 60), ratio=st.floats(0.5, 0.95), seed=st.integers(0, 2**32 - 1))
def test_matches_equal_opencv_brute_force(n, m, ratio, seed):
    rng = np.random.default_rng(seed)
    train = rng.integers(0, 256, (m, 128)).astype(np.float32)
    # half of the queries are noisy copies of train rows, so that the ratio test passes for some
    query = rng.integers(0, 256, (n, 128)).astype(np.float32)
    copies = rng.integers(0, m, n // 2)
    query[: n // 2] = train[copies] + rng.normal(0, 5, (n // 2, 128)).astype(np.float32)
    ours = sorted(map(tuple, match_ratio_test(query, train, ratio).tolist()))
    assert ours == bf_reference(query, train, ratio)


def test_empty_inputs_give_no_matches():
    descriptors = np.ones((5, 128), np.float32)
    assert match_ratio_test(np.empty((0, 128), np.float32), descriptors, 0.8).shape == (0, 2)
    assert match_ratio_test(descriptors, descriptors[:1], 0.8).shape == (0, 2)
