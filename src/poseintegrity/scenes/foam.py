"""Bone foam: the surface of a moulded solid-foam bone phantom (SAWBONES-like) as a solid texture.

A foam phantom is cast in a mould: its surface is the foam's cell structure cut by the mould wall, i.e. open
pores (pits of ~0.2-1 mm) and fine bumps on a pale, nearly uniform material. Under the camera's ring light such a
surface is seen through its *shading*: a pore wall facing the camera is bright, one turned away is dark. That
shading moves with the camera (the ring light moves with it), so the keypoints it makes change with the viewpoint,
unlike printed albedo, which only deforms.

The relief is a height field h(p) (mm) defined everywhere in the phantom's own frame (a solid texture, Perlin 1985,
"An image synthesizer", SIGGRAPH): evaluated on the surface, its gradient tilts the shading normal (bump mapping,
Blinn 1978, "Simulation of wrinkled surfaces", SIGGRAPH). No texture coordinates are needed, so any mesh (the STL
scapula has none) gets a seamless, scale-true relief.

h is a sum of octaves of one periodic volume V (a :class:`ReliefVolume`): octave k samples V at p / 2^k through its
own rotation, with amplitude 2^k, so that every octave has the same slopes and pores of radius r0 2^k. Octaves
whose pores are smaller than a pixel footprint are faded out (their shading would alias instead of averaging).
A low-frequency octave of the same volume modulates the albedo by a few per cent.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numba
import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.params.generate import VOXEL_MM

if TYPE_CHECKING:
    from poseintegrity.params.generate import BoneFoamParams

N_OCTAVES = 3  # pore radii r0, 2 r0, 4 r0
N_VOXELS = 128  # one period of the relief volume: 128 voxels of VOXEL_MM = 16 mm
# fixed, well spread rotations decorrelating the octaves (and the albedo octave) from each other
OCTAVE_ROTATIONS = Rotation.from_rotvec(
    [[0.0, 0.0, 0.0], [0.9, 0.3, -0.4], [-0.5, 1.1, 0.6], [0.7, -0.8, 1.2]]
).as_matrix()


@dataclass(frozen=True)
class ReliefVolume:
    """One period of the foam's height field, sampled on a periodic n^3 grid.

    height : (n, n, n) float32, mm, zero mean; n a power of two (sampling wraps by a bit mask)
    voxel_mm : grid spacing;  pore_radius_mm : r0 (octave 0)
    albedo_std : std of the albedo modulation (a fraction, e.g. 0.03)
    albedo_scale : the albedo octave samples the volume at p / (albedo_scale voxel): mottles ~albedo_scale r0 wide
    """

    height: np.ndarray
    voxel_mm: float
    pore_radius_mm: float
    albedo_std: float
    albedo_scale: float

    def __post_init__(self):
        n = self.height.shape[0]
        if self.height.shape != (n, n, n) or n < 2 or n & (n - 1):
            raise ValueError(f"the relief volume must be n^3 voxels with n a power of two, got {self.height.shape}")

    @cached_property  # the std of 128^3 voxels costs as much as rasterising a frame: once, not per render
    def albedo_gain(self) -> float:
        """albedo_std / std(height): scales the albedo octave's heights to albedo fractions (0 for a flat volume)."""
        std = float(self.height.std())
        return self.albedo_std / std if std > 0 else 0.0


def _periodic_gaussian_filter(field: np.ndarray, sigma_vox: float) -> np.ndarray:
    """Convolution of a periodic (n, n, n) field with a unit-sum Gaussian of std ``sigma_vox`` voxels (by FFT)."""
    n = field.shape[0]
    k = np.fft.fftfreq(n)
    k2 = k[:, None, None] ** 2 + k[None, :, None] ** 2 + k[None, None, :] ** 2
    return np.fft.ifftn(np.fft.fftn(field) * np.exp(-2.0 * np.pi**2 * sigma_vox**2 * k2)).real


def relief_volume(rng: np.random.Generator, *, pore_radius_mm: float, pore_fraction: float, pore_depth: float,
                  bump_slope: float, albedo_std: float, albedo_mottle_mm: float, n: int = N_VOXELS,
                  voxel_mm: float = VOXEL_MM) -> ReliefVolume:
    """The foam's height field over one period (n voxels of ``voxel_mm``); the material's values come from
    ``generate.bone_foam`` (:func:`bone_foam_relief`).

    Pores: spherical pits (Gaussian profile, std = radius) at uniformly random centres, depth = pore_depth x radius
    x U(0.5, 1.5), covering about ``pore_fraction`` of a plane section (each pore's cross-section pi r^2);
    bumps: white noise low-passed at twice the pore radius, scaled to RMS slope ``bump_slope``; albedo: the same
    volume magnified to mottles of ``albedo_mottle_mm``.
    """
    r_vox = pore_radius_mm / voxel_mm
    period_mm = n * voxel_mm
    # pores per unit volume such that a random plane cuts pore_fraction of its area: density x 2r x pi r^2
    density = pore_fraction / (2.0 * pore_radius_mm * np.pi * pore_radius_mm**2)
    n_pores = int(round(density * period_mm**3))
    impulses = np.zeros((n, n, n))
    centres = rng.integers(0, n, size=(n_pores, 3))
    np.add.at(impulses, tuple(centres.T), -pore_depth * pore_radius_mm * rng.uniform(0.5, 1.5, n_pores))
    # a Gaussian of std r and peak d: d (2 pi r^2)^{3/2} x the unit-sum kernel
    pores = _periodic_gaussian_filter(impulses, r_vox) * (2.0 * np.pi * r_vox**2) ** 1.5
    bumps = _periodic_gaussian_filter(rng.standard_normal((n, n, n)), 2.0 * r_vox)
    slope = np.sqrt(sum(np.gradient(bumps, voxel_mm, axis=a) ** 2 for a in range(3)).mean())
    height = pores + bumps * (bump_slope / slope)
    return ReliefVolume((height - height.mean()).astype(np.float32), voxel_mm, pore_radius_mm, albedo_std,
                        albedo_mottle_mm / pore_radius_mm)


