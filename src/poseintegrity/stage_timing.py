"""Stage wall times: one small JSON file per stage under ``reports/metrics/timing/`` (written by
:mod:`poseintegrity.stage`), and the lines ``make repro`` ends with::

    python -m poseintegrity.stage_timing reports/metrics/timing

    01_generate_datasets        412 s   local, n_jobs 2              finished 2025-11-23 14:02
    ...
    total                    1290 s
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

from poseintegrity.atomic_write import write_text_atomically
from poseintegrity.errors import PoseIntegrityError
from poseintegrity.workers import describe_backend


class TimingFileError(PoseIntegrityError):
    """A stage timing file that is unreadable, not JSON, or lacks a field or has one of the wrong type (the message
    names the file and the field)."""


FIELDS = {"stage": str, "wall_time_s": (int, float), "backend": str, "n_jobs": int, "address": (str, type(None)),
          "finished_at": str}


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
        write_text_atomically(path, json.dumps(asdict(self), indent=1) + "\n")

    @classmethod
    def read(cls, path: Path) -> StageTiming:
        """The record of ``path``; :class:`TimingFileError` naming the file and what is wrong (unreadable, not
        JSON, a field missing, unknown or of the wrong type, a negative or non-finite wall time)."""
        try:
            record = json.loads(Path(path).read_text())
        except OSError as error:
            raise TimingFileError(f"{path}: cannot read: {error.strerror}") from None
        except (ValueError, UnicodeDecodeError) as error:
            raise TimingFileError(f"{path}: not valid JSON ({error}): an interrupted write? re-run its stage") from None
        if not isinstance(record, dict):
            raise TimingFileError(f"{path}: expected a JSON object of {sorted(FIELDS)}, got {type(record).__name__}")
        if missing := [key for key in FIELDS if key not in record]:
            raise TimingFileError(f"{path}: field(s) {missing} missing: re-run its stage")
        if unknown := sorted(set(record) - set(FIELDS)):
            raise TimingFileError(f"{path}: unknown field(s) {unknown}")
        for key, kind in FIELDS.items():
            if isinstance(record[key], bool) or not isinstance(record[key], kind):
                raise TimingFileError(f"{path}: field {key} has the wrong type: {record[key]!r:.60}")
        if not (math.isfinite(record["wall_time_s"]) and record["wall_time_s"] >= 0):
            raise TimingFileError(f"{path}: field wall_time_s must be a finite number >= 0, got {record['wall_time_s']!r}")
        return cls(**record)

    def line(self) -> str:
        """``"02_extract_artifacts        612 s   local, n_jobs 2              finished 2025-11-23 14:12"``"""
        where = describe_backend(self.backend, self.address, self.n_jobs)
        finished = self.finished_at.replace("T", " ")[:16]
        return f"{self.stage:<24} {self.wall_time_s:6.0f} s   {where:<28} finished {finished}"


def read_timings(folder: Path) -> list[StageTiming]:
    """Every stage timing file of ``folder``, in stage name order ([] when there is none); :class:`TimingFileError`
    naming the first bad file."""
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
    if args.folder.exists() and not args.folder.is_dir():
        sys.exit(usage_error(f"{args.folder}: not a folder (expected the folder of the stage timing files)"))
    try:
        lines = summary(args.folder)
    except PoseIntegrityError as error:
        sys.exit(usage_error(str(error)))
    print("\n".join(lines) if lines else f"no stage timing in {args.folder} yet")


def usage_error(message: str) -> int:
    """Print ``message`` (one line: ``file: what is wrong``) to stderr; the exit status of bad input, 2 (as
    argparse's)."""
    print(message, file=sys.stderr)
    return 2


if __name__ == "__main__":
    main()
