import cv2
import numpy as np
import pytest

import loc_synthetic as synthetic
from poseintegrity.localization import features as F


@pytest.fixture(scope="module")
def image():
    return synthetic.texture(np.random.default_rng(0), (240, 320))


@pytest.fixture(scope="module")
def settings(extract_params):
    """CLAHE and SIFT settings of the tiny parameters (params.yaml's)."""
    return extract_params.clahe, extract_params.sift


def test_features_equal_opencv_sift_on_the_clahe_image(image, settings):
    """Reference: float SIFT of OpenCV on cv2.createCLAHE output; our uint8 storage is lossless."""
    clahe, sift = settings
    grid = (clahe.tile_grid, clahe.tile_grid)
    equalized = cv2.createCLAHE(clipLimit=clahe.clip_limit, tileGridSize=grid).apply(image)
    detector = cv2.SIFT_create(sift.n_features, sift.n_octave_layers, sift.contrast_threshold, sift.edge_threshold,
                               sift.sigma)
    keypoints, descriptors = detector.detectAndCompute(equalized, None)
    ours = F.detect_features(image, clahe, sift)
    np.testing.assert_allclose(ours.points, [keypoint.pt for keypoint in keypoints])
    np.testing.assert_array_equal(ours.descriptors, descriptors)
    assert ours.n_keypoints > 100


def test_blank_image_has_no_keypoints(settings):
    features = F.detect_features(np.full((100, 100), 90, np.uint8), *settings)
    assert features.points.shape == (0, 2) and features.descriptors.shape == (0, 128)


def test_cache_is_reused_and_invalidated_by_settings_and_image(tmp_path, image, settings, monkeypatch):
    clahe, sift = settings
    path, cache = tmp_path / "frame.png", tmp_path / "cache" / "frame.npz"
    cv2.imwrite(str(path), image)
    first = F.cached_features(path, cache, clahe, sift)
    calls = []
    original = F.detect_features
    monkeypatch.setattr(F, "detect_features", lambda *a: calls.append(1) or original(*a))
    again = F.cached_features(path, cache, clahe, sift)
    assert calls == []  # served from the cache
    np.testing.assert_array_equal(again.descriptors, first.descriptors)
    stricter = sift.model_copy(update=dict(contrast_threshold=2 * sift.contrast_threshold))
    fewer = F.cached_features(path, cache, clahe, stricter)
    assert calls == [1] and fewer.n_keypoints < first.n_keypoints  # a SIFT setting changed
    stronger = clahe.model_copy(update=dict(clip_limit=2 * clahe.clip_limit))
    F.cached_features(path, cache, stronger, stricter)
    assert calls == [1, 1]  # a CLAHE setting changed
    cv2.imwrite(str(path), np.fliplr(image))
    F.cached_features(path, cache, stronger, stricter)
    assert calls == [1, 1, 1]  # the image changed


def test_missing_and_unreadable_files_name_the_file(tmp_path, settings):
    with pytest.raises(F.ImageReadError, match="nowhere.png"):
        F.cached_features(tmp_path / "nowhere.png", tmp_path / "c.npz", *settings)
    broken = tmp_path / "broken.png"
    broken.write_bytes(b"not a png at all")
    with pytest.raises(F.ImageReadError, match="broken.png"):
        F.read_gray(broken)


@pytest.mark.parametrize("stored, size, message", [
    (np.zeros((40, 60), np.uint16), None, "16-bit with 1 channel"),
    (np.zeros((40, 60, 3), np.uint8), None, "8-bit with 3 channel"),
    (np.zeros((40, 60), np.uint8), (120, 80), "60 x 40 px, its dataset's camera.yaml says 120 x 80"),
])
def test_images_are_read_as_stored_never_converted(tmp_path, stored, size, message):
    """IMREAD_GRAYSCALE would quietly turn these into plausible 8-bit images of another size or content."""
    path = tmp_path / "frame.png"
    cv2.imwrite(str(path), stored)
    with pytest.raises(F.ImageReadError, match=message):
        F.read_gray(path, size)