def bone_foam_relief(bone_foam: BoneFoamParams, seed: int, **grid) -> ReliefVolume:
    """The relief of ``generate.bone_foam``, seeded by ``generate.seed`` (one material: the same for every object);
    ``grid``: ``n`` / ``voxel_mm`` of :func:`relief_volume` (tests shrink it)."""
    return relief_volume(np.random.default_rng([seed, 7]), pore_radius_mm=bone_foam.pore_radius_mm,
                         pore_fraction=bone_foam.pore_fraction, pore_depth=bone_foam.pore_depth,
                         bump_slope=bone_foam.bump_slope, albedo_std=bone_foam.albedo_std,
                         albedo_mottle_mm=bone_foam.albedo_mottle_mm, **grid)


@numba.njit(cache=True, nogil=True, fastmath=True, error_model="numpy")
def trilinear_gradient(volume, x, y, z):
    """Value and gradient (per voxel) of a periodic (n, n, n) volume (n a power of two), trilinearly interpolated at voxel
    coordinates (x, y, z). Returns (value, d/dx, d/dy, d/dz)."""
    wrap = volume.shape[0] - 1  # n is a power of two: i & (n - 1) is i mod n, also for negative i
    fx, fy, fz = np.floor(x), np.floor(y), np.floor(z)
    tx, ty, tz = x - fx, y - fy, z - fz
    i0, j0, k0 = int(fx) & wrap, int(fy) & wrap, int(fz) & wrap
    i1, j1, k1 = (i0 + 1) & wrap, (j0 + 1) & wrap, (k0 + 1) & wrap
    c000, c100 = volume[i0, j0, k0], volume[i1, j0, k0]
    c010, c110 = volume[i0, j1, k0], volume[i1, j1, k0]
    c001, c101 = volume[i0, j0, k1], volume[i1, j0, k1]
    c011, c111 = volume[i0, j1, k1], volume[i1, j1, k1]
    # interpolate along x, then y, then z; derivatives by differentiating each stage
    c00, c10 = c000 + tx * (c100 - c000), c010 + tx * (c110 - c010)
    c01, c11 = c001 + tx * (c101 - c001), c011 + tx * (c111 - c011)
    c0, c1 = c00 + ty * (c10 - c00), c01 + ty * (c11 - c01)
    value = c0 + tz * (c1 - c0)
    dx0 = (c100 - c000) + ty * ((c110 - c010) - (c100 - c000))
    dx1 = (c101 - c001) + ty * ((c111 - c011) - (c101 - c001))
    dx = dx0 + tz * (dx1 - dx0)
    dy = (c10 - c00) + tz * ((c11 - c01) - (c10 - c00))
    dz = c1 - c0
    return value, dx, dy, dz


@numba.njit(cache=True, nogil=True, fastmath=True, error_model="numpy")
def relief_gradient(volume, voxel_mm, pore_radius_mm, rotations, px, py, pz, footprint_mm):
    """Gradient of the foam height field h (mm per mm, object frame) at the point p = (px, py, pz) mm.

    Octave k: h_k(p) = 2^k V(R_k p / (2^k voxel)), so dh_k/dp = R_k^T grad V / voxel; it fades in between pore
    radii of 0.5 and 1.5 pixel footprints (``footprint_mm``: the surface length one pixel spans).
    """
    gx = 0.0
    gy = 0.0
    gz = 0.0
    for k in range(N_OCTAVES):
        scale = 2.0**k
        weight = min(max((pore_radius_mm * scale / footprint_mm) - 0.5, 0.0), 1.0)
        if weight == 0.0:
            continue
        R = rotations[k]
        s = 1.0 / (scale * voxel_mm)
        qx = (R[0, 0] * px + R[0, 1] * py + R[0, 2] * pz) * s
        qy = (R[1, 0] * px + R[1, 1] * py + R[1, 2] * pz) * s
        qz = (R[2, 0] * px + R[2, 1] * py + R[2, 2] * pz) * s
        _, dx, dy, dz = trilinear_gradient(volume, qx, qy, qz)
        w = weight / voxel_mm
        gx += w * (R[0, 0] * dx + R[1, 0] * dy + R[2, 0] * dz)
        gy += w * (R[0, 1] * dx + R[1, 1] * dy + R[2, 1] * dz)
        gz += w * (R[0, 2] * dx + R[1, 2] * dy + R[2, 2] * dz)
    return gx, gy, gz


@numba.njit(cache=True, nogil=True, fastmath=True, error_model="numpy")
def albedo_modulation(volume, voxel_mm, albedo_gain, albedo_scale, rotation, px, py, pz):
    """1 + albedo_gain x (the volume magnified albedo_scale times) at p (mm, object frame): std albedo_std."""
    s = 1.0 / (albedo_scale * voxel_mm)
    qx = (rotation[0, 0] * px + rotation[0, 1] * py + rotation[0, 2] * pz) * s
    qy = (rotation[1, 0] * px + rotation[1, 1] * py + rotation[1, 2] * pz) * s
    qz = (rotation[2, 0] * px + rotation[2, 1] * py + rotation[2, 2] * pz) * s
    value, _, _, _ = trilinear_gradient(volume, qx, qy, qz)
    return 1.0 + albedo_gain * value
