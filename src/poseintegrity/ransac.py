"""How many samples classic RANSAC draws (Fischler and Bolles 1981; Hartley and Zisserman, Multiple View Geometry,
2nd ed., sec. 4.7.1), and how many matches OpenCV's classic ``solvePnPRansac`` puts in a sample.

A leaf of plain Python (no OpenCV): the ``extract`` params schema bounds the budget with it, :mod:`pnp` and
:mod:`extract` run it. Sources in docs/references.md, "RANSAC iteration count".
"""

from __future__ import annotations

import math

from poseintegrity.errors import ArgumentError


def minimal_sample_size(method: str) -> int:
    """Correspondences per hypothesis of OpenCV 5's classic solvePnPRansac with that flag: 4, solved by P3P/AP3P,
    for ``p3p`` and ``ap3p``; 5, solved by EPnP, for every other flag (modules/geometry/src/solvepnp.cpp)."""
    return 4 if method in ("p3p", "ap3p") else 5


def ransac_iterations(confidence: float, inlier_ratio: float, sample_size: int) -> int:
    """N = ceil(log(1 - p) / log(1 - w^s)): hypotheses after which, with probability ``confidence`` p, at least one
    sample of ``sample_size`` s correspondences is free of outliers when a share ``inlier_ratio`` w of them are
    inliers (H&Z sec. 4.7.1, eq. 4.18; their Table 4.3 at p = 0.99). OpenCV's classic RANSAC stops after this many
    for the w of the best consensus it has found (rounded to the nearest integer), and at its iterationsCount.

    confidence : in (0, 1); inlier_ratio : in (0, 1] (1: every sample is all inliers, N = 1); sample_size : >= 1
    """
    if not (0 < confidence < 1 and 0 < inlier_ratio <= 1 and sample_size >= 1):
        raise ArgumentError(f"ransac_iterations needs 0 < confidence < 1, 0 < inlier_ratio <= 1 and a sample size >= 1, "
                         f"got {confidence}, {inlier_ratio}, {sample_size}")
    all_inliers = inlier_ratio**sample_size
    return 1 if all_inliers >= 1 else math.ceil(math.log1p(-confidence) / math.log1p(-all_inliers))
