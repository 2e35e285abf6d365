"""Recording folders for the recording and replay tests: the marker body 45 cm in front of the camera, rendered on
the tiny parameters and written by RecordingWriter."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from poseintegrity.tracking.io.recording import RecordingWriter
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M
from poseintegrity.tracking.simulation.frames import intrinsics, render_frame, unit_plane_lut

from tracking.track_section import GEOMETRY
from tracking.track_section import TINY as PARAMS


def record(folder: Path, n: int = 4, overwrite: bool = False, seed: int = 0) -> Path:
    """folder, holding a recording of n frames 46 ms apart (PNG frames, no gyro) rendered from seed."""
    camera = PARAMS.camera
    writer = RecordingWriter(folder, unit_plane_lut(intrinsics(camera), camera.width, camera.height), overwrite=overwrite)
    rng = np.random.default_rng(seed)
    for k in range(n):
        ir, depth = render_frame(GEOMETRY + [0.0, 0.0, 0.45], [], camera, PARAMS.frames, MARKER_DIAMETER_M / 2, rng)
        writer.add_frame(0.046 * k, ir, depth)
    writer.close()
    return folder
