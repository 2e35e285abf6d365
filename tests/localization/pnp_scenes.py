"""Synthetic PnP frames of known pose (the PnP tests' correspondences): non-planar model points and their
projections, a share of them displaced into outliers."""

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

K = np.array([[700.0, 0.0, 480.0], [0.0, 700.0, 300.0], [0.0, 0.0, 1.0]])


def scene(seed, n=200, outlier_fraction=0.5, noise_px=0.3, displacement_px=(30, 200)):
    """Non-planar points (mm) seen from a known pose; outliers (the first ones) displaced by ``displacement_px``."""
    rng = np.random.default_rng(seed)
    X = rng.uniform([-60, -40, -20], [60, 40, 20], (n, 3))
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rng.normal(0, 0.3, 3)).as_matrix()
    T[:3, 3] = [rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(250, 400)]
    x, _ = cv2.projectPoints(X, cv2.Rodrigues(T[:3, :3])[0], T[:3, 3], K, None)
    x = x.reshape(-1, 2) + rng.normal(0, noise_px, (n, 2))
    n_out = int(outlier_fraction * n)
    direction = rng.normal(size=(n_out, 2))
    x[:n_out] += direction / np.linalg.norm(direction, axis=1, keepdims=True) * rng.uniform(*displacement_px, (n_out, 1))
    return X, x, T, n - n_out
