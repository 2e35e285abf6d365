import numpy as np
import pytest
from scipy import stats
from scipy.spatial.transform import Rotation

from poseintegrity.tracking.markers.detection import detect_markers, raw_threshold
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M
from poseintegrity.tracking.simulation.frames import _lit_pixels, background_quantiles, draw_phantoms, intrinsics, render_frame, sensor_ir, skip_raw
from poseintegrity.tracking.simulation.simulate import background_seen

from tracking.track_section import GEOMETRY, TRACK

CAMERA, FRAMES, DETECTION = TRACK.camera, TRACK.frames, TRACK.detection
BACKGROUND, NOISE = FRAMES.ir_background, FRAMES.ir_noise_std


def quantized_normal_pmf(mean: float, std: float, values: np.ndarray) -> np.ndarray:
    """P(clip(rint(mean + std z), 0, 65535) = k) for k in values, z ~ N(0, 1) (scipy)."""
    upper = np.where(values >= 65535, 1.0, stats.norm.cdf(values + 0.5, mean, std))
    lower = np.where(values <= 0, 0.0, stats.norm.cdf(values - 0.5, mean, std))
    return np.where((values < 0) | (values > 65535), 0.0, upper - lower)


def test_the_background_table_gives_each_sensor_value_its_normal_probability():
    table = background_quantiles(BACKGROUND, NOISE)
    values, counts = np.unique(table, return_counts=True)
    assert np.abs(counts / 65536 - quantized_normal_pmf(BACKGROUND, NOISE, values)).max() <= 1 / 65536
    assert table.min() == 0 and table.max() >= BACKGROUND + 4 * NOISE  # +-4.3 sigma, clipped at 0 like the sensor


def chi_square_pvalue(sample: np.ndarray, mean: float, std: float) -> float:
    """Chi-square goodness of fit of integer samples to the quantized normal.  The values of probability below
    1e-3 are pooled into a lower and an upper tail: the inverse-CDF table is exact to 1 / 65536 per value, which
    is a large relative error only out there (beyond 3 std), and it moves mass only within a tail."""
    values = np.arange(max(int(mean - 6 * std), 0), int(mean + 6 * std) + 1)
    p = quantized_normal_pmf(mean, std, values)
    bulk = p >= 1e-3
    lo, hi = values[bulk][0], values[bulk][-1]
    expected = np.r_[stats.norm.cdf(lo - 0.5, mean, std), p[bulk], stats.norm.sf(hi + 0.5, mean, std)] * len(sample)
    observed, _ = np.histogram(sample, np.r_[-np.inf, np.arange(lo, hi + 2) - 0.5, np.inf])
    return stats.chisquare(observed, expected).pvalue


