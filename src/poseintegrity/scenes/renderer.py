"""A small software renderer: perspective z-buffer rasterisation of textured triangle meshes, trilinear
mip-mapped texture sampling, Gouraud-interpolated Lambert + Blinn-Phong shading under a light on the camera (ring light) and a
light fixed to the scene, then the optics (blur) and the sensor: exposure, illumination flicker, shot and read noise.

Two passes (deferred shading): :func:`_rasterize` keeps, per pixel, the nearest triangle and its
perspective-correct barycentric coordinates; :func:`_shade` then shades each pixel once, with the light
terms computed per vertex (:func:`vertex_lighting`; our meshes are finely tessellated). Both are compiled with
numba; everything else is numpy. Frames: OpenCV camera (x right, y down, z forward), millimetres.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numba
import numpy as np

from poseintegrity.scenes.mesh import Mesh
from poseintegrity.scenes.params import SensorParams
from poseintegrity.scenes.textures import TextureAtlas

NEAR_MM = 20.0
BACKGROUND = 0.08  # radiance behind everything (a dim room)
AMBIENT, RING_LIGHT, ROOM_LIGHT = 0.18, 0.72, 0.30  # light intensities; a white surface facing both ~ 1.2


@dataclass(frozen=True)
class SceneGeometry:
    """Every mesh of a scene in the world frame, flattened for the renderer.

    vertices, normals : (n, 3) float64; uv : (n, 2) float64, level-0 atlas pixels; faces : (m, 3) int32;
    face_object : (m,) int32 object index (into ``object_names``); vertex_specular, vertex_shininess : (n,) float64;
    face_texel_area : (m,) float64, texture area of each face in atlas pixels^2 (mip level selection);
    light_dir : (3,) unit vector towards the room light, world frame.
    """

    vertices: np.ndarray
    normals: np.ndarray
    uv: np.ndarray
    faces: np.ndarray
    face_object: np.ndarray
    vertex_specular: np.ndarray
    vertex_shininess: np.ndarray
    face_texel_area: np.ndarray
    atlas: TextureAtlas
    object_names: tuple[str, ...]
    light_dir: np.ndarray

    @classmethod
    def from_meshes(cls, meshes: list[tuple[str, Mesh]], atlas: TextureAtlas, light_dir: np.ndarray) -> "SceneGeometry":
        """``meshes``: (object name, mesh already placed in the world frame) pairs."""
        offsets = np.cumsum([0] + [len(m.vertices) for _, m in meshes[:-1]])
        uv = np.concatenate([atlas.atlas_uv(m.texture, m.uv) for _, m in meshes])
        faces = np.concatenate([m.faces + o for (_, m), o in zip(meshes, offsets)]).astype(np.int32)
        u0, u1, u2 = (uv[faces[:, i]] for i in range(3))
        texel_area = 0.5 * np.abs((u1[:, 0] - u0[:, 0]) * (u2[:, 1] - u0[:, 1])
                                  - (u2[:, 0] - u0[:, 0]) * (u1[:, 1] - u0[:, 1]))
        per_face = lambda values: np.concatenate([np.full(len(m.faces), v) for (_, m), v in zip(meshes, values)])
        per_vertex = lambda values: np.concatenate([np.full(len(m.vertices), v, float) for (_, m), v in zip(meshes, values)])
        return cls(
            vertices=np.concatenate([m.vertices for _, m in meshes]),
            normals=np.concatenate([m.normals for _, m in meshes]),
            uv=uv,
            faces=faces,
            face_object=per_face(range(len(meshes))).astype(np.int32),
            vertex_specular=per_vertex([m.material.specular for _, m in meshes]),
            vertex_shininess=per_vertex([m.material.shininess for _, m in meshes]),
            face_texel_area=texel_area,
            atlas=atlas,
            object_names=tuple(name for name, _ in meshes),
            light_dir=light_dir / np.linalg.norm(light_dir),
        )


@numba.njit(cache=True, nogil=True, fastmath=True, error_model="numpy")
def _rasterize(px, py, inv_z, faces, visible, width, height, depth, tri, b1, b2):
    """Z-buffer scan conversion. px, py : (n,) projected vertices (pixels); inv_z : (n,) 1/z.

    depth holds 1/z (larger is nearer, 0 = empty); b1, b2 are perspective-correct barycentrics of vertices 1, 2.
    """
    for f in range(faces.shape[0]):
        if not visible[f]:
            continue
        i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
        x0, y0, x1, y1, x2, y2 = px[i0], py[i0], px[i1], py[i1], px[i2], py[i2]
        area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        if abs(area) < 1e-12:
            continue
        xmin = max(int(np.ceil(min(x0, x1, x2))), 0)
        xmax = min(int(np.floor(max(x0, x1, x2))), width - 1)
        ymin = max(int(np.ceil(min(y0, y1, y2))), 0)
        ymax = min(int(np.floor(max(y0, y1, y2))), height - 1)
        inv_area = 1.0 / area
        z0, z1, z2 = inv_z[i0], inv_z[i1], inv_z[i2]
        for y in range(ymin, ymax + 1):
            for x in range(xmin, xmax + 1):
                w1 = ((x - x0) * (y2 - y0) - (x2 - x0) * (y - y0)) * inv_area  # screen-space barycentrics
                w2 = ((x1 - x0) * (y - y0) - (x - x0) * (y1 - y0)) * inv_area
                w0 = 1.0 - w1 - w2
                if w0 < -1e-7 or w1 < -1e-7 or w2 < -1e-7:
                    continue
                iz = w0 * z0 + w1 * z1 + w2 * z2  # 1/z is affine in screen space
                if iz > depth[y, x]:
                    depth[y, x] = iz
                    tri[y, x] = f
                    b1[y, x] = w1 * z1 / iz  # perspective-correct: attribute/z is affine in screen space
                    b2[y, x] = w2 * z2 / iz


@numba.njit(cache=True, nogil=True, fastmath=True, error_model="numpy")
def _sample(mip, offset, width, height, level, u, v):
    """Bilinear sample of mip level ``level`` at level-0 atlas coordinates (u, v); albedo in [0, 1]."""
    s = 1.0 / (1 << level)  # cv2.pyrDown centres level-k pixel i on level-0 pixel 2^k i
    x = u * s
    y = v * s
    w, h = width[level], height[level]
    x = min(max(x, 0.0), w - 1.001)
    y = min(max(y, 0.0), h - 1.001)
    xi, yi = int(x), int(y)
    fx, fy = x - xi, y - yi
    base = offset[level] + yi * w + xi
    top = mip[base] * (1 - fx) + mip[base + 1] * fx
    bottom = mip[base + w] * (1 - fx) + mip[base + w + 1] * fx
    return (top * (1 - fy) + bottom * fy) / 255.0


@numba.njit(cache=True, nogil=True, fastmath=True, error_model="numpy")
def _shade(tri, b1, b2, faces, uv, face_lod, diffuse, specular, mip, offset, width, height, out):
    """Per-pixel shading: trilinear albedo x interpolated diffuse light + interpolated specular light."""
    n_levels = offset.shape[0]
    for y in range(tri.shape[0]):
        for x in range(tri.shape[1]):
            f = tri[y, x]
            if f < 0:
                out[y, x] = BACKGROUND
                continue
            c1, c2 = b1[y, x], b2[y, x]
            c0 = 1.0 - c1 - c2
            i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
            u = c0 * uv[i0, 0] + c1 * uv[i1, 0] + c2 * uv[i2, 0]
            v = c0 * uv[i0, 1] + c1 * uv[i1, 1] + c2 * uv[i2, 1]
            lod = min(max(face_lod[f], 0.0), n_levels - 1.0)
            l0 = min(int(lod), n_levels - 2)
            t = lod - l0
            if t < 1e-3:  # magnified or exactly on a level: one bilinear sample is enough
                albedo = _sample(mip, offset, width, height, l0, u, v)
            else:
                albedo = (1 - t) * _sample(mip, offset, width, height, l0, u, v) + t * _sample(
                    mip, offset, width, height, l0 + 1, u, v)
            out[y, x] = albedo * (c0 * diffuse[i0] + c1 * diffuse[i1] + c2 * diffuse[i2]) + (
                c0 * specular[i0] + c1 * specular[i1] + c2 * specular[i2])


def vertex_lighting(normals_cam: np.ndarray, vertices_cam: np.ndarray, light_dir_cam: np.ndarray,
                    specular: np.ndarray, shininess: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gouraud shading terms per vertex (interpolated across faces by :func:`_shade`).

    diffuse = ambient + ring light (at the camera centre) x max(n.v, 0) + room light x max(n.l, 0);
    specular = k_s (ring x (n.v)^s + room x (n.h)^s), Blinn-Phong with h = (l + v) / |l + v|.
    normals_cam, vertices_cam : (n, 3) camera frame; light_dir_cam : (3,) unit, towards the room light.
    """
    view = -vertices_cam / np.linalg.norm(vertices_cam, axis=1, keepdims=True)
    n_dot_v = np.clip(np.einsum("ij,ij->i", normals_cam, view), 0.0, None)
    n_dot_l = np.clip(normals_cam @ light_dir_cam, 0.0, None)
    half = view + light_dir_cam
    half /= np.linalg.norm(half, axis=1, keepdims=True)
    n_dot_h = np.where(n_dot_l > 0, np.clip(np.einsum("ij,ij->i", normals_cam, half), 0.0, None), 0.0)
    diffuse = AMBIENT + RING_LIGHT * n_dot_v + ROOM_LIGHT * n_dot_l
    highlight = specular * (RING_LIGHT * n_dot_v**shininess + ROOM_LIGHT * n_dot_h**shininess)
    return diffuse, highlight


