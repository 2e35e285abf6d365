"""The project's published values as the defaults of public functions.

A function that takes a params section (``detect_markers(ir, depth, lut, detection=None)``) uses the section of the
packaged copy of ``params.yaml`` when none is given (:func:`poseintegrity.config.default_params`); a section passed
explicitly, e.g. from ``load_params("my_params.yaml")``, overrides it.
"""

from __future__ import annotations

from typing import Any


def published(dotted: str) -> Any:
    """The section or value of the packaged ``params.yaml`` at ``dotted`` (e.g. ``"track.detection"``).

    The params schema is imported on first use only: it imports every stage's schema (trimesh among them, ~0.9 s),
    which a worker that only detects markers should not pay."""
    from poseintegrity.config import default_params

    value: Any = default_params()
    for part in dotted.split("."):
        value = getattr(value, part)
    return value
