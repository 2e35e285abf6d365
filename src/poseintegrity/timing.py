"""Stage wall times: one small JSON file per stage under ``reports/metrics/timing/`` (written by
:mod:`poseintegrity.stage`), and the lines ``make repro`` ends with::

    python -m poseintegrity.timing reports/metrics/timing

    01_generate_datasets        412 s   local, n_jobs 2              finished 2025-11-23 14:02
    ...
    total                    1290 s
"""

from __future__ import annotations

import argparse
import json
import os
from dataclasses import asdict, dataclass
from pathlib import Path

from poseintegrity.parallel import describe_backend


@dataclass(frozen=True)
class StageTiming:
    """One run of one stage: wall time (s) from the runner's start to the exported HTML, and where its parallel
    tasks ran (``n_jobs``: tasks at once; for a scheduler address, the worker threads connected at the start)."""

    stage: str
    wall_time_s: float
    backend: str
    n_jobs: int
    address: str | None
    finished_at: str  # local time, ISO 8601 to the second

    def write(self, path: Path) -> None:
        """Write ``path`` atomically: an interrupted write leaves no file that looks complete."""
        partial = path.with_name(path.name + ".partial")
        partial.write_text(json.dumps(asdict(self), indent=1) + "\n")
        os.replace(partial, path)

    @classmethod
    def read(cls, path: Path) -> StageTiming:
        return cls(**json.loads(path.read_text()))

    def line(self) -> str:
        """``"02_extract_artifacts        612 s   local, n_jobs 2              finished 2025-11-23 14:12"``"""
        where = describe_backend(self.backend, self.address, self.n_jobs)
        finished = self.finished_at.replace("T", " ")[:16]
        return f"{self.stage:<24} {self.wall_time_s:6.0f} s   {where:<28} finished {finished}"


def read_timings(folder: Path) -> list[StageTiming]:
    """Every stage timing file of ``folder``, in stage name order ([] when there is none)."""
    return [StageTiming.read(path) for path in sorted(Path(folder).glob("*.json"))]


def summary(folder: Path) -> list[str]:
    """One line per timing file of ``folder`` (stage name order), then the total; [] when there is none."""
    timings = read_timings(folder)
    if not timings:
        return []
    return [t.line() for t in timings] + [f"{'total':<24} {sum(t.wall_time_s for t in timings):6.0f} s"]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="Print each stage's wall time from its timing file.")
    parser.add_argument("folder", type=Path, nargs="?", default=Path("reports/metrics/timing"))
    args = parser.parse_args(argv)
    lines = summary(args.folder)
    print("\n".join(lines) if lines else f"no stage timing in {args.folder} yet")


if __name__ == "__main__":
    main()