@dataclass(frozen=True)
class Render:
    """radiance : (h, w) float32, 1 = white surface under full light; object_index : (h, w) int32, -1 = none;
    depth_mm : (h, w) float32 along z, inf where empty."""

    radiance: np.ndarray
    object_index: np.ndarray
    depth_mm: np.ndarray


def render(scene: SceneGeometry, K: np.ndarray, width: int, height: int, T_cam_world: np.ndarray) -> Render:
    """Noise-free radiance image of ``scene`` seen by a pinhole camera K at pose T_cam_world."""
    R, t = T_cam_world[:3, :3], T_cam_world[:3, 3]
    v_cam = scene.vertices @ R.T + t
    n_cam = scene.normals @ R.T
    z = v_cam[:, 2]
    safe_z = np.where(z > NEAR_MM, z, 1.0)
    px = K[0, 0] * v_cam[:, 0] / safe_z + K[0, 2]
    py = K[1, 1] * v_cam[:, 1] / safe_z + K[1, 2]
    f = scene.faces
    in_front = (z[f] > NEAR_MM).all(axis=1)
    p0, p1, p2 = (v_cam[f[:, i]] for i in range(3))
    facing = np.einsum("ij,ij->i", np.cross(p1 - p0, p2 - p0), p0) < 0  # back-face culling
    x0, y0 = px[f[:, 0]], py[f[:, 0]]
    screen_area = 0.5 * np.abs((px[f[:, 1]] - x0) * (py[f[:, 2]] - y0) - (px[f[:, 2]] - x0) * (py[f[:, 1]] - y0))
    visible = in_front & facing & (screen_area > 1e-9)
    # mip level: log2 of texels per pixel, from the ratio of the face's texture and screen areas
    face_lod = 0.5 * np.log2(np.maximum(scene.face_texel_area, 1e-9) / np.maximum(screen_area, 1e-9))

    depth = np.zeros((height, width), np.float64)
    tri = np.full((height, width), -1, np.int32)
    b1 = np.zeros((height, width), np.float64)
    b2 = np.zeros((height, width), np.float64)
    _rasterize(px, py, np.where(z > NEAR_MM, 1.0 / safe_z, 0.0), f, visible, width, height, depth, tri, b1, b2)
    radiance = np.empty((height, width), np.float32)
    a = scene.atlas
    diffuse, highlight = vertex_lighting(n_cam, v_cam, R @ scene.light_dir, scene.vertex_specular,
                                         scene.vertex_shininess)
    _shade(tri, b1, b2, f, scene.uv, face_lod, diffuse, highlight, a.mip, a.offset, a.width, a.height, radiance)
    object_index = np.where(tri >= 0, scene.face_object[np.maximum(tri, 0)], -1).astype(np.int32)
    with np.errstate(divide="ignore"):
        depth_mm = np.where(depth > 0, 1.0 / depth, np.inf).astype(np.float32)
    return Render(radiance, object_index, depth_mm)


