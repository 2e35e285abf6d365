"""The lens between radiance and sensor (scenes/optics.py): the thin-lens circle of confusion, and the layered
depth-of-field blur against OpenCV's Gaussian blur where the sigma is one."""

import cv2
import numpy as np
import pytest

from poseintegrity.config import load_params
from poseintegrity.scenes.optics import blur_by_sigma, defocus_sigma_px, lens
from repository import ROOT

CAMERA = load_params(ROOT / "params.yaml").generate.camera.model_copy(
    update={"lens_mm": 12.0, "f_number": 4.0, "pixel_um": 5.86, "downscale": 2})


def test_defocus_is_zero_in_focus_and_follows_the_thin_lens_law():
    assert defocus_sigma_px(220.0, 220.0, CAMERA) == 0.0
    # c = f^2/N |d - d_f| / (d (d_f - f)) = 144/4 * 150 / (370 * 208) mm; sigma = c/2 in half-resolution pixels
    c_mm = 36.0 * 150.0 / (370.0 * 208.0)
    assert defocus_sigma_px(370.0, 220.0, CAMERA) == pytest.approx(0.5 * c_mm / 0.00586 / 2)
    sigmas = defocus_sigma_px(np.array([240.0, 300.0, 370.0, np.inf]), 220.0, CAMERA)
    assert np.all(np.diff(sigmas) > 0)  # farther is blurrier, up to the background at infinity
    assert sigmas[-1] == pytest.approx(0.5 * 36.0 / 208.0 / 0.00586 / 2)  # |d - d_f| / d -> 1


@pytest.mark.parametrize("sigma", [0.05, 0.6, 1.7, 4.0])
def test_one_sigma_everywhere_is_opencvs_gaussian_blur(sigma):
    image = np.random.default_rng(0).random((60, 80)).astype(np.float32)
    blurred = blur_by_sigma(image, np.full(image.shape, sigma, np.float32))
    reference = image if sigma <= 0.1 else cv2.GaussianBlur(image, (0, 0), sigma)
    np.testing.assert_allclose(blurred, reference, atol=1e-6)


def test_each_pixel_takes_its_own_sigma_between_two_rungs():
    """Left half sharp-ish, right half blurred: each half matches OpenCV's blur at its own sigma away from the seam,
    and a pixel between two rungs lies between the two blurs."""
    image = np.random.default_rng(1).random((40, 200)).astype(np.float32)
    sigma = np.where(np.arange(200) < 100, 0.6, 2.5).astype(np.float32)[None, :].repeat(40, 0)
    out = blur_by_sigma(image, sigma)
    np.testing.assert_allclose(out[:, 10:90], cv2.GaussianBlur(image, (0, 0), 0.6)[:, 10:90], atol=1e-5)
    np.testing.assert_allclose(out[:, 110:190], cv2.GaussianBlur(image, (0, 0), 2.5)[:, 110:190], atol=1e-5)
    between = blur_by_sigma(image, np.full(image.shape, 1.0, np.float32))  # 0.6 .. 1.0 .. 2.5: not a rung of this
    low, high = cv2.GaussianBlur(image, (0, 0), 0.9), cv2.GaussianBlur(image, (0, 0), 1.1)
    inside = (between >= np.minimum(low, high) - 1e-3) & (between <= np.maximum(low, high) + 1e-3)
    assert inside.mean() > 0.95


def test_the_lens_blurs_a_far_surface_more_than_the_focused_one():
    image = np.random.default_rng(2).random((50, 100)).astype(np.float32)
    depth = np.where(np.arange(100) < 50, 300.0, 600.0)[None, :].repeat(50, 0)
    out = lens(image, depth, 300.0, 0.6, CAMERA)
    sharp, far = out[:, 5:45] - image[:, 5:45], out[:, 55:95] - image[:, 55:95]
    assert np.abs(far).mean() > 1.5 * np.abs(sharp).mean()
