"""Write a folder or a file atomically, and say so in one line when the disk is full.

A folder is written into a hidden staging folder beside it (``.<name>.partial``, :func:`staged`), a file into a
hidden staging file beside it (``.<name>.<random>.partial``, :func:`write_atomically`); each is renamed when
complete, so that an interrupted run leaves nothing that looks complete (a leftover staging folder is replaced by
the next run, a leftover staging file is removed by :func:`remove_staging_files`). Stage 01's datasets and
calibration sessions, the recorded-data writers, every cache entry (:mod:`poseintegrity.cache_entry`) and every
metrics file are written this way.

A write that fails because the disk (or the user's quota) is full raises :class:`DiskFullError`, whose message is
one line naming the file or folder and the free space left (:func:`disk_full`); the stage runner prints it alone,
without a traceback.

A command line that writes a folder or file the user names (``--out``) checks it first
(:func:`check_new_folder`, :func:`check_new_file`): before any work, and so that nothing of the user's is replaced.
"""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import BinaryIO

from poseintegrity.errors import PoseIntegrityError


class DestinationError(PoseIntegrityError):
    """An output path that would replace something of the user's, or cannot be written: named with what is there."""


class DiskFullError(PoseIntegrityError):
    """A write that found no space left on its disk (ENOSPC, or EDQUOT: the user's quota): names the path being
    written and the free space of its file system."""


FULL = (errno.ENOSPC, errno.EDQUOT)  # the errors of a full disk or an exhausted quota
STAGING_SUFFIX = ".partial"


def free_space(path: str | Path) -> str:
    """The space left on the file system of ``path`` (its nearest existing folder), e.g. ``"12.3 MB"``."""
    folder = Path(os.path.abspath(path))
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    try:
        free = shutil.disk_usage(folder).free
    except OSError:
        return "an unknown amount"
    for unit, size in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if free >= size:
            return f"{free / size:.1f} {unit}"
    return f"{free} bytes"


def disk_full(path: str | Path, error: OSError | None = None) -> DiskFullError:
    """The :class:`DiskFullError` of writing ``path``: one line with its absolute path and the free space left."""
    what = "the quota is exhausted" if error is not None and error.errno == errno.EDQUOT else "no space left on device"
    path = os.path.abspath(path)
    return DiskFullError(f"{path}: cannot be written, {what} ({free_space(path)} free there); free some space and "
                         f"re-run: nothing of this write is left behind")


@contextmanager
def full_disk_named(path: str | Path) -> Iterator[None]:
    """Turn an ENOSPC / EDQUOT ``OSError`` raised in the block into :func:`disk_full` naming ``path``."""
    try:
        yield
    except OSError as error:
        if error.errno in FULL:
            raise disk_full(path, error) from None
        raise


def write_atomically(path: str | Path, write: Callable[[BinaryIO], None]) -> None:
    """Write ``path`` by ``write(stream)`` into a hidden staging file beside it (``.<name>.<random>.partial``), then
    rename it into place: ``path`` is the old file or the new one, never a half-written one, also with parallel
    writers. Any error (an interrupt included) removes the staging file; a full disk raises :class:`DiskFullError`."""
    path = Path(path)
    with full_disk_named(path):
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, staging = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=STAGING_SUFFIX)
        try:
            with os.fdopen(handle, "wb") as stream:
                write(stream)
            os.replace(staging, path)
        except BaseException:
            Path(staging).unlink(missing_ok=True)
            raise


def write_text_atomically(path: str | Path, text: str) -> None:
    """:func:`write_atomically` of UTF-8 ``text``."""
    write_atomically(path, lambda stream: stream.write(text.encode("utf-8")))


def remove_staging_files(folder: str | Path) -> int:
    """Remove the staging files :func:`write_atomically` left under ``folder`` when its process was killed (they
    can never be renamed into place); returns how many. Run it only where no other writer works."""
    found = list(Path(folder).rglob(f".*{STAGING_SUFFIX}")) if Path(folder).is_dir() else []
    for path in found:
        if path.is_file():
            path.unlink(missing_ok=True)
    return len(found)


def partial_folder(final: Path) -> Path:
    """The staging folder of ``final``: ``.<name>.partial`` beside it."""
    final = Path(final)
    return final.parent / f".{final.name}.partial"


def check_new_folder(path: str | Path, option: str = "--out") -> Path:
    """``path`` as the folder a command will create: it must not exist, or be an empty folder, and its parent must
    be a folder; :class:`DestinationError` naming ``option`` and the path otherwise (nothing is touched)."""
    path = Path(path)
    if path.is_dir():
        if entries := sorted(entry.name for entry in path.iterdir()):
            shown = ", ".join(entries[:3]) + (", ..." if len(entries) > 3 else "")
            raise DestinationError(f"{option} {path}: the folder is not empty ({len(entries)} entries: {shown}); "
                                   f"give a new or empty folder (nothing of it is replaced)")
    elif path.exists():
        raise DestinationError(f"{option} {path}: exists and is not a folder; give a new or empty folder")
    elif not path.parent.is_dir():
        raise DestinationError(f"{option} {path}: its parent folder {path.parent} does not exist")
    return path


def check_new_file(path: str | Path, option: str = "--out", overwrite: bool = False) -> Path:
    """``path`` as the file a command will write: its parent a folder, ``path`` not a folder, and not an existing
    file unless ``overwrite``; :class:`DestinationError` naming ``option`` and the path otherwise."""
    path = Path(path)
    if path.is_dir():
        raise DestinationError(f"{option} {path}: is a folder; give the path of a file")
    if path.exists() and not overwrite:
        raise DestinationError(f"{option} {path}: the file exists; give a new name (or --overwrite to replace it)")
    if not path.parent.is_dir():
        raise DestinationError(f"{option} {path}: its folder {path.parent} does not exist")
    return path


@contextmanager
def staged(final: Path) -> Iterator[Path]:
    """Yield an empty staging folder; on success it replaces ``final`` (a folder, or nothing), on any error, the
    final rename's included, it is removed (a full disk: :class:`DiskFullError` naming ``final``)."""
    final, tmp = Path(final), partial_folder(final)
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        with full_disk_named(final):
            tmp.mkdir(parents=True)
            yield tmp
            if final.exists() and not final.is_dir():
                raise DestinationError(f"{final}: exists and is not a folder; it is not replaced")
            shutil.rmtree(final, ignore_errors=True)
            tmp.rename(final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
