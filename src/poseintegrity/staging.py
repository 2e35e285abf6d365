"""Write a folder atomically: into a hidden staging folder beside it (``.<name>.partial``), renamed when complete,
so that an interrupted run leaves nothing that looks complete (a leftover staging folder is replaced by the next
run). Stage 01's datasets and calibration sessions and the recorded-data writers all write this way."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


def partial_folder(final: Path) -> Path:
    """The staging folder of ``final``: ``.<name>.partial`` beside it."""
    final = Path(final)
    return final.parent / f".{final.name}.partial"


@contextmanager
def staged(final: Path) -> Iterator[Path]:
    """Yield an empty staging folder; on success it replaces ``final``, on an error it is removed."""
    final, tmp = Path(final), partial_folder(final)
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    shutil.rmtree(final, ignore_errors=True)
    tmp.rename(final)
