"""Building blocks shared by the params schemas of every section (``poseintegrity.<subpackage>.params``)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import AfterValidator, ValidationInfo


def _resolve(path: Path, info: ValidationInfo) -> Path:
    """A relative path made relative to the params root directory (validation context ``base_dir``, set by
    :func:`poseintegrity.config.load_section`); unchanged without one."""
    base = (info.context or {}).get("base_dir")
    return path if path.is_absolute() or base is None else Path(base) / path


ProjectPath = Annotated[Path, AfterValidator(_resolve)]  # a file named in params.yaml, relative to its directory


def _worker_count(n_jobs: int) -> int:
    if n_jobs == 0 or n_jobs < -1:
        raise ValueError("n_jobs must be a positive number of worker processes or -1 (all cores)")
    return n_jobs


WorkerCount = Annotated[int, AfterValidator(_worker_count)]  # n_jobs: processes, or -1 for all cores
