"""The renderer against independent references: OpenCV's perspective warp of a flat texture, analytic depth and
Lambert shading, the z-buffer's order independence, mip-mapping's anti-aliasing, and the bone foam's
viewpoint-dependent appearance."""

import cv2
import numpy as np
import pytest

from poseintegrity.config import load_params
from poseintegrity.scenes import foam, mesh, renderer
from poseintegrity.scenes.textures import build_atlas
from repository import ROOT

GENERATE = load_params(ROOT / "params.yaml").generate

W, H = 320, 240
K = np.array([[300.0, 0, (W - 1) / 2], [0, 300.0, (H - 1) / 2], [0, 0, 1]])
NO_SPECULAR = mesh.Material(specular=0.0)
LIGHTS = (0.2, 0.7, 0.3, 0.05)  # ambient, ring, room, background
FLAT = foam.ReliefVolume(np.zeros((8, 8, 8), np.float32), 0.125, 0.2, 0.0, 1.0)  # no relief, no mottling
# the phantoms' foam with more contrast between pores and bumps, unmottled, on a smaller grid
RELIEF = foam.bone_foam_relief(
    GENERATE.bone_foam.model_copy(update={"pore_fraction": 0.05, "bump_slope": 0.1, "albedo_std": 0.0}), 0, n=64)


def smooth_texture(seed: int, size: int = 256, sigma: float = 3.0) -> np.ndarray:
    """Band-limited noise: point-sampled references (warpPerspective) do not alias on it."""
    noise = np.random.default_rng(seed).uniform(0, 255, (size, size)).astype(np.float32)
    return cv2.normalize(cv2.GaussianBlur(noise, (0, 0), sigma), None, 20, 235, cv2.NORM_MINMAX).astype(np.uint8)


def pose(R, t) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def geometry(named_meshes, textures, relief=FLAT, light_dir=(0.0, 0.0, -1.0)):
    return renderer.SceneGeometry.from_meshes(named_meshes, build_atlas(textures or {"none": np.zeros((8, 8), np.uint8)}),
                                              np.array(light_dir), LIGHTS, relief)


def plane_facing_camera(size_mm, texture, T_cam_plane):
    """A plane in the camera frame; plane() faces +z, flip it to face the camera (-z)."""
    flip = pose(np.diag([1.0, -1.0, -1.0]), [0, 0, 0])
    return mesh.plane(size_mm, size_mm, 8, 8, texture, material=NO_SPECULAR).transformed(T_cam_plane @ flip)


@pytest.mark.parametrize("tilt_deg", [0.0, 50.0])
def test_textured_plane_matches_opencv_homography_warp(tilt_deg):
    texture = smooth_texture(1, sigma=6.0)
    R = cv2.Rodrigues(np.array([np.deg2rad(tilt_deg), 0.2, 0.1]))[0]
    T_cam_plane = pose(R, [5.0, -3.0, 400.0])
    geo = geometry([("p", plane_facing_camera(200.0, "tex", T_cam_plane))], {"tex": texture})
    out = renderer.render(geo, K, W, H, np.eye(4))
    # texture pixel (c, r) -> point (x, y, 0) of the frame T_cam_plane: x = (c/(n-1) - 0.5) s, y = (r/(n-1) - 0.5) s
    n, s = texture.shape[0], 200.0
    S = np.array([[s / (n - 1), 0, -s / 2], [0, s / (n - 1), -s / 2], [0, 0, 1]])
    Hmg = K @ np.column_stack([R[:, 0], R[:, 1], T_cam_plane[:3, 3]]) @ S
    covered = cv2.warpPerspective(np.full_like(texture, 255), Hmg, (W, H), flags=cv2.INTER_NEAREST) > 0
    rendered_mask = out.object_index == 0
    iou = (rendered_mask & covered).sum() / (rendered_mask | covered).sum()
    assert iou > 0.98
    inside = cv2.erode(rendered_mask.astype(np.uint8), np.ones((9, 9), np.uint8)) > 0
    a = out.radiance[inside] - out.radiance[inside].mean()

    def ncc(dx: float, dy: float) -> float:
        """Correlation with the reference shifted by (dx, dy) px (shading varies slowly: NCC ignores it)."""
        shifted = np.array([[1, 0, dx], [0, 1, dy], [0, 0, 1]]) @ Hmg
        b = cv2.warpPerspective(texture, shifted, (W, H), flags=cv2.INTER_LINEAR).astype(np.float32)[inside]
        b = b - b.mean()
        return float(a @ b / np.sqrt((a @ a) * (b @ b)))

    centred = ncc(0.0, 0.0)
    assert centred > 0.95
    # registered to better than a quarter pixel: every shifted reference correlates less
    for dx, dy in [(0.25, 0), (-0.25, 0), (0, 0.25), (0, -0.25)]:
        assert ncc(dx, dy) < centred


