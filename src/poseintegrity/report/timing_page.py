"""``reports/timing.md``: every figure that changes with the machine and its load, on a page of its own.

The stage wall times (``reports/metrics/timing/<stage>.json``, written by the stage runner) and stage 06's step times,
speed-ups and Table I-like subroutine times (``reports/metrics/timing/subroutines/06_marker_tracking.json``) are the
only machine-dependent numbers the pipeline writes; no data or metrics file, and not ``reports/summary.md``, holds
any, so that two runs on any machines give the same bytes there. This page shows them with their targets, each
passed or failed, and names the machine that wrote it.
"""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path

from poseintegrity.stage_timing import StageTiming
from poseintegrity.workers import describe_backend

SUBROUTINES = "subroutines"  # the folder of the stages' own timings beside the stage timing files
TIMING_PAGE = "timing.md"
# target: (stage, its wall time bar s, what it stands for)
STAGE_TARGETS = {"01_generate_datasets": (480.0, "rendering every world on 2 cores")}
SPEEDUP_TARGET = 10.0  # the SR-UKF step over filterpy's UKF step


def read_subroutines(timing_dir: Path) -> dict[str, dict]:
    """``{stage: its timings}`` of ``timing_dir / subroutines`` ({} when there is none)."""
    folder = Path(timing_dir) / SUBROUTINES
    return {p.stem: json.loads(p.read_text()) for p in sorted(folder.glob("*.json"))} if folder.is_dir() else {}


def machine() -> str:
    """This machine's CPU model and logical cores, e.g. ``"AMD EPYC, 2 logical cores (x86_64)"``."""
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as info:
            model = next((line.partition(":")[2].strip() for line in info if line.startswith("model name")), model)
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} logical cores ({platform.machine()})"


def _verdict(value: float, bar: float, at_most: bool) -> str:
    held = value <= bar if at_most else value >= bar
    return "pass" if held else "fail"


def stage_table(timings: list[StageTiming]) -> list[str]:
    """Markdown lines: each stage's wall time in the run that wrote its metrics, where its tasks ran, the bar where
    there is one and whether it held, and the total."""
    if not timings:
        return ["No stage timing yet (`reports/metrics/timing/` is written by `python -m poseintegrity.stage`).", ""]
    lines = ["| stage | wall time (s) | tasks ran on | finished | target |", "| --- | --- | --- | --- | --- |"]
    for t in timings:
        where = describe_backend(t.backend, t.address, t.n_jobs)
        target = ""
        if t.stage in STAGE_TARGETS:
            bar, what = STAGE_TARGETS[t.stage]
            target = f"<= {bar:g} s, {what}: {_verdict(t.wall_time_s, bar, True)}"
        lines.append(f"| {t.stage} | {t.wall_time_s:.0f} | {where} | {t.finished_at.replace('T', ' ')[:16]} | {target} |")
    lines.append(f"| total (without the report) | {sum(t.wall_time_s for t in timings):.0f} | | | |")
    return [*lines, ""]


def tracking_table(speed: dict | None) -> list[str]:
    """Markdown lines: the SR-UKF's speed-ups (with the bar over filterpy), its step times and the subroutine
    means of stage 06 (:class:`~poseintegrity.tracking.experiments.study.Study`'s ``speed``)."""
    if not speed:
        return ["Stage 06 has not written its timings yet.", ""]
    filterpy = speed["speedup_vs_filterpy"]
    lines = ["| figure | this machine | target |", "| --- | --- | --- |",
             f"| SR-UKF step speed-up over filterpy's UKF | {filterpy:.1f}x | >= {SPEEDUP_TARGET:g}x: "
             f"{_verdict(filterpy, SPEEDUP_TARGET, False)} |",
             f"| SR-UKF step speed-up over pykalman's SR-UKF | {speed['speedup_vs_pykalman']:.1f}x | |"]
    lines += [f"| filter step, {name} (ms) | {ms:.3f} | |" for name, ms in speed["filter_step_ms"].items()]
    lines += [f"| {name} (ms) | {ms:.3f} | |" for name, ms in speed["subroutine_ms"].items()]
    return [*lines, ""]


def render_timing(timings: list[StageTiming], subroutines: dict[str, dict], where: str) -> str:
    """The page: the machine ``where`` (:func:`machine`), the stage wall times, stage 06's timings."""
    return "\n".join([
        "# Machine-dependent figures", "",
        "Wall times and speed-ups change with the machine and with what else it runs; no data or metrics file holds",
        "them, so they are here alone (`reports/summary.md` links this page). Written by stage 07 on: " + where + ".", "",
        "## Stage wall times", "", *stage_table(timings),
        "## Marker tracking: filter step and subroutines (stage 06, Black and Salcudean Table I)", "",
        *tracking_table(subroutines.get("06_marker_tracking")),
    ])
