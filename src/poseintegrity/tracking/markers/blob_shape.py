"""The shape of one blob (section II-B's shape tests): its area, circularity and convexity, by the polygon through
its boundary pixel centres (the published code) or by its pixels (ours; :mod:`.detection`'s docstring), and the
pixels it covers.
"""

from __future__ import annotations

import cv2
import numpy as np


def blob_shape(contour: np.ndarray, measure: str) -> tuple[float, float, float]:
    """(area px^2, circularity, convexity) of one external contour (k, 1, 2) int.

    measure "contour": the polygon through the boundary pixel centres (their public code);
    "pixel": each pixel a unit square (module docstring).  Circularity is area over the area of the
    minimum enclosing circle, convexity area over the convex hull's area.
    """
    area = cv2.contourArea(contour)
    _, radius = cv2.minEnclosingCircle(contour)
    hull = cv2.convexHull(contour)
    hull_area = cv2.contourArea(hull)
    if measure == "pixel":
        area += len(contour) / 2.0 + 1.0  # Pick: pixels = interior + boundary = A + B/2 + 1
        radius += 0.5
        hull_area += cv2.arcLength(hull, True) / 2.0 + 1.0
    circularity = area / (np.pi * radius * radius) if radius > 0 else 0.0
    convexity = area / hull_area if hull_area > 0 else 0.0
    return area, circularity, convexity


def blob_pixels(contour: np.ndarray) -> np.ndarray:
    """Pixel coordinates (k, 2) int (u, v) inside an external contour (k, 1, 2), its boundary included."""
    x0, y0, w, h = cv2.boundingRect(contour)
    mask = np.zeros((h, w), np.uint8)
    cv2.drawContours(mask, [contour - [x0, y0]], -1, 1, thickness=cv2.FILLED)
    v, u = np.nonzero(mask)
    return np.column_stack([u + x0, v + y0])