def test_depth_buffer_holds_analytic_depth():
    geo = geometry([("p", plane_facing_camera(1200.0, "tex", pose(np.eye(3), [0, 0, 500.0])))],
                   {"tex": smooth_texture(2)})
    out = renderer.render(geo, K, W, H, np.eye(4))
    assert (out.object_index == 0).all()
    np.testing.assert_allclose(out.depth_mm, 500.0, rtol=1e-5)


def test_zbuffer_keeps_the_nearest_surface_whatever_the_drawing_order():
    near = ("near", plane_facing_camera(60.0, "a", pose(np.eye(3), [-10, 0, 300.0])))
    far = ("far", plane_facing_camera(200.0, "b", pose(np.eye(3), [0, 0, 600.0])))
    textures = {"a": smooth_texture(3), "b": smooth_texture(4)}
    first = renderer.render(geometry([near, far], textures), K, W, H, np.eye(4))
    second = renderer.render(geometry([far, near], textures), K, W, H, np.eye(4))
    names_first = np.array(["near", "far", "none"])[first.object_index]  # index -1: nothing
    names_second = np.array(["far", "near", "none"])[second.object_index]
    assert (names_first == names_second).all()
    np.testing.assert_allclose(first.radiance, second.radiance, atol=1e-6)
    # the near plane covers x in [-40, 20] mm at z = 300: u = 300 x / 300 + cx
    row = names_first[H // 2]
    near_cols = np.flatnonzero(row == "near")
    assert near_cols.min() == pytest.approx(-40 + K[0, 2], abs=1.5)
    assert near_cols.max() == pytest.approx(20 + K[0, 2], abs=1.5)


def test_back_faces_are_culled_and_a_closed_box_shows_its_front():
    box = mesh.box((100.0, 100.0, 100.0), "a", material=NO_SPECULAR).transformed(pose(np.eye(3), [0, 0, 500.0]))
    out = renderer.render(geometry([("box", box)], {"a": smooth_texture(5)}), K, W, H, np.eye(4))
    centre = out.depth_mm[H // 2 - 5: H // 2 + 5, W // 2 - 5: W // 2 + 5]
    np.testing.assert_allclose(centre, 450.0, rtol=1e-5)  # the face at z = 450, not the one at 550


def test_mip_mapping_prevents_aliasing_of_fine_texture():
    checker = (np.indices((512, 512)).sum(axis=0) % 2 * 200 + 28).astype(np.uint8)  # 1-texel checkerboard
    far = plane_facing_camera(150.0, "c", pose(np.eye(3), [0, 0, 900.0]))  # ~50 px for 512 texels
    out = renderer.render(geometry([("c", far)], {"c": checker}), K, W, H, np.eye(4))
    inside = cv2.erode((out.object_index == 0).astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
    values = out.radiance[inside]
    assert values.std() < 0.05 * values.mean()  # point sampling would give a noisy 28 / 228 pattern


def test_expose_is_seeded_and_models_noise():
    sensor = GENERATE.sensor.model_copy(update={"flicker": 0.0, "blur_sigma_px": 0.0, "read_noise_dn": 2.0,
                                                "shot_noise_dn_per_dn": 0.0})
    radiance = np.full((200, 200), 0.5, np.float32)
    a = renderer.expose(radiance, sensor, np.random.default_rng(1))
    b = renderer.expose(radiance, sensor, np.random.default_rng(1))
    assert a.dtype == np.uint8 and (a == b).all()
    assert a.mean() == pytest.approx(0.5 * sensor.exposure, abs=0.1)
    assert a.std() == pytest.approx(np.sqrt(4.0 + 1 / 12), rel=0.05)  # read noise + rounding


def numpy_expose(irradiance, sensor, rng):
    """The sensor model written as whole-array numpy float32 operations, in expose's order of draws."""
    gain = sensor.exposure * (1.0 + sensor.flicker * rng.standard_normal())
    dn = irradiance * np.float32(gain)
    noise = rng.standard_normal(dn.shape, dtype=np.float32)
    dn += noise * np.sqrt(np.float32(sensor.read_noise_dn**2) + np.float32(sensor.shot_noise_dn_per_dn)
                          * np.maximum(dn, 0))
    return np.clip(np.rint(dn), 0, 255).astype(np.uint8)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_expose_equals_the_numpy_sensor_model_bit_for_bit(seed):
    """Below zero, above full scale, exact half-DN ties (rounded to even) and everything between."""
    sensor = GENERATE.sensor.model_copy(update={"flicker": 0.0, "read_noise_dn": 0.0, "shot_noise_dn_per_dn": 0.0})
    ties = np.arange(-2.5, 258.5, 0.5, dtype=np.float32) / np.float32(sensor.exposure)
    assert (renderer.expose(ties[None], sensor, np.random.default_rng(seed))
            == numpy_expose(ties[None], sensor, np.random.default_rng(seed))).all()
    irradiance = np.random.default_rng(seed).uniform(-0.2, 1.6, (97, 131)).astype(np.float32)
    image = renderer.expose(irradiance, GENERATE.sensor, np.random.default_rng([seed, 9]))
    assert (image == numpy_expose(irradiance, GENERATE.sensor, np.random.default_rng([seed, 9]))).all()
    assert 0 < (image == 0).mean() < 1 and 0 < (image == 255).mean() < 1  # both clips were exercised


def test_smooth_surfaces_follow_the_lambert_and_blinn_phong_model():
    """A tilted foam plane without relief: radiance = albedo (ambient + ring n.v + room n.l) + k_s (ring (n.v)^s +
    room (n.h)^s) per pixel, with v towards the camera (the ring light) and l the room light."""
    R = cv2.Rodrigues(np.array([0.5, -0.3, 0.0]))[0]
    material = mesh.Material(specular=0.1, shininess=10.0, foam_albedo=0.7)
    plane = mesh.plane(400.0, 400.0, 4, 4, None, material=material)
    placed = plane.transformed(pose(R, [10.0, -5.0, 500.0]) @ pose(np.diag([1.0, -1.0, -1.0]), [0, 0, 0]))
    light = np.array([0.3, -0.5, -1.0]) / np.linalg.norm([0.3, -0.5, -1.0])
    out = renderer.render(geometry([("p", placed)], {}, light_dir=light), K, W, H, np.eye(4))
    n = -R[:, 2]  # the flipped plane faces the camera
    ys, xs = np.nonzero(out.object_index == 0)
    rays = np.linalg.inv(K) @ np.vstack([xs, ys, np.ones_like(xs)])
    v = -(rays / np.linalg.norm(rays, axis=0)).T
    n_dot_v, n_dot_l = np.clip(v @ n, 0, None), max(n @ light, 0.0)
    half = (v + light) / np.linalg.norm(v + light, axis=1, keepdims=True)
    ambient, ring, room, _ = LIGHTS
    expected = 0.7 * (ambient + ring * n_dot_v + room * n_dot_l) + 0.1 * (
        ring * n_dot_v**10 + room * np.clip(half @ n, 0, None) ** 10)
    np.testing.assert_allclose(out.radiance[ys, xs], expected, rtol=1e-5)
    assert out.radiance[out.object_index < 0] == pytest.approx(LIGHTS[3])


def test_bone_foam_changes_with_the_viewpoint_where_print_only_deforms():
    """Turn the camera 6 deg about a plane's centre and warp the view back onto the first one with the plane's
    homography: printed albedo comes back (it only deforms), the foam's ring-lit relief does not (its shading
    depends on the direction it is seen from)."""
    foam_mat = mesh.Material(specular=0.0, foam_albedo=0.8)

    def similarity(named_mesh, textures, relief):
        geo = geometry([named_mesh], textures, relief)
        T_plane = pose(np.eye(3), [0.0, 0.0, 300.0])
        views = []
        for angle in (0.0, 6.0):
            R = cv2.Rodrigues(np.array([0.0, np.radians(angle), 0.0]))[0]
            T_cam_world = pose(R, T_plane[:3, 3] - R @ T_plane[:3, 3])  # turned about the plane's centre
            views.append((T_cam_world, renderer.render(geo, K, W, H, T_cam_world).radiance))
        (_, first), (T1, second) = views  # view 0 is the world frame
        # plane n.X = d (n = +z, d = 300): pixels of view 0 map to view 1 by H01 = K (R + t n^T / d) K^-1
        H01 = K @ (T1[:3, :3] + np.outer(T1[:3, 3], [0.0, 0.0, 1.0]) / 300.0) @ np.linalg.inv(K)
        back = cv2.warpPerspective(second, H01, (W, H), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP)
        inner = (slice(60, H - 60), slice(90, W - 90))
        a, b = first[inner] - first[inner].mean(), back[inner] - back[inner].mean()
        return float((a * b).sum() / np.sqrt((a * a).sum() * (b * b).sum()))

    flip = pose(np.diag([1.0, -1.0, -1.0]), [0, 0, 300.0])
    printed = ("p", mesh.plane(300.0, 300.0, 8, 8, "t", material=NO_SPECULAR).transformed(flip))
    foamed = ("p", mesh.plane(300.0, 300.0, 8, 8, None, material=foam_mat).transformed(flip))
    print_similarity = similarity(printed, {"t": smooth_texture(9, sigma=2.0)}, FLAT)
    foam_similarity = similarity(foamed, {}, RELIEF)
    assert print_similarity > 0.95
    assert foam_similarity < print_similarity - 0.15
