"""The images of a shot as written (scenes/shots.py): the PNG encoder settings are lossless."""

import cv2
import numpy as np
import pytest

from poseintegrity.config import load_params
from poseintegrity.scenes import renderer, shots
from repository import ROOT

TINY = load_params(ROOT / "tests" / "params_tiny.yaml")


@pytest.mark.parametrize("flags", ["IMAGE_PNG_FLAGS", "MASK_PNG_FLAGS"])
def test_png_files_hold_exactly_the_pixels_exposed(tmp_path, flags):
    """The encoder settings are lossless on a noisy camera image and a flat mask, whatever they compress."""
    folder = shots.partial_dataset(tmp_path, "d")
    folder.mkdir()
    noisy = renderer.expose(np.full((64, 96), 0.6, np.float32), TINY.generate.sensor, np.random.default_rng(0))
    mask = np.zeros((64, 96), np.uint8)
    mask[10:40, 20:70] = 255
    for name, image in (("noisy.png", noisy), ("mask.png", mask)):
        shots._write_png(tmp_path, ("d",), name, image, getattr(shots, flags))
        assert (cv2.imread(str(folder / name), cv2.IMREAD_UNCHANGED) == image).all()
