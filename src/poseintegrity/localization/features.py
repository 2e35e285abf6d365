"""CLAHE + SIFT keypoint features (paper IV-C), computed once per image and cached on disk.

The cache holds one ``.npz`` per image. Its key hashes the image bytes together with the CLAHE and SIFT
settings, so a re-rendered image or a changed setting recomputes the features, while re-runs with other
matching or RANSAC settings (and every PnP method of stage 05) reuse them.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from poseintegrity.localization.params import ClaheParams, SiftParams

CACHE_VERSION = 1  # bump when the cached content or its layout changes


class ImageReadError(RuntimeError):
    """An image file of a dataset is missing or cannot be decoded (stops the stage)."""


@dataclass(frozen=True)
class Features:
    """Keypoints of one image.

    points : (n, 2) float32, pixels (x right, y down)
    descriptors : (n, 128) float32, SIFT descriptors (integer valued 0..255)
    """

    points: np.ndarray
    descriptors: np.ndarray

    @property
    def n_keypoints(self) -> int:
        return len(self.points)


def read_image_bytes(path: str | Path) -> bytes:
    """The raw bytes of an image file; :class:`ImageReadError` naming the file if it is missing."""
    try:
        return Path(path).read_bytes()
    except OSError as error:
        raise ImageReadError(f"cannot read image file {path}: {error.strerror}") from None


def decode_gray(data: bytes, path: str | Path) -> np.ndarray:
    """Decode PNG/JPEG bytes to an 8-bit grayscale (h, w) image; :class:`ImageReadError` if undecodable."""
    image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_GRAYSCALE) if data else None
    if image is None:
        raise ImageReadError(f"cannot decode image file {path} (not a readable image)")
    return image


def read_gray(path: str | Path) -> np.ndarray:
    """Read an 8-bit grayscale image: (h, w) uint8; :class:`ImageReadError` naming the file on failure."""
    return decode_gray(read_image_bytes(path), path)


def equalize(image: np.ndarray, clahe: ClaheParams) -> np.ndarray:
    """Contrast limited adaptive histogram equalization (IV-C: improves features on low-texture bone)."""
    grid = (clahe.tile_grid, clahe.tile_grid)
    return cv2.createCLAHE(clipLimit=clahe.clip_limit, tileGridSize=grid).apply(image)


def detect_features(image: np.ndarray, clahe: ClaheParams, sift: SiftParams) -> Features:
    """CLAHE, then SIFT detectAndCompute on the whole image. No keypoints gives empty arrays."""
    detector = cv2.SIFT_create(
        sift.n_features, sift.n_octave_layers, sift.contrast_threshold, sift.edge_threshold, sift.sigma,
        cv2.CV_8U,  # OpenCV's float descriptors are saturated bytes anyway: uint8 is lossless and 4x smaller
    )
    keypoints, descriptors = detector.detectAndCompute(equalize(image, clahe), None)
    if not keypoints:
        return Features(np.empty((0, 2), np.float32), np.empty((0, 128), np.float32))
    points = np.array([keypoint.pt for keypoint in keypoints], dtype=np.float32)
    return Features(points, descriptors.astype(np.float32))


def features_key(data: bytes, clahe: ClaheParams, sift: SiftParams) -> str:
    """Hash of image bytes + CLAHE + SIFT settings: the cache entry is valid only for this key."""
    settings = json.dumps([CACHE_VERSION, clahe.model_dump(), sift.model_dump()], sort_keys=True)
    return hashlib.sha1(settings.encode() + data).hexdigest()


def cached_features(image_path: str | Path, cache_path: str | Path, clahe: ClaheParams, sift: SiftParams) -> Features:
    """Features of ``image_path``, read from ``cache_path`` (.npz) when its key matches, else computed and stored.

    Raises :class:`ImageReadError` naming the file if the image is missing or unreadable.
    """
    data = read_image_bytes(image_path)
    key = features_key(data, clahe, sift)
    cache_path = Path(cache_path)
    if cache_path.exists():
        try:
            with np.load(cache_path) as stored:
                if str(stored["key"]) == key:
                    return Features(stored["points"], stored["descriptors"].astype(np.float32))
        except (OSError, ValueError, KeyError):
            pass  # a truncated or foreign file is simply recomputed
    features = detect_features(decode_gray(data, image_path), clahe, sift)
    cache_path.parent.mkdir(parents=True, exist_ok=True)
    # write-then-rename: parallel workers and interrupted runs never leave a half-written entry
    handle, tmp_path = tempfile.mkstemp(dir=cache_path.parent, suffix=".npz")
    with os.fdopen(handle, "wb") as stream:
        np.savez(stream, key=key, points=features.points, descriptors=features.descriptors.astype(np.uint8))
    os.replace(tmp_path, cache_path)
    return features
