"""The one conversion of an image array to what OpenCV's CLAHE, SIFT and ArUco detector take: 8-bit single-channel.

Shared by the localization pipeline (features, board pose) and the recorded-data reader, which converts each
recorded image once with it; a module of its own so that reading recordings does not import the pipeline's params.
"""

from __future__ import annotations

import cv2
import numpy as np

from poseintegrity.errors import ArgumentError, check_image


def as_gray8(name: str, image: object) -> np.ndarray:
    """``image`` as the 8-bit single-channel (h, w) array OpenCV's CLAHE, SIFT and ArUco detector take, checked once.

    Accepted unchanged: (h, w) uint8 (the images stage 01 writes). Converted (documented, the way OpenCV reads such
    files): (h, w, 1) -> (h, w); colour (h, w, 3) BGR or (h, w, 4) BGRA -> gray by ``cv2.cvtColor`` (OpenCV's
    0.299 R + 0.587 G + 0.114 B); uint16 -> uint8 by keeping the high byte (value // 256, as ``cv2.imread`` with
    IMREAD_GRAYSCALE does). Refused with :class:`~poseintegrity.errors.ArgumentError` naming ``name``, the shape and
    dtype: None or a non-array, an empty image, other channel counts, float images (NaN-holding or not: their
    scale, 0..1 or 0..255, is not known) and any other dtype.
    """
    if isinstance(image, np.ndarray) and image.dtype == np.uint8 and image.ndim == 2 and image.size:
        return image  # the pipeline's own images: no copy, no conversion
    if isinstance(image, np.ndarray) and image.dtype.kind == "f":
        nan = " holding NaN" if image.size and np.isnan(image).any() else ""
        raise ArgumentError(f"{name}: expected an 8-bit (uint8) or 16-bit (uint16) image, got a {image.dtype} "
                            f"image{nan} of shape {image.shape} (convert it to uint8 0..255 first)")
    image = check_image(name, image, channels=(1, 3, 4), dtypes=("uint8", "uint16"))
    if image.ndim == 3:
        image = image[:, :, 0] if image.shape[2] == 1 else cv2.cvtColor(
            image, cv2.COLOR_BGR2GRAY if image.shape[2] == 3 else cv2.COLOR_BGRA2GRAY)
    if image.dtype == np.uint16:
        image = (image >> 8).astype(np.uint8)
    return np.ascontiguousarray(image)
