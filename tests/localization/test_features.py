import cv2
import numpy as np
import pytest

import loc_synthetic as synthetic
from poseintegrity.localization import features as F
from poseintegrity.localization.params import ClaheParams, SiftParams

CLAHE, SIFT = ClaheParams(), SiftParams()


@pytest.fixture(scope="module")
def image():
    return synthetic.texture(np.random.default_rng(0), (240, 320))


def test_features_equal_opencv_sift_on_the_clahe_image(image):
    """Reference: float SIFT of OpenCV on cv2.createCLAHE output; our uint8 storage is lossless."""
    equalized = cv2.createCLAHE(clipLimit=2.0, tileGridSize=(8, 8)).apply(image)
    keypoints, descriptors = cv2.SIFT_create().detectAndCompute(equalized, None)
    ours = F.detect_features(image, CLAHE, SIFT)
    np.testing.assert_allclose(ours.points, [k.pt for k in keypoints])
    np.testing.assert_array_equal(ours.descriptors, descriptors)
    assert ours.n_keypoints > 100


def test_blank_image_has_no_keypoints():
    features = F.detect_features(np.full((100, 100), 90, np.uint8), CLAHE, SIFT)
    assert features.points.shape == (0, 2) and features.descriptors.shape == (0, 128)


def test_cache_is_reused_and_invalidated_by_settings_and_image(tmp_path, image, monkeypatch):
    path, cache = tmp_path / "frame.png", tmp_path / "cache" / "frame.npz"
    cv2.imwrite(str(path), image)
    first = F.cached_features(path, cache, CLAHE, SIFT)
    calls = []
    original = F.detect_features
    monkeypatch.setattr(F, "detect_features", lambda *a: calls.append(1) or original(*a))
    again = F.cached_features(path, cache, CLAHE, SIFT)
    assert calls == []  # served from the cache
    np.testing.assert_array_equal(again.descriptors, first.descriptors)
    fewer = F.cached_features(path, cache, CLAHE, SiftParams(contrast_threshold=0.08))
    assert calls == [1] and fewer.n_keypoints < first.n_keypoints  # a SIFT setting changed
    F.cached_features(path, cache, ClaheParams(clip_limit=4.0), SiftParams(contrast_threshold=0.08))
    assert calls == [1, 1]  # a CLAHE setting changed
    cv2.imwrite(str(path), np.fliplr(image))
    F.cached_features(path, cache, ClaheParams(clip_limit=4.0), SiftParams(contrast_threshold=0.08))
    assert calls == [1, 1, 1]  # the image changed


def test_missing_and_unreadable_files_name_the_file(tmp_path):
    with pytest.raises(F.ImageReadError, match="nowhere.png"):
        F.cached_features(tmp_path / "nowhere.png", tmp_path / "c.npz", CLAHE, SIFT)
    broken = tmp_path / "broken.png"
    broken.write_bytes(b"not a png at all")
    with pytest.raises(F.ImageReadError, match="broken.png"):
        F.read_gray(broken)
