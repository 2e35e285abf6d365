"""``reports/timing.md`` (report/timing_page.py): the wall times and speed-ups, which change with the machine."""

from poseintegrity.report.summary import render_summary
from poseintegrity.report.timing_page import render_timing
from poseintegrity.stage_timing import StageTiming


def test_stage_wall_times_say_where_the_tasks_ran_and_stay_out_of_the_summary():
    """Wall times and speed-ups are on the machine-dependent page, each bar passed or failed; the summary only links
    it, so that it holds no number that changes with the machine."""
    timings = [StageTiming("01_generate_datasets", 501.4, "local", 2, None, "2026-11-23T10:02:03"),
               StageTiming("02_extract_artifacts", 250.0, "dask", 8, "tcp://10.0.0.5:8786", "2026-11-23T10:06:13")]
    speed = {"speedup_vs_filterpy": 12.3, "speedup_vs_pykalman": 40.0, "filter_step_ms": {"srukf": 0.05},
             "subroutine_ms": {"Contour detection": 1.25}}
    text = render_timing(timings, {"06_marker_tracking": speed}, "AMD EPYC, 2 logical cores (x86_64)")
    assert ("| 01_generate_datasets | 501 | local, n_jobs 2 | 2026-11-23 10:02 | <= 480 s, rendering every world on 2 "
            "cores: fail |") in text
    assert "| 02_extract_artifacts | 250 | dask at tcp://10.0.0.5:8786, n_jobs 8 | 2026-11-23 10:06 |  |" in text
    assert "| total (without the report) | 751 | | | |" in text and "AMD EPYC, 2 logical cores" in text
    assert "| SR-UKF step speed-up over filterpy's UKF | 12.3x | >= 10x: pass |" in text
    assert "| Contour detection (ms) | 1.250 | |" in text
    assert "No stage timing yet" in render_timing([], {}, "x") and "has not written its timings" in render_timing([], {}, "x")
    summary = render_summary({"tracking": {"rms_mm": {"ukf": 1.1}}})
    assert "](timing.md)" in summary and "wall time (s)" not in summary and "| SR-UKF step speed-up" not in summary