def test_ir_noise_is_the_quantized_normal_on_the_background_and_on_the_reflections():
    """One 512 x 512 image: 3/4 of it background, a quarter lit at 790 so that the pixels straddle the detector's
    threshold (222 of 255 at clip 1000: raw 870.6, i.e. values >= 871): their share above it is the normal tail."""
    rng = np.random.default_rng(3)
    brightness = np.zeros((CAMERA.height, CAMERA.width), np.float32)
    brightness[:128] = 790.0
    lit = np.flatnonzero(brightness > 0)
    ir = np.concatenate([sensor_ir(brightness.shape, lit, brightness.ravel()[lit], FRAMES, rng) for _ in range(4)])
    background = ir[np.tile(brightness == 0, (4, 1))].astype(float)
    lit = ir[np.tile(brightness > 0, (4, 1))].astype(float)
    assert chi_square_pvalue(background, BACKGROUND, NOISE) > 1e-3
    assert chi_square_pvalue(lit, BACKGROUND + 790.0, NOISE) > 1e-3
    raw_threshold = DETECTION.threshold * DETECTION.ir_clip / 255.0
    p_above = stats.norm.sf(np.floor(raw_threshold) + 0.5, BACKGROUND + 790.0, NOISE)
    assert abs((lit > raw_threshold).mean() - p_above) < 4 * np.sqrt(p_above * (1 - p_above) / lit.size)
    assert background.max() < raw_threshold
    assert stats.ks_2samp(background, np.clip(np.rint(BACKGROUND + NOISE * rng.standard_normal(200_000)), 0, None)).pvalue > 1e-3
    # neighbouring pixels are independent (four uniforms share one raw 64-bit word)
    z = (background[: len(background) // 2 * 2] - BACKGROUND) / NOISE
    assert abs(np.corrcoef(z[0::2], z[1::2])[0, 1]) < 4 / np.sqrt(len(z) / 2)


def reference_render(markers_cam, phantoms, camera, frames, marker_radius_m, rng):
    """render_frame written plainly in numpy, noise-free IR (it needs frames.ir_noise_std = 0): brightness and depth
    of every sphere and phantom by ray casting s x s rays per pixel, the draws in render_frame's order."""
    H, W, s = camera.height, camera.width, frames.supersampling
    K = intrinsics(camera)
    offsets = (np.arange(s) + 0.5) / s - 0.5
    du, dv = (g.ravel() for g in np.meshgrid(offsets, offsets))
    brightness = np.zeros((H, W))
    depth = np.full((H, W), np.rint(frames.background_depth_mm))
    frame_bias = rng.normal(0.0, frames.frame_depth_bias_std_mm)

    def rays(u0, u1, v0, v1):
        return np.broadcast_arrays(np.arange(u0, u1)[None, :, None] + du, np.arange(v0, v1)[:, None, None] + dv)

    def compose(patch, cover, surface_mm, level):
        depth[patch] = np.where(cover > 0, np.minimum(depth[patch], np.clip(np.rint(surface_mm), 0, 65535)), depth[patch])
        brightness[patch] = np.maximum(brightness[patch], np.float32(level * cover))

    for c in markers_cam[np.argsort(-markers_cam[:, 2])]:
        u_c, v_c = K[0, 0] * c[0] / c[2] + K[0, 2], K[1, 1] * c[1] / c[2] + K[1, 2]
        rho = camera.focal_px * marker_radius_m / np.sqrt(c[2] ** 2 - marker_radius_m**2) + 2.0
        u0, u1, v0, v1 = max(int(u_c - rho), 0), min(int(u_c + rho) + 2, W), max(int(v_c - rho), 0), min(int(v_c + rho) + 2, H)
        if u0 >= u1 or v0 >= v1:  # outside the image: no draws
            continue
        uu, vv = rays(u0, u1, v0, v1)
        d = np.stack([(uu - K[0, 2]) / K[0, 0], (vv - K[1, 2]) / K[1, 1], np.ones(uu.shape)], axis=-1)
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        proj = d @ c
        disc = marker_radius_m**2 - (c @ c - proj**2)
        near = np.where(disc > 0, (proj - np.sqrt(np.maximum(disc, 0.0))) * 1000.0, np.inf).min(axis=-1)
        bias = frame_bias + rng.normal(0.0, frames.depth_bias_std_mm)
        noise = rng.normal(0.0, frames.depth_noise_mm, near.shape)
        compose((slice(v0, v1), slice(u0, u1)), (disc > 0).mean(axis=-1), near + bias + noise, frames.marker_ir + rng.normal(0.0, frames.marker_ir_std))
    for p in phantoms:
        extent = p.radius_px * p.elongation + 2.0
        u0, u1 = max(int(p.u - extent), 0), min(int(p.u + extent) + 2, W)
        v0, v1 = max(int(p.v - extent), 0), min(int(p.v + extent) + 2, H)
        uu, vv = rays(u0, u1, v0, v1)
        a = ((uu - p.u) * np.cos(p.angle) + (vv - p.v) * np.sin(p.angle)) / (p.radius_px * p.elongation)
        b = (-(uu - p.u) * np.sin(p.angle) + (vv - p.v) * np.cos(p.angle)) / p.radius_px
        noise = rng.normal(0.0, frames.depth_noise_mm, (v1 - v0, u1 - u0))
        compose((slice(v0, v1), slice(u0, u1)), (a * a + b * b <= 1.0).mean(axis=-1), p.depth_mm + noise, frames.marker_ir + rng.normal(0.0, frames.marker_ir_std))
    return np.clip(np.rint(frames.ir_background + brightness.astype(np.float32)), 0, 65535), depth


def test_render_frame_ray_casts_like_the_numpy_reference():
    """Markers from 2 cm (a patch larger than the image part it covers) to 1 m, some outside the image, and
    phantoms: with the IR noise off, IR and depth equal the plain numpy ray casting to the bit."""
    frames = FRAMES.model_copy(update={"ir_noise_std": 0.0})
    drawn = 0
    for seed in range(40):
        rng = np.random.default_rng(seed)
        n = int(rng.integers(1, 5))
        centre = [rng.uniform(-0.25, 0.25), rng.uniform(-0.25, 0.25), rng.uniform(0.02, 1.0)]
        markers = GEOMETRY[:n] @ Rotation.random(random_state=seed).as_matrix().T + centre
        markers = markers[markers[:, 2] > MARKER_DIAMETER_M / 2]
        phantoms = draw_phantoms(int(rng.integers(0, 4)), CAMERA, frames, 0.5, rng)
        ir, depth = render_frame(markers, phantoms, CAMERA, frames, MARKER_DIAMETER_M / 2, np.random.default_rng(seed))
        ref_ir, ref_depth = reference_render(markers, phantoms, CAMERA, frames, MARKER_DIAMETER_M / 2, np.random.default_rng(seed))
        np.testing.assert_array_equal(depth, ref_depth)
        np.testing.assert_array_equal(ir, ref_ir)
        drawn += (ir > BACKGROUND).any()
    assert drawn >= 30  # most frames show a marker or a phantom


def test_render_frame_with_ir_noise_off_still_matches_with_a_flat_background():
    """The flat-background path (background_noise=False) draws the same reflections: with the IR noise off it is
    the same image as the reference, background included."""
    frames = FRAMES.model_copy(update={"ir_noise_std": 0.0})
    for seed in range(10):
        rng = np.random.default_rng(seed)
        markers = GEOMETRY @ Rotation.random(random_state=seed).as_matrix().T + [rng.uniform(-0.2, 0.2), 0.0, rng.uniform(0.3, 0.9)]
        phantoms = draw_phantoms(3, CAMERA, frames, 0.3, rng)
        ir, depth = render_frame(markers, phantoms, CAMERA, frames, MARKER_DIAMETER_M / 2, np.random.default_rng(seed), False)
        ref_ir, ref_depth = reference_render(markers, phantoms, CAMERA, frames, MARKER_DIAMETER_M / 2, np.random.default_rng(seed))
        np.testing.assert_array_equal(depth, ref_depth)
        np.testing.assert_array_equal(ir, ref_ir)


@pytest.mark.parametrize("buffered", [False, True])
def test_skip_raw_leaves_the_generator_where_random_raw_does(buffered):
    """Skipping n raw words equals drawing them, also when a float32 draw left half a word buffered (which
    PCG64.advance alone would drop): the next draws of every kind are the same."""
    drawn, skipped = np.random.default_rng(5), np.random.default_rng(5)
    for rng in (drawn, skipped):
        rng.standard_normal(3 if buffered else 2, dtype=np.float32)
    assert drawn.bit_generator.state["has_uint32"] == int(buffered)
    drawn.bit_generator.random_raw(65536)
    skip_raw(skipped, 65536)
    assert drawn.bit_generator.state == skipped.bit_generator.state
    np.testing.assert_array_equal(drawn.standard_normal(5, dtype=np.float32), skipped.standard_normal(5, dtype=np.float32))
    np.testing.assert_array_equal(drawn.normal(0.0, 1.0, 5), skipped.normal(0.0, 1.0, 5))


def test_a_flat_background_differs_only_where_nothing_reflects_and_detects_the_same():
    """background_noise=False: the same depth, the same value on every lit pixel, rint(ir_background) elsewhere, the
    generator in the same state afterwards, and the same detected points (the detector's threshold is far above
    the background's largest value)."""
    K = intrinsics(CAMERA)
    lit_seen = 0
    for seed in range(20):
        rng = np.random.default_rng(seed)
        markers = GEOMETRY @ Rotation.random(random_state=seed).as_matrix().T + [rng.uniform(-0.1, 0.1), 0.0, rng.uniform(0.35, 0.9)]
        phantoms = draw_phantoms(int(rng.integers(0, 3)), CAMERA, FRAMES, 0.5, rng)
        noisy_rng, flat_rng = np.random.default_rng(seed), np.random.default_rng(seed)
        ir, depth = render_frame(markers, phantoms, CAMERA, FRAMES, MARKER_DIAMETER_M / 2, noisy_rng)
        flat_ir, flat_depth = render_frame(markers, phantoms, CAMERA, FRAMES, MARKER_DIAMETER_M / 2, flat_rng, False)
        np.testing.assert_array_equal(flat_depth, depth)
        lit = depth < FRAMES.background_depth_mm  # where a marker or phantom was drawn
        np.testing.assert_array_equal(flat_ir[lit], ir[lit])
        assert np.all(flat_ir[~lit] == np.rint(BACKGROUND)) and np.any(ir[~lit] != np.rint(BACKGROUND))
        assert noisy_rng.bit_generator.state == flat_rng.bit_generator.state
        np.testing.assert_array_equal(detect_markers(flat_ir, depth, K, DETECTION), detect_markers(ir, depth, K, DETECTION))
        lit_seen += lit.sum()
    assert lit_seen > 1000


def test_lit_pixels_inside_patches_are_flatnonzero_of_the_image():
    """_lit_pixels on the box (from origin) around the patches gives the flat indices np.flatnonzero finds in the
    whole image, and their brightness."""
    rng = np.random.default_rng(2)
    for _ in range(50):
        brightness = np.zeros((64, 80), np.float32)
        patches = []
        for _ in range(int(rng.integers(0, 5))):
            v0, u0 = int(rng.integers(0, 64)), int(rng.integers(0, 80))
            v1, u1 = min(v0 + int(rng.integers(0, 20)), 64), min(u0 + int(rng.integers(0, 20)), 80)
            brightness[v0:v1, u0:u1] = np.where(rng.random((v1 - v0, u1 - u0)) < 0.5, rng.uniform(1, 9, (v1 - v0, u1 - u0)), 0.0)
            patches.append((v0, v1, u0, u1))
        patches = np.array(patches, dtype=np.int64).reshape(-1, 4)
        drawn = patches[(patches[:, 0] < patches[:, 1]) & (patches[:, 2] < patches[:, 3])]
        v0, v1, u0, u1 = (drawn[:, 0].min(), drawn[:, 1].max(), drawn[:, 2].min(), drawn[:, 3].max()) if len(drawn) else (0, 0, 0, 0)
        lit, reflected = _lit_pixels(brightness[v0:v1, u0:u1], (int(v0), int(u0)), patches, 80)
        np.testing.assert_array_equal(lit, np.flatnonzero(brightness > 0))
        np.testing.assert_array_equal(reflected, brightness.ravel()[lit])


def test_the_background_is_seen_only_by_a_detector_whose_threshold_it_can_reach():
    assert not background_seen(TRACK, [DETECTION])  # raw 870.6 against a largest background value of ~188
    low = DETECTION.model_copy(update={"threshold": 40})  # raw 157: within the background's +-4.3 sigma
    assert background_quantiles(BACKGROUND, NOISE).max() > raw_threshold(low, np.uint16)
    assert background_seen(TRACK, [DETECTION, low])
