"""Write a folder atomically: into a hidden staging folder beside it (``.<name>.partial``), renamed when complete,
so that an interrupted run leaves nothing that looks complete (a leftover staging folder is replaced by the next
run). Stage 01's datasets and calibration sessions and the recorded-data writers all write this way.

A command line that writes a folder or file the user names (``--out``) checks it first
(:func:`check_new_folder`, :func:`check_new_file`): before any work, and so that nothing of the user's is replaced.
"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from poseintegrity.errors import PoseIntegrityError


class DestinationError(PoseIntegrityError):
    """An output path that would replace something of the user's, or cannot be written: named with what is there."""


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
    final rename's included, it is removed."""
    final, tmp = Path(final), partial_folder(final)
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    try:
        yield tmp
        if final.exists() and not final.is_dir():
            raise DestinationError(f"{final}: exists and is not a folder; it is not replaced")
        shutil.rmtree(final, ignore_errors=True)
        tmp.rename(final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
