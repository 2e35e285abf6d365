import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.tracking.filter.tracker import MarkerTracker
from poseintegrity.tracking.markers.kabsch import kabsch, kabsch_residuals, pose_from_points

from tracking import reference_matching as reference
from tracking.track_section import GEOMETRY, TRACK

POINTS = GEOMETRY + [0.0, 0.0, 0.45]


@settings(deadline=None, max_examples=40)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 8), noise=st.floats(0.0, 0.01))
def test_kabsch_matches_scipy_align_vectors(seed, n, noise):
    rng = np.random.default_rng(seed)
    body = rng.normal(0, 0.05, (n, 3))
    R_true = Rotation.random(random_state=seed).as_matrix()
    world = body @ R_true.T + rng.normal(0, 0.3, 3) + rng.normal(0, noise, (n, 3))
    R, t = kabsch(world, body)
    R_ref, _ = Rotation.align_vectors(world - world.mean(0), body - body.mean(0))
    np.testing.assert_allclose(R, R_ref.as_matrix(), atol=1e-8)
    np.testing.assert_allclose(t, world.mean(0) - R @ body.mean(0), atol=1e-12)  # least-squares translation


def test_kabsch_exact_pose_and_proper_rotation_for_reflected_input():
    T = pose_from_points(GEOMETRY @ Rotation.from_rotvec([0.3, -1.0, 2.0]).as_matrix().T + [0.1, 0.2, 0.5], GEOMETRY)
    np.testing.assert_allclose(T[:3, :3], Rotation.from_rotvec([0.3, -1.0, 2.0]).as_matrix(), atol=1e-12)
    np.testing.assert_allclose(T[:3, 3], [0.1, 0.2, 0.5], atol=1e-12)
    body = np.array([[0.0, 0.0, 0.0], [0.05, 0.0, 0.0], [0.0, 0.04, 0.0], [0.0, 0.0, 0.03]])  # not planar
    R, _ = kabsch(body * [1, 1, -1], body)  # a mirror image has no exact proper rotation
    assert np.isclose(np.linalg.det(R), 1.0)
    assert kabsch_residuals(body * [1, 1, -1], body).max() > 1e-3


@settings(deadline=None, max_examples=30)
@given(seed=st.integers(0, 2**32 - 1))
def test_batched_kabsch_equals_scipy_align_vectors_per_problem(seed):
    rng = np.random.default_rng(seed)
    body = rng.normal(0, 0.05, (4, 3))
    world = np.einsum("bij,nj->bni", Rotation.random(9, random_state=seed).as_matrix(), body) + rng.normal(0, 0.004, (9, 4, 3))
    world = world.reshape(3, 3, 4, 3)  # two batch axes
    R, t = kabsch(world, body)
    assert R.shape == (3, 3, 3, 3) and t.shape == (3, 3, 3)
    for b in np.ndindex(3, 3):
        R_ref, _ = Rotation.align_vectors(world[b] - world[b].mean(0), body - body.mean(0))
        np.testing.assert_allclose(R[b], R_ref.as_matrix(), atol=1e-9)
        np.testing.assert_allclose(t[b], world[b].mean(0) - R[b] @ body.mean(0), atol=1e-12)


def test_kabsch_residuals_equal_numpys():
    """The compiled residuals round the fitted points' 3-term products with one fused multiply-add each, as the
    OpenBLAS kernels numpy called on the development machine did (equal to the bit there).  Another CPU's BLAS
    kernel may round them otherwise, so the check here is to 1e-15 m (the residuals are ~1e-2 m)."""
    rng = np.random.default_rng(3)
    for k in (1, 2, 3, 4, 7, 9):
        body = rng.normal(0.0, 0.03, (k, 3))
        world = rng.normal(0.0, 0.03, (50, k, 3)) + rng.normal(0.0, 1.0, 3)
        for body_arg in (body, body + rng.normal(0.0, 0.001, (50, k, 3))):
            np.testing.assert_allclose(kabsch_residuals(world, body_arg), reference.kabsch_residuals(world, body_arg), rtol=0, atol=1e-15)
        np.testing.assert_allclose(kabsch_residuals(world[0], body), reference.kabsch_residuals(world[0], body), rtol=0, atol=1e-15)


def test_kabsch_refuses_non_finite_too_few_and_collinear_points():
    with pytest.raises(PoseIntegrityError, match="points_world: entries must be finite.*nan"):
        pose_from_points(POINTS * np.nan, GEOMETRY)
    with pytest.raises(PoseIntegrityError, match="points_world: entries must be finite.*inf"):
        kabsch(np.where(np.eye(4, 3) > 0, np.inf, POINTS), GEOMETRY)
    with pytest.raises(PoseIntegrityError, match="points_world: Kabsch needs at least 3 corresponding points, got 2"):
        pose_from_points(POINTS[:2], GEOMETRY[:2])
    line = np.array([[0, 0, 0], [0.01, 0, 0], [0.03, 0, 0]], float)
    with pytest.raises(PoseIntegrityError, match="points_body: the points lie on one line"):
        pose_from_points(line + [0, 0, 0.5], line)
    with pytest.raises(PoseIntegrityError, match=r"points_body: expected shape \(3, 3\)"):
        pose_from_points(POINTS[:3], GEOMETRY)
    with pytest.raises(PoseIntegrityError, match=r"points_body: the points lie on one line"):
        MarkerTracker(line, TRACK.filter, TRACK.matching)
    assert np.isfinite(pose_from_points(POINTS, GEOMETRY)).all()
