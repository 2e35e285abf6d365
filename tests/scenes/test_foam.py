"""The bone-foam solid texture: its derivatives against finite differences, its statistics against its parameters."""

import numpy as np
import pytest

from poseintegrity.scenes import foam


@pytest.fixture(scope="module")
def relief():
    return foam.relief_volume(np.random.default_rng(3), n=32, voxel_mm=0.125, pore_radius_mm=0.2,
                              pore_fraction=0.1, pore_depth=1.0, bump_slope=0.1, albedo_std=0.05, albedo_mottle_mm=1.0)


def height(relief, p, footprint):
    """h(p) written out from the octave definition (module docstring), for finite differences."""
    total = 0.0
    for k in range(foam.N_OCTAVES):
        scale = 2.0**k
        weight = min(max(relief.pore_radius_mm * scale / footprint - 0.5, 0.0), 1.0)
        q = foam.OCTAVE_ROTATIONS[k] @ p / (scale * relief.voxel_mm)
        total += weight * scale * relief.voxel_mm * foam.trilinear_gradient(relief.height, *q)[0] / relief.voxel_mm
    return total


def test_trilinear_gradient_is_the_derivative_of_its_value_and_periodic(relief):
    rng = np.random.default_rng(0)
    n = relief.height.shape[0]
    for x, y, z in rng.uniform(0, n, (20, 3)):
        value, *grad = foam.trilinear_gradient(relief.height, x, y, z)
        h = 1e-4
        numeric = [(foam.trilinear_gradient(relief.height, *(np.array([x, y, z]) + h * e))[0]
                    - foam.trilinear_gradient(relief.height, *(np.array([x, y, z]) - h * e))[0]) / (2 * h)
                   for e in np.eye(3)]
        np.testing.assert_allclose(grad, numeric, atol=1e-3)
        assert foam.trilinear_gradient(relief.height, x + n, y - 2 * n, z)[0] == pytest.approx(value, abs=1e-6)
    # at a grid point the value is the voxel
    assert foam.trilinear_gradient(relief.height, 3.0, 4.0, 5.0)[0] == pytest.approx(relief.height[3, 4, 5])


def test_trilinear_value_matches_scipy_periodic_interpolation_across_the_wrap(relief):
    """Points on both sides of the period's edges and far outside it (negative too): scipy's order-1
    map_coordinates with grid-wrap is the reference for the bit-mask wrapping."""
    from scipy.ndimage import map_coordinates

    n = relief.height.shape[0]
    points = np.random.default_rng(4).uniform(-2.5 * n, 2.5 * n, (300, 3))
    points[:6] = [[-0.5, 0.2, 0.3], [n - 0.5, 3.2, n - 0.25], [-n - 0.7, -0.1, 2 * n - 0.9], [0.0, -1e-9, 0.5],
                  [n - 1e-9, n, -n], [-3 * n + 0.25, 7.5, -0.75]]
    values = [foam.trilinear_gradient(relief.height, *p)[0] for p in points]
    reference = map_coordinates(relief.height.astype(np.float64), points.T, order=1, mode="grid-wrap")
    np.testing.assert_allclose(values, reference, atol=1e-6)


@pytest.mark.parametrize("shape", [(12, 12, 12), (16, 16, 8), (1, 1, 1)])
def test_a_relief_volume_is_a_cube_of_a_power_of_two_voxels(shape):
    with pytest.raises(ValueError, match="power of two"):
        foam.ReliefVolume(np.zeros(shape, np.float32), 0.125, 0.2, 0.0, 1.0)


@pytest.mark.parametrize("footprint", [0.05, 0.3, 0.7])
def test_relief_gradient_is_the_gradient_of_the_octave_sum(relief, footprint):
    rng = np.random.default_rng(1)
    for p in rng.uniform(-30, 30, (10, 3)):
        grad = foam.relief_gradient(relief.height, relief.voxel_mm, relief.pore_radius_mm, foam.OCTAVE_ROTATIONS,
                                    *p, footprint)
        h = 1e-4
        numeric = [(height(relief, p + h * e, footprint) - height(relief, p - h * e, footprint)) / (2 * h)
                   for e in np.eye(3)]
        np.testing.assert_allclose(grad, numeric, atol=2e-3)


def test_octaves_smaller_than_a_pixel_fade_out(relief):
    p = np.array([1.3, -2.1, 0.7])
    args = (relief.height, relief.voxel_mm, relief.pore_radius_mm, foam.OCTAVE_ROTATIONS, *p)
    assert np.allclose(foam.relief_gradient(*args, 100.0), 0.0)  # every pore below half a pixel: flat
    assert np.linalg.norm(foam.relief_gradient(*args, 0.01)) > 0


def test_volume_statistics_follow_the_parameters():
    def volume(**kwargs):
        base = dict(n=32, voxel_mm=0.125, pore_radius_mm=0.2, pore_fraction=0.1, pore_depth=1.0, bump_slope=0.1,
                    albedo_std=0.05, albedo_mottle_mm=1.0)
        return foam.relief_volume(np.random.default_rng(5), **(base | kwargs))

    bumps_only = volume(pore_fraction=1e-6)
    slope = np.sqrt(sum(g**2 for g in np.gradient(bumps_only.height, 0.125)).mean())
    assert slope == pytest.approx(0.1, rel=0.05)  # the RMS slope asked for
    assert abs(bumps_only.height.mean()) < 1e-6
    sparse, dense = volume(pore_fraction=0.05, bump_slope=0.0), volume(pore_fraction=0.2, bump_slope=0.0)
    assert (dense.height < -0.05).mean() > 2 * (sparse.height < -0.05).mean()  # more pores, more pitted surface
    assert dense.height.min() < -0.1  # pits: negative heights of the order of the pore depth (0.2 mm)


def test_albedo_modulation_has_unit_mean_and_the_requested_spread(relief):
    rng = np.random.default_rng(2)
    values = [foam.albedo_modulation(relief.height, relief.voxel_mm, relief.albedo_gain, relief.albedo_scale,
                                     foam.OCTAVE_ROTATIONS[-1], *p)
              for p in rng.uniform(-200, 200, (4000, 3))]
    assert np.mean(values) == pytest.approx(1.0, abs=0.01)
    assert np.std(values) == pytest.approx(relief.albedo_std, rel=0.3)  # trilinear smoothing lowers it a little
