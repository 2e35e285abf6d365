"""Random frames of the published marker body (params.yaml) for the matcher tests: markers in a random pose, some
missing, far phantoms, shuffled; and the same markers a small motion after a prediction."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from tracking.track_section import GEOMETRY


def scene(seed: int, n_missing: int, n_phantoms: int, noise: float = 0.0005) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Markers in a random pose (some missing), far phantoms, shuffled.  Returns the points (n, 3) m, the true
    assignment (4,) int and the markers (4, 3) m (with their noise, none dropped).

    The matcher tests that need the true assignment take noise=0.0002: with one marker missing, the swapped triangle
    3-2-1 fits the true 1-2-3 to ~1 mm RMS (sides 35.8 / 38.5 mm), so at 0.5 mm noise a swap is a legitimate best
    fit (seed 1018941 found one)."""
    rng = np.random.default_rng(seed)
    markers = GEOMETRY @ Rotation.random(random_state=seed).as_matrix().T + [0.0, 0.0, 0.5] + rng.normal(0, noise, (4, 3))
    keep = np.ones(4, dtype=bool)
    keep[rng.choice(4, n_missing, replace=False)] = False
    phantoms = markers.mean(0) + rng.choice([-1, 1], (n_phantoms, 3)) * rng.uniform(0.12, 0.3, (n_phantoms, 3))
    points = np.vstack([markers[keep], phantoms])
    order = rng.permutation(len(points))
    truth = np.full(4, -1)
    truth[keep] = np.argsort(order)[: keep.sum()]
    return points[order], truth, markers


def small_motion(seed: int, n_missing: int, n_phantoms: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A frame without phantoms (0.2 mm noise), the markers' last positions 2 mm off it, and the frame with
    n_phantoms far phantoms appended.  Returns (points (k, 3), previous (4, 3), with_phantoms (k + n_phantoms, 3),
    truth (4,) int), metres."""
    points, truth, markers = scene(seed, n_missing, 0, noise=0.0002)
    rng = np.random.default_rng(seed)
    previous = markers + rng.normal(0, 0.002, (4, 3))  # the last positions, a little off
    phantoms = markers.mean(0) + rng.choice([-1, 1], (n_phantoms, 3)) * rng.uniform(0.12, 0.3, (n_phantoms, 3))
    return points, previous, np.vstack([points, phantoms]), truth
