"""Textures: procedural albedo maps (printed blocks, table, clutter, the ground-truth board), image files
as overrides, and the mip-mapped atlas the renderer samples.

Albedo maps are 8-bit grayscale (the camera is the monochrome U3-3060CP-M); 255 means a white Lambertian surface.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from poseintegrity.boards import Board, Charuco

N_MIP_LEVELS = 6
PAD_PX = 2 ** (N_MIP_LEVELS - 1)  # replicated border around each texture, so coarse mip levels do not bleed

WORDS = "FEMUR SCAPULA GLENOID DRILL ROBOT PANDA SIFT RANSAC PNP POSE LOT 4471 REF-2023 STERILE TRAY".split()


def fractal_noise(rng: np.random.Generator, shape: tuple[int, int], base_cells: int, octaves: int,
                  persistence: float = 0.5) -> np.ndarray:
    """Zero-mean, unit-std value noise: random grids of 2^k * base_cells cells, bicubic-upsampled and summed."""
    h, w = shape
    out = np.zeros(shape, np.float32)
    for k in range(octaves):
        cells = base_cells * 2**k
        grid = rng.standard_normal((max(2, cells * h // max(h, w)), max(2, cells * w // max(h, w))))
        out += persistence**k * cv2.resize(grid.astype(np.float32), (w, h), interpolation=cv2.INTER_CUBIC)
    return (out - out.mean()) / out.std()


def to_u8(albedo: np.ndarray) -> np.ndarray:
    return np.clip(np.rint(albedo * 255), 0, 255).astype(np.uint8)


def collage_texture(rng: np.random.Generator, shape: tuple[int, int], density: float, contrast: float,
                    text: bool) -> np.ndarray:
    """A printed, highly textured surface: overlapping shapes, stripes and (optionally) words on noise."""
    h, w = shape
    img = to_u8(0.55 + 0.1 * fractal_noise(rng, shape, 3, 3))  # drawn in 8 bit (putText needs it)
    n_shapes = int(density * h * w / 2000)
    for _ in range(n_shapes):
        value = int(255 * np.clip(0.5 + contrast * rng.uniform(-1, 1), 0.02, 0.98))
        kind = rng.integers(0, 4 if text else 3)
        x, y = int(rng.integers(0, w)), int(rng.integers(0, h))
        s = int(rng.integers(6, max(8, min(h, w) // 8)))
        if kind == 0:
            cv2.rectangle(img, (x, y), (x + s, y + int(s * rng.uniform(0.3, 1.5))), value, -1, cv2.LINE_AA)
        elif kind == 1:
            cv2.circle(img, (x, y), s // 2, value, -1 if rng.random() < 0.7 else 2, cv2.LINE_AA)
        elif kind == 2:
            angle = rng.uniform(0, np.pi)
            dx, dy = int(s * np.cos(angle)), int(s * np.sin(angle))
            cv2.line(img, (x, y), (x + dx, y + dy), value, int(rng.integers(1, 4)), cv2.LINE_AA)
        else:
            word = WORDS[rng.integers(len(WORDS))]
            cv2.putText(img, word, (x, y), int(rng.integers(0, 4)), rng.uniform(0.5, 2.0), value,
                        int(rng.integers(1, 3)), cv2.LINE_AA)
    return img


def wood_texture(rng: np.random.Generator, size: int = 2048) -> np.ndarray:
    """A table top: stretched noise for grain, slow rings, moderate contrast."""
    grain = fractal_noise(rng, (size // 16, size), 24, 4)
    grain = cv2.resize(grain, (size, size), interpolation=cv2.INTER_CUBIC)
    rings = np.sin(np.linspace(0, 40 * np.pi, size)[None, :] + 3.0 * fractal_noise(rng, (size, size), 2, 2))
    return to_u8(0.42 + 0.05 * grain + 0.03 * rings)


def board_texture(board: Board, px_per_mm: float, margin_mm: float) -> np.ndarray:
    """The printed ground-truth board (:mod:`poseintegrity.boards`, as drawn) with a white margin, (h, w) uint8 at
    ``px_per_mm``: gray paper white (0.85), black ink (0.06). The pattern spans its drawing's size, centred."""
    margin = int(round(margin_mm * px_per_mm))
    w_mm, h_mm = board.size_mm
    size = (int(round(w_mm * px_per_mm)) + 2 * margin, int(round(h_mm * px_per_mm)) + 2 * margin)
    extra = {} if isinstance(board, Charuco) else {"borderBits": 1}
    img = board.cv_board().generateImage(size, marginSize=margin, **extra).astype(np.float32) / 255
    return to_u8(0.06 + 0.79 * img)


