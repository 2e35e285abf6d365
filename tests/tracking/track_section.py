"""The ``track`` section of params.yaml for the tracking tests: the real values, never a second copy of them;
a test varies them with ``.model_copy(update=...)``."""

from pathlib import Path

import numpy as np

from poseintegrity.config import load_section

ROOT = Path(__file__).resolve().parents[2]
TRACK = load_section(ROOT / "params.yaml", "track")  # paper scale
TINY = load_section(ROOT / "tests" / "params_tiny.yaml", "track")  # params.yaml shrunk by the tiny overlay
GEOMETRY = np.array(TRACK.markers_body)  # (4, 3) m, the marker body of docs/references.md
SECOND = np.array(TRACK.evaluation.second_tool)  # (4, 3) m, the second tool of the two-tool runs
