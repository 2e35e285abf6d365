"""Building blocks shared by the params schemas of every section (``poseintegrity.params.<section>``).

Every section model derives from :class:`Section`: unknown keys are refused, values are frozen, every float
must be finite (NaN and inf are refused wherever a number is expected) and numbers are strict: YAML's ``true``,
the text ``"3"`` and ``2.0`` for a count are refused, an integer where a float is expected is taken (JSON's rule).
Every number carries a lower and an upper bound with its reason (tests/params/test_every_number_bounded.py walks the schema).
A tuple field is written as a YAML list: it is marked :data:`FromList` (its entries stay strict). Field types here carry the rules that
recur across sections (seeds, worker counts, ordered ranges, distinct entries), so that a bad value is refused
by the field itself and the error names its key. A rule between several keys of one model raises
:class:`KeyRule` from a ``model_validator``; :mod:`poseintegrity.config` then names the key it carries.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, TypeVar

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, Strict, ValidationInfo

from poseintegrity.errors import PoseIntegrityError

T = TypeVar("T")


class Section(BaseModel):
    """Base of every params.yaml (sub)section: extra keys refused, frozen, floats finite, numbers strict."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


# Strict mode takes a tuple only from a tuple and a Path only from a Path; YAML gives lists and text. This marker
# lets the container (or path) be converted while every number inside stays strict.
FromList = Strict(False)


class KeyRule(PoseIntegrityError):
    """A rule between keys of one section failed; ``key`` (dotted, relative to the model that raised it) is the
    key the error message names, e.g. ``KeyRule("k_report_arc", "must be <= k_max (5), got 30")``."""

    def __init__(self, key: str, message: str):
        super().__init__(message)
        self.key = key


PACKAGE_PREFIX = "poseintegrity:"  # a file shipped with the package (poseintegrity/assets), wherever it is installed


def _resolve(path: Path, info: ValidationInfo) -> Path:
    """``poseintegrity:<path>`` made a path inside the installed package; another relative path made relative to
    the params root directory (validation context ``base_dir``, set by :func:`poseintegrity.config.load_section`),
    unchanged without one."""
    text = path.as_posix()
    if text.startswith(PACKAGE_PREFIX):
        return Path(__file__).parent / text.removeprefix(PACKAGE_PREFIX)
    base = (info.context or {}).get("base_dir")
    return path if path.is_absolute() or base is None else Path(base) / path


# a file named in params.yaml: relative to its directory, or poseintegrity:<path> inside the package
ProjectPath = Annotated[Path, Strict(False), AfterValidator(_resolve)]


def _worker_count(n_jobs: int) -> int:
    if n_jobs == 0 or n_jobs < -1:
        raise ValueError("n_jobs must be a positive number of worker processes or -1 (all cores)")
    return n_jobs


# n_jobs: processes, or -1 for all cores; more than 1024 is no machine's core count (and each worker holds a scene)
WorkerCount = Annotated[int, Field(ge=-1, le=1024), AfterValidator(_worker_count)]
Seed = Annotated[int, Field(ge=0, lt=2**63)]  # a numpy SeedSequence entropy: a non-negative integer


def _ordered(bounds: tuple[float, float]) -> tuple[float, float]:
    if not bounds[0] <= bounds[1]:
        raise ValueError(f"a range [low, high] needs low <= high, got {list(bounds)}")
    return bounds


def ordered_range(**bounds: float) -> type:
    """``[low, high]`` with ``low <= high``, each end within ``bounds`` (``Field`` keywords: ``ge``, ``gt``,
    ``le``, ``lt``), e.g. ``ordered_range(ge=100, le=2000)`` for a camera distance in mm."""
    end = Annotated[float, Field(**bounds)]
    return Annotated[tuple[end, end], FromList, AfterValidator(_ordered)]


def _distinct(values: Sequence[T]) -> Sequence[T]:
    repeated = sorted({str(v) for v in values if list(values).count(v) > 1})
    if repeated:
        raise ValueError(f"entries must be distinct, repeated: {', '.join(repeated)}")
    return values


def distinct(item_type: type) -> type:
    """``list[item_type]`` whose entries must all differ, e.g. ``distinct(float)`` for azimuths."""
    return Annotated[list[item_type], AfterValidator(_distinct)]