def load_texture(path: Path) -> np.ndarray:
    """An image file as an 8-bit grayscale albedo map; ValueError naming the file when unreadable."""
    img = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise ValueError(f"texture file {str(path)!r} cannot be read as an image")
    return img


@dataclass(frozen=True)
class TextureAtlas:
    """All textures of a scene packed into one image, with a mip pyramid for trilinear sampling.

    mip : (total,) uint8, the levels stored one after another; offset, width, height : (N_MIP_LEVELS,) int64.
    rects : name -> (x0, y0, w, h) of the texture inside level 0 (excluding padding).
    """

    mip: np.ndarray
    offset: np.ndarray
    width: np.ndarray
    height: np.ndarray
    rects: dict[str, tuple[int, int, int, int]]

    def atlas_uv(self, texture: str, uv: np.ndarray) -> np.ndarray:
        """Texture coordinates in [0, 1]^2 -> level-0 atlas pixel coordinates, (n, 2) float."""
        x0, y0, w, h = self.rects[texture]
        return np.column_stack([x0 + uv[:, 0] * (w - 1), y0 + uv[:, 1] * (h - 1)])

    def level(self, k: int) -> np.ndarray:
        return self.mip[self.offset[k]: self.offset[k] + self.width[k] * self.height[k]].reshape(
            self.height[k], self.width[k])


def build_atlas(textures: dict[str, np.ndarray], atlas_width: int = 4096) -> TextureAtlas:
    """Shelf-pack textures (tallest first) into one image, then build its mip pyramid by Gaussian pyrDown."""
    order = sorted(textures, key=lambda n: (-textures[n].shape[0], n))
    rects, x, y, shelf = {}, 0, 0, 0
    for name in order:
        h, w = textures[name].shape
        if x + w + 2 * PAD_PX > atlas_width:
            x, y, shelf = 0, y + shelf, 0
        rects[name] = (x + PAD_PX, y + PAD_PX, w, h)
        x += w + 2 * PAD_PX
        shelf = max(shelf, h + 2 * PAD_PX)
    height = -(-(y + shelf) // 2 ** (N_MIP_LEVELS - 1)) * 2 ** (N_MIP_LEVELS - 1)
    atlas = np.zeros((height, atlas_width), np.uint8)
    for name, (x0, y0, w, h) in rects.items():
        padded = cv2.copyMakeBorder(textures[name], PAD_PX, PAD_PX, PAD_PX, PAD_PX, cv2.BORDER_REPLICATE)
        atlas[y0 - PAD_PX: y0 + h + PAD_PX, x0 - PAD_PX: x0 + w + PAD_PX] = padded
    levels = [atlas]
    for _ in range(N_MIP_LEVELS - 1):
        levels.append(cv2.pyrDown(levels[-1]))
    widths = np.array([lv.shape[1] for lv in levels], np.int64)
    heights = np.array([lv.shape[0] for lv in levels], np.int64)
    offsets = np.concatenate([[0], np.cumsum(widths * heights)[:-1]]).astype(np.int64)
    return TextureAtlas(np.concatenate([lv.ravel() for lv in levels]), offsets, widths, heights, rects)
