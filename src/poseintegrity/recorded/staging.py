"""Write a folder atomically: into a hidden staging folder beside it, renamed when complete, so that an interrupted
run leaves nothing that looks complete (a leftover ``.<name>.partial`` is removed by the next run)."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def staged(final: Path) -> Iterator[Path]:
    """Yield an empty staging folder; on success it replaces ``final``, on an error it is removed."""
    final = Path(final)
    tmp = final.parent / f".{final.name}.partial"
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    shutil.rmtree(final, ignore_errors=True)
    tmp.rename(final)
