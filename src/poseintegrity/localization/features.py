"""CLAHE + SIFT keypoint features (paper IV-C), computed once per image and cached on disk.

The cache holds one file per image (:mod:`poseintegrity.cache_entry`: whole or recomputed). Its key hashes the image
bytes together with the CLAHE and SIFT settings, so a re-rendered image or a changed setting recomputes the features,
while re-runs with other matching or RANSAC settings (and every PnP method of stage 05) reuse them.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from poseintegrity.cache_entry import Miss, read_entry, write_entry
from poseintegrity.config import published
from poseintegrity.grayscale import as_gray8
from poseintegrity.localization.dataset import DatasetError
from poseintegrity.params.extract import ClaheParams, SiftParams

CACHE_VERSION = 1  # bump when the cached content or its layout changes


class ImageReadError(DatasetError):
    """An image file of a dataset is missing, cannot be decoded, or is not what its meta.json says (an 8-bit gray
    image of the camera's size). Stops the stage for a model image or mask; a frame image is flagged instead."""


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


def decode_gray(data: bytes, path: str | Path, size: tuple[int, int] | None = None) -> np.ndarray:
    """Decode PNG/JPEG bytes as stored: an 8-bit single-channel (h, w) image, of ``size`` (width, height) if given.

    :class:`ImageReadError` naming the file and what is wrong otherwise. The bytes are decoded unchanged, never
    converted: IMREAD_GRAYSCALE would turn a 16-bit or colour file into a plausible 8-bit image.
    """
    image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED) if data else None
    if image is None:
        raise ImageReadError(f"cannot decode image file {path} (not a readable image)")
    if image.dtype != np.uint8 or image.ndim != 2:
        channels = 1 if image.ndim == 2 else image.shape[2]
        raise ImageReadError(f"image file {path} is {image.dtype.itemsize * 8}-bit with {channels} channel(s), "
                             f"expected 8-bit gray")
    if size is not None and (image.shape[1], image.shape[0]) != tuple(size):
        raise ImageReadError(f"image file {path} is {image.shape[1]} x {image.shape[0]} px, its dataset's "
                             f"camera.yaml says {size[0]} x {size[1]} px")
    return image


def read_gray(path: str | Path, size: tuple[int, int] | None = None) -> np.ndarray:
    """Read an 8-bit grayscale image (of ``size`` (width, height) if given): (h, w) uint8; :class:`ImageReadError`
    naming the file on failure (:func:`decode_gray`)."""
    return decode_gray(read_image_bytes(path), path, size)


def equalize(image: np.ndarray, clahe: ClaheParams) -> np.ndarray:
    """Contrast limited adaptive histogram equalization (IV-C: improves features on low-texture bone)."""
    grid = (clahe.tile_grid, clahe.tile_grid)
    return cv2.createCLAHE(clipLimit=clahe.clip_limit, tileGridSize=grid).apply(image)


def detect_features(image: np.ndarray, clahe: ClaheParams | None = None, sift: SiftParams | None = None) -> Features:
    """CLAHE, then SIFT detectAndCompute on the whole image. No keypoints gives empty arrays.

    image : (h, w) uint8; colour or 16-bit images are converted, anything else refused (:func:`as_gray8`).
    clahe, sift : ``extract.clahe`` / ``extract.sift``; None takes the published defaults (params.yaml).
    """
    clahe = published("extract.clahe") if clahe is None else clahe
    sift = published("extract.sift") if sift is None else sift
    image = as_gray8("image", image)
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


def cached_features(
    image_path: str | Path, cache_path: str | Path, clahe: ClaheParams, sift: SiftParams, data: bytes | None = None,
    image: np.ndarray | None = None,
) -> Features:
    """Features of ``image_path``, read from ``cache_path`` when it is whole and its key matches, else computed and
    stored (:mod:`poseintegrity.cache_entry`).

    ``data``: the file's bytes if already read; ``image``: the decoded image if already decoded (and checked).
    Raises :class:`ImageReadError` naming the file if the image is missing or unreadable.
    """
    data = read_image_bytes(image_path) if data is None else data
    key = features_key(data, clahe, sift)
    stored = read_entry(Path(cache_path), key)
    if not isinstance(stored, Miss):
        return Features(stored["points"], stored["descriptors"].astype(np.float32))
    return stored_features(image_path, cache_path, key, clahe, sift, data, image)


def stored_features(
    image_path: str | Path, cache_path: str | Path, key: str, clahe: ClaheParams, sift: SiftParams, data: bytes,
    image: np.ndarray | None = None,
) -> Features:
    """Compute the features of ``image_path`` (its bytes ``data``, decoded ``image`` if given) and store them at
    ``cache_path`` under ``key`` (:func:`features_key`)."""
    features = detect_features(decode_gray(data, image_path) if image is None else image, clahe, sift)
    write_entry(Path(cache_path), key, {"points": features.points, "descriptors": features.descriptors.astype(np.uint8)})
    return features
