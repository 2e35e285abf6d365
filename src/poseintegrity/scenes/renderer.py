"""A small software renderer: perspective z-buffer rasterisation of triangle meshes, per-pixel shading with
trilinear mip-mapped textures or a bone-foam solid texture (relief by bump mapping), Lambert + Blinn-Phong under a
ring light on the camera and a light fixed to the scene, and the sensor: exposure, illumination flicker, shot and
read noise (the lens between them: :mod:`poseintegrity.scenes.optics`, :mod:`poseintegrity.lens`).

Two passes (deferred shading): :func:`_rasterize` keeps, per pixel, the nearest triangle and its
perspective-correct barycentric coordinates; :func:`_shade` then shades each pixel once: it interpolates the
normal (Phong shading), tilts it by the gradient of the foam's height field on bone-foam surfaces (Blinn 1978,
:mod:`poseintegrity.scenes.foam`) and lights it. The ring light sits at the camera centre, so the camera never sees
its shadows (none are rendered); the room light's shadows are not rendered either. Both passes are compiled with
numba; everything else is numpy. Frames: OpenCV camera (x right, y down, z forward), millimetres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from poseintegrity.scenes import foam
from poseintegrity.scenes.foam import ReliefVolume
from poseintegrity.scenes.mesh import Mesh
from poseintegrity.params.camera import SensorParams
from poseintegrity.scenes.textures import TextureAtlas

NEAR_MM = 20.0
MIN_COS_FOOTPRINT = 0.2  # a pixel's footprint on the surface grows as 1 / cos(incidence), capped at 5 x


@dataclass(frozen=True)
class SceneGeometry:
    """Every mesh of a scene in the world frame, flattened for the renderer.

    vertices, normals : (n, 3) float64, world frame; uv : (n, 2) float64, level-0 atlas pixels (textured meshes);
    solid : (n, 3) float64, each vertex in its own object's frame, mm (the coordinates of the foam's solid texture);
    faces : (m, 3) int32; face_object : (m,) int32 object index (into ``object_names``);
    face_texel_area : (m,) float64, texture area of each face in atlas pixels^2 (mip level selection);
    per object (k,): R_world_obj (k, 3, 3), specular, shininess, foam_albedo (0: textured, else bone foam);
    light_dir : (3,) unit vector towards the room light, world frame; lights : (ambient, ring, room, background)
    intensities (radiance of a white surface lit by each; background: what is seen behind everything);
    foam : the bone-foam relief.
    """

    vertices: np.ndarray
    normals: np.ndarray
    uv: np.ndarray
    solid: np.ndarray
    faces: np.ndarray
    face_object: np.ndarray
    face_texel_area: np.ndarray
    R_world_obj: np.ndarray
    specular: np.ndarray
    shininess: np.ndarray
    foam_albedo: np.ndarray
    atlas: TextureAtlas
    object_names: tuple[str, ...]
    light_dir: np.ndarray
    lights: tuple[float, float, float, float]
    foam: ReliefVolume

    @classmethod
    def from_meshes(cls, meshes: list[tuple[str, Mesh]], atlas: TextureAtlas, light_dir: np.ndarray,
                    lights: tuple[float, float, float, float], relief: ReliefVolume) -> "SceneGeometry":
        """``meshes``: (object name, mesh already placed in the world frame) pairs."""
        offsets = np.cumsum([0] + [len(m.vertices) for _, m in meshes[:-1]])
        uv = np.concatenate([atlas.atlas_uv(m.texture, m.uv) if m.texture is not None else np.zeros_like(m.uv)
                             for _, m in meshes])
        faces = np.concatenate([m.faces + o for (_, m), o in zip(meshes, offsets)]).astype(np.int32)
        u0, u1, u2 = (uv[faces[:, i]] for i in range(3))
        texel_area = 0.5 * np.abs((u1[:, 0] - u0[:, 0]) * (u2[:, 1] - u0[:, 1])
                                  - (u2[:, 0] - u0[:, 0]) * (u1[:, 1] - u0[:, 1]))
        solid = np.concatenate([(m.vertices - m.T_world_obj[:3, 3]) @ m.T_world_obj[:3, :3] for _, m in meshes])
        foam_albedo = [0.0 if m.material.foam_albedo is None else m.material.foam_albedo for _, m in meshes]
        return cls(
            vertices=np.concatenate([m.vertices for _, m in meshes]),
            normals=np.concatenate([m.normals for _, m in meshes]),
            uv=uv,
            solid=solid,
            faces=faces,
            face_object=np.concatenate([np.full(len(m.faces), i) for i, (_, m) in enumerate(meshes)]).astype(np.int32),
            face_texel_area=texel_area,
            R_world_obj=np.stack([m.T_world_obj[:3, :3] for _, m in meshes]),
            specular=np.array([m.material.specular for _, m in meshes], float),
            shininess=np.array([m.material.shininess for _, m in meshes], float),
            foam_albedo=np.array(foam_albedo, float),
            atlas=atlas,
            object_names=tuple(name for name, _ in meshes),
            light_dir=light_dir / np.linalg.norm(light_dir),
            lights=tuple(float(v) for v in lights),
            foam=relief,
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
def _shade(tri, b1, b2, inv_depth, faces, uv, solid, normals, face_lod, face_object, R_cam_obj, specular,
           shininess, foam_albedo, light, lights, camera, mip, offset, width, height, relief, albedo_rotation, out):
    """Per-pixel shading (module docstring); writes radiance into ``out``.

    normals : (n, 3) camera frame; R_cam_obj : (k, 3, 3); light : (3,) unit, towards the room light, camera frame;
    lights : (ambient, ring, room, background); camera : (fx, fy, cx, cy);
    relief : (volume, voxel_mm, pore_radius_mm, albedo_gain, albedo_scale, rotations).
    """
    volume, voxel_mm, pore_radius_mm, albedo_gain, albedo_scale, rotations = relief
    ambient, ring, room, background = lights
    fx, fy, cx, cy = camera
    n_levels = offset.shape[0]
    for y in range(tri.shape[0]):
        for x in range(tri.shape[1]):
            f = tri[y, x]
            if f < 0:
                out[y, x] = background
                continue
            c1, c2 = b1[y, x], b2[y, x]
            c0 = 1.0 - c1 - c2
            i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
            obj = face_object[f]
            nx = c0 * normals[i0, 0] + c1 * normals[i1, 0] + c2 * normals[i2, 0]
            ny = c0 * normals[i0, 1] + c1 * normals[i1, 1] + c2 * normals[i2, 1]
            nz = c0 * normals[i0, 2] + c1 * normals[i1, 2] + c2 * normals[i2, 2]
            norm = np.sqrt(nx * nx + ny * ny + nz * nz) + 1e-12
            nx, ny, nz = nx / norm, ny / norm, nz / norm
            # towards the camera (and the ring light on it): minus the pixel's viewing ray
            rx, ry = (x - cx) / fx, (y - cy) / fy
            rn = np.sqrt(rx * rx + ry * ry + 1.0)
            vx, vy, vz = -rx / rn, -ry / rn, -1.0 / rn
            if foam_albedo[obj] > 0.0:  # bone foam: solid texture (0: a textured surface)
                px = c0 * solid[i0, 0] + c1 * solid[i1, 0] + c2 * solid[i2, 0]
                py = c0 * solid[i0, 1] + c1 * solid[i1, 1] + c2 * solid[i2, 1]
                pz = c0 * solid[i0, 2] + c1 * solid[i1, 2] + c2 * solid[i2, 2]
                cos_in = max(abs(nx * vx + ny * vy + nz * vz), MIN_COS_FOOTPRINT)
                footprint = 1.0 / (inv_depth[y, x] * fx * cos_in)  # surface mm spanned by one pixel
                gx, gy, gz = foam.relief_gradient(volume, voxel_mm, pore_radius_mm, rotations, px, py, pz, footprint)
                R = R_cam_obj[obj]
                hx = R[0, 0] * gx + R[0, 1] * gy + R[0, 2] * gz
                hy = R[1, 0] * gx + R[1, 1] * gy + R[1, 2] * gz
                hz = R[2, 0] * gx + R[2, 1] * gy + R[2, 2] * gz
                # bump mapping: n' = normalize(n - (grad h - (grad h . n) n)), the tangential slope tilts n
                hn = hx * nx + hy * ny + hz * nz
                nx, ny, nz = nx - (hx - hn * nx), ny - (hy - hn * ny), nz - (hz - hn * nz)
                norm = np.sqrt(nx * nx + ny * ny + nz * nz) + 1e-12
                nx, ny, nz = nx / norm, ny / norm, nz / norm
                albedo = foam_albedo[obj] * foam.albedo_modulation(volume, voxel_mm, albedo_gain, albedo_scale,
                                                                   albedo_rotation, px, py, pz)
            else:
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
            n_dot_v = max(nx * vx + ny * vy + nz * vz, 0.0)
            n_dot_l = max(nx * light[0] + ny * light[1] + nz * light[2], 0.0)
            hx, hy, hz = vx + light[0], vy + light[1], vz + light[2]
            hn = np.sqrt(hx * hx + hy * hy + hz * hz) + 1e-12
            n_dot_h = max((nx * hx + ny * hy + nz * hz) / hn, 0.0) if n_dot_l > 0.0 else 0.0
            # Lambert under ambient + ring light (at the camera) + room light; Blinn-Phong lobes (ring: h = v)
            diffuse = ambient + ring * n_dot_v + room * n_dot_l
            s = shininess[obj]
            out[y, x] = albedo * diffuse + specular[obj] * (ring * n_dot_v**s + room * n_dot_h**s)


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
    a, relief = scene.atlas, scene.foam
    relief_args = (relief.height, relief.voxel_mm, relief.pore_radius_mm, relief.albedo_gain, relief.albedo_scale,
                   foam.OCTAVE_ROTATIONS)
    _shade(tri, b1, b2, depth, f, scene.uv, scene.solid, scene.normals @ R.T, face_lod, scene.face_object,
           R @ scene.R_world_obj, scene.specular, scene.shininess, scene.foam_albedo, R @ scene.light_dir,
           scene.lights, (K[0, 0], K[1, 1], K[0, 2], K[1, 2]), a.mip, a.offset, a.width, a.height, relief_args,
           foam.OCTAVE_ROTATIONS[-1], radiance)
    object_index = np.where(tri >= 0, scene.face_object[np.maximum(tri, 0)], -1).astype(np.int32)
    with np.errstate(divide="ignore"):
        depth_mm = np.where(depth > 0, 1.0 / depth, np.inf).astype(np.float32)
    return Render(radiance, object_index, depth_mm)


def expose(irradiance: np.ndarray, sensor: SensorParams, rng: np.random.Generator) -> np.ndarray:
    """The sensor: (h, w) irradiance -> (h, w) uint8 image.

    DN = exposure x flicker gain x irradiance, plus Gaussian noise of variance read_noise^2 + shot_noise x DN
    (the Poisson-Gaussian model of a CMOS sensor), rounded and clipped to 8 bit. The draws: the flicker gain, then
    one float32 standard normal per pixel (row-major); the arithmetic is float32.
    """
    gain = sensor.exposure * (1.0 + sensor.flicker * rng.standard_normal())
    noise = rng.standard_normal(irradiance.shape, dtype=np.float32)
    image = np.empty(irradiance.shape, np.uint8)
    _sensor(np.ascontiguousarray(irradiance, np.float32).reshape(-1), np.float32(gain),
            np.float32(sensor.read_noise_dn**2), np.float32(sensor.shot_noise_dn_per_dn), noise.reshape(-1),
            image.reshape(-1))
    return image


@numba.njit(cache=True, nogil=True, error_model="numpy")  # no fastmath: IEEE float32, no reassociation or FMA
def _sensor(irradiance, gain, read_variance, shot_noise, noise, out):
    """One pass over (n,) float32 pixels: out = clip(rint(dn + noise sqrt(read_variance + shot_noise max(dn, 0))),
    0, 255) with dn = gain irradiance; rint rounds half to even (as numpy)."""
    zero = np.float32(0.0)
    for i in range(irradiance.shape[0]):
        dn = irradiance[i] * gain
        dn = np.rint(dn + noise[i] * np.sqrt(read_variance + shot_noise * max(dn, zero)))
        out[i] = np.uint8(min(max(dn, zero), np.float32(255.0)))
