"""One cache file on disk: an ``.npz`` that proves it is whole and says what it was computed from.

Every cache of the pipeline (per image its SIFT features, per frame its evidence, PnP results and consensus
columns, per dataset its target model M_t; under ``extract.features_dir``, in the main world's folder and in each
population world's) is one such file:

- its arrays in ``.npz`` form, one of them ``__key__``: the hash of what they were computed from, the caller's key
  (the inputs and params that decide them, and the cache's layout version) together with :func:`provenance` (the
  versions of the libraries that compute them and the level their kernels dispatch to), so that an entry made by
  other code or other kernels is never taken for this run's;
- then a trailer: 8 bytes ``POSECACH`` and the SHA-256 of every byte before it, so that a file cut short or
  altered anywhere (one bit of a zip header a zip reader would not notice included) is known as damaged.

:func:`read_entry` returns the arrays only when the file is whole and its key is the one asked for; otherwise a
:class:`Miss` that says why, and the caller computes the entry again and writes it (:func:`write_entry`: a staging
file renamed into place, :func:`poseintegrity.atomic_write.write_atomically`). A file that cannot prove it is whole is
never used. Every miss is counted in the :func:`counting` block around it, so that a stage can say per dataset how
many files it recomputed and why (:func:`describe`).
"""

from __future__ import annotations

import hashlib
import io
import json
import zipfile
from collections import Counter
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import TypeVar

import numpy as np

from poseintegrity.atomic_write import write_atomically

Task = TypeVar("Task")
Result = TypeVar("Result")
KEY = "__key__"
MAGIC = b"POSECACH"
TRAILER = len(MAGIC) + hashlib.sha256().digest_size
# why an entry was computed: no file; a file the system cannot read (permissions, an I/O error); a file cut short or
# altered (no trailer, or its checksum fails); one computed from other inputs, params, code or kernels, or a whole
# file of the format before trailers
REASONS = ("missing", "unreadable", "damaged", "stale")
WHY = {"unreadable": "unreadable", "damaged": "damaged: cut short or altered",
       "stale": "stale: other inputs, params, code or file format"}


@dataclass(frozen=True)
class Miss:
    """A cache file that cannot be used, and why (one of :data:`REASONS`)."""

    reason: str


@cache
def provenance() -> str:
    """What computes every cached value besides its inputs: OpenCV's, numpy's and scipy's versions and the level
    their kernels dispatch to (:func:`poseintegrity.kernel_pin.kernel_level`: the same on every x86-64 machine when
    pinned). A cache entry made under another one is stale."""
    import cv2
    import scipy

    from poseintegrity.kernel_pin import kernel_level

    return json.dumps([cv2.__version__, np.__version__, scipy.__version__, kernel_level()])


def stamped(key: str) -> str:
    """The stored ``__key__`` of an entry of ``key``: ``key`` and :func:`provenance` hashed together."""
    return hashlib.sha1(f"{key}\n{provenance()}".encode()).hexdigest()


_tallies: list[Counter] = []  # the open counting() blocks of this process, innermost last


@contextmanager
def counting() -> Iterator[Counter]:
    """Count every :func:`read_entry` in the block (``"checked"``) and each miss by its reason (and what
    :func:`count` adds): a worker task returns the counter with its result (a task runs alone in its process)."""
    tally = Counter()
    _tallies.append(tally)
    try:
        yield tally
    finally:
        _tallies.remove(tally)


def tallied(function: Callable[[Task], Result], task: Task) -> tuple[Result, Counter]:
    """``function(task)`` and the cache reads it counted (:func:`counting`): a worker task's result and tally,
    ``workers.map(partial(tallied, function), tasks)``."""
    with counting() as tally:
        return function(task), tally


def count(reason: str) -> None:
    """Count one entry computed for ``reason`` in every open :func:`counting` block."""
    for tally in _tallies:
        tally[reason] += 1


def read_entry(path: Path, key: str) -> dict[str, np.ndarray] | Miss:
    """The arrays of the cache file ``path`` (without its ``__key__``) when it is whole and was computed
    from ``key`` (:func:`stamped`); else a :class:`Miss` naming why, counted (:func:`counting`)."""
    found = read_whole(Path(path), key)
    count("checked")
    if isinstance(found, Miss):
        count(found.reason)
    return found


def read_whole(path: Path, key: str) -> dict[str, np.ndarray] | Miss:
    """:func:`read_entry` without counting: for a file this stage checked already (M_t, loaded by each worker)."""
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        return Miss("missing")
    except OSError:
        return Miss("unreadable")
    payload, magic, digest = data[:-TRAILER], data[-TRAILER:-TRAILER + len(MAGIC)], data[-TRAILER + len(MAGIC):]
    if len(data) < TRAILER or magic != MAGIC:
        return Miss("stale" if _whole_zip(data) else "damaged")  # a whole file of the format before checksums
    if hashlib.sha256(payload).digest() != digest:
        return Miss("damaged")
    try:
        with np.load(io.BytesIO(payload), allow_pickle=False) as stored:
            arrays = {name: stored[name] for name in stored.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile):
        return Miss("damaged")  # whole, but not what write_entry writes
    if str(arrays.pop(KEY, "")) != stamped(key):
        return Miss("stale")
    return arrays


def _whole_zip(data: bytes) -> bool:
    """Whether ``data`` is a zip archive without a comment, ending where its end record does, whose members all pass
    their CRC: an .npz of the format before trailers (np.savez writes no comment)."""
    if data[-22:-18] != b"PK\x05\x06":
        return False
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            return archive.testzip() is None
    except (zipfile.BadZipFile, OSError, ValueError, EOFError):
        return False


def write_entry(path: Path, key: str, arrays: Mapping[str, np.ndarray]) -> None:
    """Write the cache file ``path``: ``arrays`` with their key (:func:`stamped`) and the trailer, by a staging file
    renamed into place (a full disk: :class:`~poseintegrity.atomic_write.DiskFullError` naming ``path``). The bytes are
    the same for the same arrays and key."""
    buffer = io.BytesIO()
    np.savez(buffer, **arrays, **{KEY: np.array(stamped(key))})
    payload = buffer.getvalue()
    write_atomically(Path(path), lambda stream: stream.write(payload + MAGIC + hashlib.sha256(payload).digest()))


def describe(tally: Mapping[str, int]) -> str:
    """What a :func:`counting` tally says: ``"3 of 1 441 cache files recomputed (2 damaged: cut short or altered,
    1 stale: other inputs, params, code or file format), 12 new"``; ``"480 of 1 441 cache files new"`` on a first
    run; ``"1 441 cache files whole and current"`` when nothing was computed."""
    again = {reason: tally[reason] for reason in REASONS[1:] if tally.get(reason, 0)}
    files, new = _count(tally.get("checked", 0)), tally.get("missing", 0)
    if not again:
        return f"{_count(new)} of {files} cache files new" if new else f"{files} cache files whole and current"
    why = ", ".join(f"{_count(n)} {WHY[reason]}" for reason, n in again.items())
    return f"{_count(sum(again.values()))} of {files} cache files recomputed ({why})" + (
        f", {_count(new)} new" if new else "")


def _count(n: int) -> str:
    """``23652`` -> ``"23 652"``."""
    return f"{n:,}".replace(",", " ")
