"""Stage 06's metrics do not move when its code is made faster: run_study on the tiny parameters (the track section
of tests/params_tiny.yaml, one process) gives tracking.json as the code before the speed-up wrote it
(study_metrics_tiny.json: the stage-06 notebook's output on those parameters, timings left out).

Every experiment draws from its own seeded generator in a fixed order, so the numbers are the same to the bit on one
machine, and since OpenBLAS runs its Haswell kernels everywhere (poseintegrity.kernel_pin), on every x86-64 machine. The
fixture was written before that, on a CPU with other OpenBLAS kernels, and the filters amplify the last-bit
differences of those kernels over hundreds of steps, so it is compared within their spread. Measured
on one AMD EPYC (AVX2) under every kernel set it can run (OPENBLAS_CORETYPE Prescott/Core2 = Katmai, Nehalem,
Sandybridge, Haswell = Zen = the default), against this fixture (written on a CPU with yet other kernels): the
filters' metrics (RMS errors, sigma sweeps, occlusion and restart errors) spread by at most 1.7e-5 relative
(occlusion_rms_deg/ukf_gyro; 1.2e-5 ten_metre_jump, all others below 4.3e-6); the metrics without a filter by
5e-15; counts, flags and every other value not at all. RTOL admits 6 times the largest spread. A real change of the
filter moves far more: a process or measurement sigma changed by 0.1 % moves 15-27 metrics by 1e-4 to 1.1e-3, and
0.1 % more angular-rate noise written into the process model's code (model.py, B's dt * sigma_alpha rows) fails this
test on 20 metrics. What moves the metrics less than the kernels do passes unseen on any machine: dropping eq. 29's
centripetal term (second order at dt = 2.5 ms) moves none by more than 4.9e-6.

Three diagnostics are themselves the disagreement of two implementations (pykalman's time update against ours,
the SR-UKF against the UKF, a replayed recording against the live run): a few ulps that vary by more than their
own size from kernel to kernel (relative spread up to 0.97), so they are held to an absolute bound, 10 to 20 times
their measured spread, instead.
"""

import json
from pathlib import Path

from poseintegrity.config import load_section
from poseintegrity.report.metrics import json_ready, metrics_differences
from poseintegrity.tracking.experiments.study import run_study
from poseintegrity.workers import Workers
from tracking.track_section import ROOT, TINY

BEFORE = Path(__file__).with_name("study_metrics_tiny.json")
RTOL = 1e-4  # 6 x the largest spread across OpenBLAS kernels (1.7e-5, module docstring)
AGREEMENT_ATOL = {  # diagnostic -> absolute bound on its change: measured spread across the kernels, x 10-20
    "pykalman_time_update_max_diff": 1e-14,  # spread 4.9e-16 (mean), 2.2e-16, 6.8e-21
    "srukf_vs_ukf_max_rel_diff": 5e-7,  # spread 3.5e-8 (alpha 0.001), 3.1e-14 (alpha 1)
    "max_position_diff_mm": 1e-5,  # recording_replay: spread 1.1e-6 mm
}


def agreement_differences(before: dict, after: dict) -> list[str]:
    """The AGREEMENT_ATOL diagnostics that moved by more than their bound (or went missing): "path: before -> after"."""
    return [f"{path}: {old!r} -> {new!r} (bound {atol:g})" for key, atol in AGREEMENT_ATOL.items()
            for path, old, new in _under(before, after, key)
            if not isinstance(new, (int, float)) or abs(new - old) > atol]


def _under(before, after, key: str, path: str = "", inside: bool = False):
    """(path, before, after) of every leaf of ``before`` under ``key`` at any depth (after's leaf, or None)."""
    if isinstance(before, dict):
        for name, value in before.items():
            yield from _under(value, after.get(name) if isinstance(after, dict) else None, key, f"{path}/{name}",
                              inside or name == key)
    elif inside:
        yield path, before, after


def test_tiny_study_metrics_equal_those_before_the_speed_up(tmp_path):
    parallel = load_section(ROOT / "tests" / "params_tiny.yaml", "parallel")
    with Workers(parallel) as workers:
        study = run_study(TINY, tmp_path / "replay", workers)
    after, before = json.loads(json.dumps(json_ready(study.metrics), allow_nan=False)), json.loads(BEFORE.read_text())
    assert metrics_differences(before, after, set(AGREEMENT_ATOL), rtol=RTOL) == []
    assert agreement_differences(before, after) == []
    assert set(study.speed) == {"filter_step_ms", "speedup_vs_filterpy", "speedup_vs_pykalman", "subroutine_ms"}
    assert not set(study.speed) & set(study.metrics)  # machine-dependent figures stay out of the metrics file
