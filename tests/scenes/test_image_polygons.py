"""The image geometry both board placements share (scenes/image_polygons.py): the compiled projection rounds as numpy
does, points fall on a mask as numpy's rounding puts them, and convex polygons overlap within CLEARANCE_PX."""

import numpy as np
from scipy.spatial.transform import Rotation

from poseintegrity.poses import pose_matrix
from poseintegrity.scenes.image_polygons import CLEARANCE_PX, NEAR_MM, hits, overlap, pixels

K = np.array([[1024.3, 0.0, 483.7], [0.0, 1023.9, 303.2], [0.0, 0.0, 1.0]])


def test_pixels_are_numpys_to_the_bit():
    """Boards of several points each (k, m > 1, 3) at random views: numpy's ``points @ R.T + t`` and pinhole, the
    same floats, points behind the camera flagged alike."""
    rng = np.random.default_rng(0)
    for trial in range(50):
        view = pose_matrix(Rotation.random(random_state=trial).as_matrix(), rng.normal(0.0, 300.0, 3))
        points = rng.normal(0.0, 400.0, (int(rng.integers(1, 40)), int(rng.integers(2, 60)), 3))
        cam = points @ view[:3, :3].T + view[:3, 3]
        front = cam[..., 2] > NEAR_MM
        z = np.where(front, cam[..., 2], 1.0)
        expected = np.stack([K[0, 0] * cam[..., 0] / z + K[0, 2], K[1, 1] * cam[..., 1] / z + K[1, 2]], axis=-1)
        uv, in_front = pixels(points, view, K)
        assert np.array_equal(in_front, front) and np.array_equal(uv, expected)


def test_a_point_hits_the_pixel_numpy_rounds_it_onto():
    """Half-pixel positions round half to even (np.round); points behind the camera or outside the image hit
    nothing."""
    rng = np.random.default_rng(1)
    near = rng.random((30, 40)) < 0.3
    points = np.round(rng.uniform(-5.0, 45.0, (200, 6, 2)) * 2) / 2  # many on half pixels
    front = rng.random((200, 6)) < 0.9
    u, v = np.round(points[..., 0]).astype(int), np.round(points[..., 1]).astype(int)
    inside = front & (u >= 0) & (u < 40) & (v >= 0) & (v < 30)
    expected = np.zeros(front.shape, bool)
    expected[inside] = near[v[inside], u[inside]]
    assert np.array_equal(hits(points, front, near), expected.any(axis=1))


def test_polygons_overlap_within_the_clearance():
    square = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]])
    post = np.array([[5.0, 0.0], [5.0, 30.0]])  # a segment
    for gap, overlapping in ((CLEARANCE_PX - 1.0, True), (CLEARANCE_PX + 1.0, False)):
        assert overlap(square, square + [10.0 + gap, 0.0]) == overlapping
        assert overlap(square, post + [5.0 + gap, 0.0]) == overlapping
