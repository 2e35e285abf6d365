"""Stage 06's metrics do not move when its code is made faster: run_study on the tiny parameters (the track section
of tests/params_tiny.yaml, one process) gives tracking.json as the code before the speed-up wrote it
(study_metrics_tiny.json: the stage-06 notebook's output on those parameters, timings left out).

Every experiment draws from its own seeded generator in a fixed order, so the numbers are the same to the bit on
one machine; the tolerance of 1e-9 (relative) only admits the last-place differences of another CPU's BLAS.
"""

import json
from pathlib import Path

from poseintegrity.config import load_section
from poseintegrity.parallel import Workers
from poseintegrity.report.metrics import json_ready, metrics_differences
from poseintegrity.tracking.experiments.study import run_study
from poseintegrity.tracking.experiments.timing import TIMING_METRICS
from tracking.track_section import ROOT, TINY

BEFORE = Path(__file__).with_name("study_metrics_tiny.json")


def test_tiny_study_metrics_equal_those_before_the_speed_up(tmp_path):
    parallel = load_section(ROOT / "tests" / "params_tiny.yaml", "parallel")
    with Workers(parallel) as workers:
        study = run_study(TINY, tmp_path / "replay", workers)
    after = json.loads(json.dumps(json_ready(study.metrics), allow_nan=False))
    assert metrics_differences(json.loads(BEFORE.read_text()), after, TIMING_METRICS, rtol=1e-9) == []
