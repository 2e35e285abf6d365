"""AHAT-like IR reflectivity and depth frames with marker blobs, phantom reflections and noise.

A pinhole camera stands in for the HoloLens 2 AHAT camera (512 x 512, docs/references.md).  Markers are spheres
rendered by ray casting with ``supersampling**2`` rays per pixel: IR is proportional to the covered
fraction of the pixel, depth is the distance in millimetres *along the ray* to the first hit (as AHAT
reports it), so the detector's depth lookup lands on the sphere surface, not its centre.
IR is ``rint(ir_background + ir_noise_std z + reflection)``, z ~ N(0, 1) per pixel (:func:`sensor_ir`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numba
import numpy as np
from scipy.special import ndtri

from poseintegrity.params.track import AhatCameraParams, FrameParams


@dataclass(frozen=True)
class Phantom:
    """A reflection that is not a marker: an ellipse in the image at a constant depth.

    u, v : centre, px; radius_px : minor semi-axis; elongation : major / minor axis (1 = round);
    angle : orientation, rad; depth_mm : along the ray.
    """

    u: float
    v: float
    radius_px: float
    elongation: float
    angle: float
    depth_mm: float


def intrinsics(camera: AhatCameraParams) -> np.ndarray:
    """Pinhole K (3, 3), principal point at the image centre."""
    return np.array(
        [[camera.focal_px, 0.0, (camera.width - 1) / 2.0], [0.0, camera.focal_px, (camera.height - 1) / 2.0], [0.0, 0.0, 1.0]]
    )


def unit_plane_lut(K: np.ndarray, width: int, height: int) -> np.ndarray:
    """Per-pixel unit-plane lookup table of a pinhole camera, (H, W, 2): ``lut[v, u] = (x, y)`` at z = 1.

    This is the form the HoloLens Research Mode API gives (docs/references.md).
    """
    u, v = np.meshgrid(np.arange(width, dtype=float), np.arange(height, dtype=float))
    return np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1]], axis=-1)


def draw_phantoms(n: int, camera: AhatCameraParams, frames: FrameParams, round_fraction: float, rng: np.random.Generator) -> list[Phantom]:
    """n random reflections; a share ``round_fraction`` of them round (they pass the circularity test)."""
    phantoms = []
    for _ in range(n):
        is_round = rng.random() < round_fraction
        phantoms.append(
            Phantom(
                u=rng.uniform(10, camera.width - 10),
                v=rng.uniform(10, camera.height - 10),
                radius_px=rng.uniform(*frames.phantom_radius_px),
                elongation=1.0 if is_round else rng.uniform(*frames.phantom_elongation),
                angle=rng.uniform(0, np.pi),
                depth_mm=rng.uniform(*frames.phantom_depth_mm),
            )
        )
    return phantoms


@numba.njit(cache=True, nogil=True)
def _draw_sphere(depth, brightness, origin, centre, radius_m, K, u0, v0, noise_mm, bias_mm, level, s):
    """Ray-cast one sphere into the patch of pixels [u0, u0 + w) x [v0, v0 + h) of depth and brightness, in place.

    depth : (H, W) uint16 mm; brightness : float32, the image's pixels from origin (v, u) on (a box holding every
    patch); centre : (3,) m, camera frame; K : (3, 3) pinhole;
    noise_mm : (h, w) depth noise, mm; bias_mm : depth bias, mm; level : IR of a fully covered pixel; s : rays
    per pixel side.  A pixel's cover is the share of its s x s rays (row-major grid, offsets (i + 0.5) / s - 0.5
    px) that hit the sphere, its depth the nearest hit along the ray (t = d.c - sqrt(R^2 - |c|^2 + (d.c)^2),
    unit ray d) in whole mm with the noise, kept where it is nearer than what the pixel shows.
    """
    h, w = noise_mm.shape
    c_sq = centre[0] * centre[0] + centre[1] * centre[1] + centre[2] * centre[2]
    for i in range(h):
        for j in range(w):
            hits, near = 0, np.inf
            for a in range(s):
                y = (v0 + i + ((a + 0.5) / s - 0.5) - K[1, 2]) / K[1, 1]
                for b in range(s):
                    x = (u0 + j + ((b + 0.5) / s - 0.5) - K[0, 2]) / K[0, 0]
                    norm = np.sqrt(x * x + y * y + 1.0)
                    proj = (x / norm) * centre[0] + (y / norm) * centre[1] + (1.0 / norm) * centre[2]
                    disc = radius_m * radius_m - (c_sq - proj * proj)
                    if disc > 0:
                        hits += 1
                        near = min(near, (proj - np.sqrt(disc)) * 1000.0)
            if hits:
                _compose(depth, brightness, origin, v0 + i, u0 + j, near + bias_mm + noise_mm[i, j], level * (hits / (s * s)))


@numba.njit(cache=True, nogil=True)
def _draw_ellipse(depth, brightness, origin, phantom, u0, v0, noise_mm, level, s):  # pragma: no cover - compiled
    """Draw one phantom (6,) (u, v, radius_px, elongation, angle, depth_mm) into the patch of pixels
    [u0, u0 + w) x [v0, v0 + h) of depth and brightness, in place, as :func:`_draw_sphere` draws a sphere: cover is
    the share of the s x s rays inside the ellipse, depth its constant depth_mm plus noise_mm (h, w).

    Each pixel row is tested only over the columns where one of its ray rows crosses the ellipse grown by half a
    pixel (every ray the exact test accepts lies well inside that one): a thin tilted reflection fills a few
    pixels of each row of its square patch."""
    pu, pv, radius, elongation, angle, depth_mm = phantom[0], phantom[1], phantom[2], phantom[3], phantom[4], phantom[5]
    cos, sin = np.cos(angle), np.sin(angle)
    h, w = noise_mm.shape
    # the grown ellipse (P du + Q dv)^2 + (R du + T dv)^2 <= 1, for one ray row a quadratic qa du^2 + qb du + qc <= 0
    P, Q = cos / (radius * elongation + 0.5), sin / (radius * elongation + 0.5)
    R, T = -sin / (radius + 0.5), cos / (radius + 0.5)
    qa = P * P + R * R
    first_offset, last_offset = 0.5 / s - 0.5, (s - 0.5) / s - 0.5  # of the rays within a pixel
    for i in range(h):
        j0, j1 = w, -1
        for a in range(s):
            dv = v0 + i + ((a + 0.5) / s - 0.5) - pv
            qb, qc = 2.0 * (P * Q + R * T) * dv, (Q * Q + T * T) * dv * dv - 1.0
            disc = qb * qb - 4.0 * qa * qc
            if disc >= 0.0:
                root = np.sqrt(disc)
                j0 = min(j0, int(np.floor((-qb - root) / (2.0 * qa) + pu - u0 - last_offset)))
                j1 = max(j1, int(np.ceil((-qb + root) / (2.0 * qa) + pu - u0 - first_offset)))
        for j in range(max(j0, 0), min(j1 + 1, w)):
            hits = 0
            for a in range(s):
                dv = v0 + i + ((a + 0.5) / s - 0.5) - pv
                for b in range(s):
                    du = u0 + j + ((b + 0.5) / s - 0.5) - pu
                    major = (du * cos + dv * sin) / (radius * elongation)
                    minor = (-du * sin + dv * cos) / radius
                    hits += major * major + minor * minor <= 1.0
            if hits:
                _compose(depth, brightness, origin, v0 + i, u0 + j, depth_mm + noise_mm[i, j], level * (hits / (s * s)))


@numba.njit(cache=True, nogil=True, inline="always")
def _compose(depth, brightness, origin, v, u, depth_mm, ir):
    """A surface at depth_mm (rounded to whole mm, clipped to uint16) reflecting ir: the pixel (v, u) keeps the
    nearer depth and the brighter reflection."""
    depth[v, u] = min(depth[v, u], min(max(np.rint(depth_mm), 0.0), 65535.0))
    brightness[v - origin[0], u - origin[1]] = max(brightness[v - origin[0], u - origin[1]], np.float32(ir))


def render_frame(
    markers_cam: np.ndarray,
    phantoms: list[Phantom],
    camera: AhatCameraParams,
    frames: FrameParams,
    marker_radius_m: float,
    rng: np.random.Generator,
    background_noise: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """Render one IR and one depth frame.

    markers_cam : (k, 3) centres of the visible markers in the camera frame, metres (z forward).
    phantoms : reflections to draw.  marker_radius_m : sphere radius, m.  background_noise : see :func:`sensor_ir`
    (False only where nothing reads the unlit pixels but a threshold above the background's largest value).
    Returns ir : (H, W) uint16 (raw reflectivity, background ~80, markers saturate above 1000) and
    depth_mm : (H, W) uint16, millimetres along the ray (background_depth_mm where nothing is hit).

    Depth is kept as whole millimetres throughout: rounding and clipping to uint16 are monotone, so rounding
    each surface before taking the nearest one gives the same image as rounding the nearest float depth.
    Per marker (far to near) the generator draws its depth bias, its patch's depth noise and its IR level; per
    phantom its depth noise and IR level; then the IR noise (:func:`sensor_ir`).  The marker and phantom draws
    are one call of standard normals, scaled as ``rng.normal`` scales them (loc + scale z), so the values and
    the generator's state are those of one ``rng.normal`` call per draw.
    """
    H, W, s = camera.height, camera.width, frames.supersampling
    K = intrinsics(camera)
    depth = np.full((H, W), depth_mm_uint16(frames.background_depth_mm), dtype=np.uint16)
    frame_bias = rng.normal(0.0, frames.frame_depth_bias_std_mm)
    centres = np.ascontiguousarray(markers_cam[np.argsort(-markers_cam[:, 2])] if len(markers_cam) else np.zeros((0, 3)), dtype=float)
    shapes = np.array([(p.u, p.v, p.radius_px, p.elongation, p.angle, p.depth_mm) for p in phantoms], dtype=float).reshape(-1, 6)
    patches, n_draws, box = _patches(centres, shapes, K, float(camera.focal_px), float(marker_radius_m), W, H)  # the only pixels lit
    z = rng.standard_normal(n_draws)
    brightness = np.zeros((box[1] - box[0], box[3] - box[2]), dtype=np.float32)  # the pixels of the box around every patch
    origin = (int(box[0]), int(box[2]))
    _draw_scene(depth, brightness, origin, centres, shapes, patches, z, frame_bias, float(frames.depth_bias_std_mm), float(frames.depth_noise_mm),
                float(frames.marker_ir), float(frames.marker_ir_std), K, float(marker_radius_m), s)
    lit, reflected = _lit_pixels(brightness, origin, patches, W)
    return sensor_ir((H, W), lit, reflected, frames, rng, background_noise), depth


@numba.njit(cache=True, nogil=True)
def _patches(centres, shapes, K, focal_px, radius_m, W, H):  # pragma: no cover - compiled
    """Pixel patches (k + p, 4) int rows (v0, v1, u0, u1) of the spheres (k, 3) m and then the phantoms (p, 6) (u, v,
    radius_px, elongation, angle, depth_mm), and the number of normal draws :func:`_draw_scene` takes.

    A sphere's patch is its projected centre +- its image radius + 2 px within the image, (0, 0, 0, 0) if it is not
    drawn (centre within one radius of the camera, or a patch outside the image); it draws 2 + its pixel count.  A
    phantom's is its centre +- radius_px elongation + 2 px within the image (possibly empty); it draws 1 + its pixel
    count.  Bounds truncate toward zero, as ``int()`` does.  Also returns the box (4,) (v0, v1, u0, u1) around
    every non-empty patch (all 0 if there is none)."""
    patches = np.zeros((len(centres) + len(shapes), 4), np.int64)
    n_draws = 0
    for k in range(len(centres)):
        x, y, z = centres[k, 0], centres[k, 1], centres[k, 2]
        if z <= radius_m:
            continue
        u_c, v_c = K[0, 0] * x / z + K[0, 2], K[1, 1] * y / z + K[1, 2]
        rho = focal_px * radius_m / np.sqrt(z**2 - radius_m**2) + 2.0
        u0, u1 = max(np.trunc(u_c - rho), 0.0), min(np.trunc(u_c + rho) + 2.0, W)
        v0, v1 = max(np.trunc(v_c - rho), 0.0), min(np.trunc(v_c + rho) + 2.0, H)
        if u0 < u1 and v0 < v1:
            patches[k, 0], patches[k, 1], patches[k, 2], patches[k, 3] = int(v0), int(v1), int(u0), int(u1)
            n_draws += 2 + (int(v1) - int(v0)) * (int(u1) - int(u0))
    for q in range(len(shapes)):
        extent = shapes[q, 2] * shapes[q, 3] + 2.0
        row = patches[len(centres) + q]
        row[2], row[3] = max(int(np.trunc(shapes[q, 0] - extent)), 0), min(int(np.trunc(shapes[q, 0] + extent)) + 2, W)
        row[0], row[1] = max(int(np.trunc(shapes[q, 1] - extent)), 0), min(int(np.trunc(shapes[q, 1] + extent)) + 2, H)
        n_draws += 1 + max(row[1] - row[0], 0) * max(row[3] - row[2], 0)
    box = np.array([H, 0, W, 0], np.int64)  # (v0, v1, u0, u1) around every non-empty patch; empty if there is none
    for row in patches:
        if row[0] < row[1] and row[2] < row[3]:
            box[0], box[1], box[2], box[3] = min(box[0], row[0]), max(box[1], row[1]), min(box[2], row[2]), max(box[3], row[3])
    if box[0] >= box[1]:
        box[:] = 0
    return patches, n_draws, box


@numba.njit(cache=True, nogil=True)
def _draw_scene(depth, brightness, origin, centres, shapes, patches, z, frame_bias, depth_bias_std_mm, depth_noise_mm, marker_ir, marker_ir_std, K,
                radius_m, s):  # pragma: no cover - compiled
    """Every sphere with a patch (far to near) and then every phantom, in place, in their patches (:func:`_patches`),
    taking their normal draws from z in order: per sphere its depth bias, its patch's depth noise (row-major) and
    its IR level; per phantom its patch's depth noise and its IR level (loc + scale z, as ``rng.normal`` computes them)."""
    k = 0
    for m in range(len(centres)):
        v0, v1, u0, u1 = patches[m, 0], patches[m, 1], patches[m, 2], patches[m, 3]
        if v0 >= v1:
            continue
        bias = frame_bias + (0.0 + depth_bias_std_mm * z[k])
        noise = (0.0 + depth_noise_mm * z[k + 1 : k + 1 + (v1 - v0) * (u1 - u0)]).reshape(v1 - v0, u1 - u0)
        k += 1 + (v1 - v0) * (u1 - u0)
        level = marker_ir + marker_ir_std * z[k]
        k += 1
        _draw_sphere(depth, brightness, origin, centres[m], radius_m, K, u0, v0, noise, bias, level, s)
    for m in range(len(shapes)):
        v0, v1, u0, u1 = patches[len(centres) + m, 0], patches[len(centres) + m, 1], patches[len(centres) + m, 2], patches[len(centres) + m, 3]
        h, w = max(v1 - v0, 0), max(u1 - u0, 0)
        noise = (0.0 + depth_noise_mm * z[k : k + h * w]).reshape(h, w)
        k += h * w
        level = marker_ir + marker_ir_std * z[k]
        k += 1
        _draw_ellipse(depth, brightness, origin, shapes[m], u0, v0, noise, level, s)


UNIFORM_LEVELS = 65536  # 16-bit uniforms: the background's inverse-CDF table has this many entries


@lru_cache(maxsize=8)
def background_quantiles(background: float, noise_std: float) -> np.ndarray:
    """(65536,) uint16 table: the sensor value rint(background + noise_std z), clipped to uint16, at the midpoint
    quantiles z = Phi^-1((i + 0.5) / 65536).  Indexed by a uniform 16-bit integer it samples that quantized normal
    (inverse-CDF sampling): each value's probability is within 1 / 65536 of the exact
    Phi((k + 0.5 - background) / noise_std) - Phi((k - 0.5 - background) / noise_std), and draws beyond
    +-4.3 noise_std are folded into the outermost values."""
    z = ndtri((np.arange(UNIFORM_LEVELS) + 0.5) / UNIFORM_LEVELS)
    return np.clip(np.rint(background + noise_std * z), 0, 65535).astype(np.uint16)


@numba.njit(cache=True, nogil=True)
def _lookup_16bit(words: np.ndarray, table: np.ndarray, out: np.ndarray) -> None:
    """out.ravel()[4 i + j] = table[bits 16 j .. 16 j + 15 of words[i]]: four 16-bit uniforms per 64-bit word."""
    flat = out.ravel()
    for i in range(flat.size):
        flat[i] = table[(words[i // 4] >> np.uint64(16 * (i % 4))) & np.uint64(0xFFFF)]


@numba.njit(cache=True, nogil=True)
def _lit_pixels(brightness, origin, patches, W):  # pragma: no cover - compiled
    """The lit pixels of an image W wide, in raster order: their flat indices and their brightness (float32).
    brightness : the pixels from origin (v, u) on, 0 outside the patches (k, 4) int rows (v0, v1, u0, u1); each row
    is scanned only from the leftmost to the rightmost patch column that covers it."""
    h = brightness.shape[0]
    size = 0
    for k in range(len(patches)):
        size += max(patches[k, 1] - patches[k, 0], 0) * max(patches[k, 3] - patches[k, 2], 0)
    lit, reflected = np.empty(size, np.int64), np.empty(size, np.float32)  # patches may overlap: at most their total area
    n = 0
    for r in range(h):
        v = origin[0] + r
        first, last = W, 0
        for k in range(len(patches)):
            if patches[k, 0] <= v < patches[k, 1] and patches[k, 2] < patches[k, 3]:  # an empty patch lights nothing
                first, last = min(first, patches[k, 2]), max(last, patches[k, 3])
        for u in range(first, last):
            if brightness[r, u - origin[1]] > 0:
                lit[n], reflected[n] = v * W + u, brightness[r, u - origin[1]]
                n += 1
    return lit[:n], reflected[:n]


def skip_raw(rng: np.random.Generator, n_words: int) -> None:
    """Move rng on as ``rng.bit_generator.random_raw(n_words)`` would, without computing the words.

    PCG64 (numpy's default) jumps ahead in O(log n); ``advance`` clears the buffered half of a 64-bit word that a
    32-bit draw may have left (random_raw keeps it), so that buffer is put back.  Other bit generators draw the words."""
    bit_generator = rng.bit_generator
    if not hasattr(bit_generator, "advance"):
        bit_generator.random_raw(n_words)
        return
    state = bit_generator.state
    bit_generator.advance(n_words)
    bit_generator.state = {**bit_generator.state, "has_uint32": state["has_uint32"], "uinteger": state["uinteger"]}


def sensor_ir(shape: tuple[int, int], lit: np.ndarray, reflected: np.ndarray, frames: FrameParams, rng: np.random.Generator,
              background_noise: bool = True) -> np.ndarray:
    """Raw IR (H, W) = shape, uint16, of an image lit at the flat indices lit (k,) (ascending) with brightness
    reflected (k,) float32 > 0 and dark elsewhere: rint(ir_background + ir_noise_std z + brightness), clipped to uint16.

    Unlit pixels (nearly all of them) take the quantized value directly from :func:`background_quantiles` with a
    16-bit uniform, four per raw 64-bit word of the generator; lit pixels draw z as a float32 normal.  This has the
    distribution of drawing z everywhere (within 1 / 65536 per value on the background, which is ~30 noise_std
    below the detector's threshold either way) at a quarter of the cost.
    background_noise False: the unlit pixels read the table's median, rint(ir_background), and the generator skips
    their words (:func:`skip_raw`), so the lit pixels and every later draw are those of the noisy image; only a
    reader of the unlit pixels can tell the two apart (the detector's mask cannot: see ``record``).
    """
    ir = np.empty(shape, dtype=np.uint16)
    table = background_quantiles(frames.ir_background, frames.ir_noise_std)
    if background_noise:
        _lookup_16bit(rng.bit_generator.random_raw(-(-ir.size // 4)), table, ir)
    else:
        skip_raw(rng, -(-ir.size // 4))
        ir.fill(table[UNIFORM_LEVELS // 2])
    value = rng.standard_normal(lit.size, dtype=np.float32)  # in place: ir_background + ir_noise_std * z + brightness
    value *= np.float32(frames.ir_noise_std)
    value += np.float32(frames.ir_background)
    value += reflected
    ir.ravel()[lit] = np.clip(np.rint(value, out=value), 0, 65535, out=value)
    return ir


def depth_mm_uint16(depth_mm: np.ndarray | float) -> np.ndarray:
    """Depth (any shape) in mm rounded to whole millimetres and clipped to the uint16 range, as the sensor stores it."""
    return np.clip(np.rint(depth_mm), 0, 65535).astype(np.uint16)