def optics(radiance: np.ndarray, sensor: SensorParams, defocus_sigma_px: float = 0.0) -> np.ndarray:
    """The lens: (h, w) radiance -> (h, w) irradiance on the sensor, blurred by a Gaussian combining the lens'
    own blur and the defocus of the target's depth (one sigma for the whole frame: the scene's objects of
    interest lie near the target's depth).

    Done once per robot stop: blur is linear and flicker is a scalar gain, so the two commute.
    """
    sigma = float(np.hypot(sensor.blur_sigma_px, defocus_sigma_px))
    if sigma <= 0:
        return radiance
    return cv2.GaussianBlur(radiance, (0, 0), sigma)


def expose(irradiance: np.ndarray, sensor: SensorParams, rng: np.random.Generator) -> np.ndarray:
    """The sensor: (h, w) irradiance -> (h, w) uint8 image.

    DN = exposure x flicker gain x irradiance, plus Gaussian noise of variance read_noise^2 + shot_noise x DN
    (the Poisson-Gaussian model of a CMOS sensor), rounded and clipped to 8 bit.
    """
    gain = sensor.exposure * (1.0 + sensor.flicker * rng.standard_normal())
    dn = irradiance * np.float32(gain)
    noise = rng.standard_normal(dn.shape, dtype=np.float32)
    noise *= np.sqrt(np.float32(sensor.read_noise_dn**2) + np.float32(sensor.shot_noise_dn_per_dn) * np.maximum(dn, 0))
    dn += noise
    np.rint(dn, out=dn)
    np.clip(dn, 0, 255, out=dn)
    return dn.astype(np.uint8)
