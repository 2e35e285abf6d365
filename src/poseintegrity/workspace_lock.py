"""One writer per data folder: the stage runner (``dvc repro``) against the notebooks opened in JupyterLab.

Two ``dvc repro`` in one workspace never overlap: DVC's own lock (``.dvc/tmp/lock``) refuses the second at once.
But a notebook run from JupyterLab is no DVC command: while ``dvc repro`` ran stage 02, the same notebook started by
hand would delete and write the same tables and caches, and DVC would record whichever bytes were last. So both take a
lock on the data folder they write, ``<data_dir>/.poseintegrity.lock`` (an ``flock``, released by the system when the
process ends, however it ends):

- the stage runner takes it **exclusively** for the whole stage (:func:`runner_lock`), and tells the kernel it starts
  that the lock is held for it (``POSEINTEGRITY_RUNNER_LOCK``);
- a notebook kernel takes it **shared** when its first cell resolves its paths
  (:func:`poseintegrity.project.stage_paths` -> :func:`kernel_lock`) and keeps it until the kernel shuts down, so that
  several notebooks can be open at once.

Whichever comes second is refused at once (after ``wait_s``, for a kernel that is shutting down), with one line
naming the folder, who holds it (the processes, from ``/proc/locks``) and what to do: a ``dvc repro`` never runs
over an open notebook kernel, and a notebook never runs during a stage on the same data.
"""

from __future__ import annotations

import fcntl
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from poseintegrity.errors import PoseIntegrityError

LOCK_FILE = ".poseintegrity.lock"
RUNNER = "POSEINTEGRITY_RUNNER_LOCK"  # the lock file the stage runner holds for the processes it starts
_kernel_locks: dict[Path, int] = {}  # lock file -> the open descriptor that holds it, for this process's life


class WorkspaceBusy(PoseIntegrityError):
    """The data folder is being written by another stage run or used by an open notebook kernel."""


def lock_path(data_dir: str | Path) -> Path:
    """The lock file of ``data_dir`` (absolute)."""
    return Path(os.path.abspath(data_dir)) / LOCK_FILE


def holders(path: Path) -> list[str]:
    """The processes that hold a lock on ``path``, e.g. ``["pid 812 (python -m ipykernel_launcher)"]``: read from
    ``/proc/locks`` (empty where there is none, or the file is gone)."""
    try:
        inode = path.stat().st_ino
        with open("/proc/locks", encoding="ascii", errors="replace") as locks:
            pids = sorted({int(fields[4]) for line in locks if len(fields := line.split()) > 5
                           and fields[5].rsplit(":", 1)[-1] == str(inode)})
    except (OSError, ValueError):
        return []
    found = []
    for pid in pids:
        try:
            argv = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
            what = " ".join(" ".join(arg.decode(errors="replace") for arg in argv[:4] if arg).split())[:80]
        except OSError:
            what = "ended"
        found.append(f"pid {pid} ({what})")
    return found


def _acquire(path: Path, mode: int, wait_s: float) -> int | None:
    """An open descriptor of ``path`` holding ``mode`` (fcntl.LOCK_SH / LOCK_EX), or None after ``wait_s``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    handle = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
    deadline = time.monotonic() + wait_s
    while True:
        try:
            fcntl.flock(handle, mode | fcntl.LOCK_NB)
            return handle
        except BlockingIOError:
            if time.monotonic() >= deadline:
                os.close(handle)
                return None
            time.sleep(0.1)


def _busy(path: Path, message: str) -> WorkspaceBusy:
    held = holders(path)
    return WorkspaceBusy(f"{path.parent}: {message}" + (f" (held by {', '.join(held)})" if held else ""))


@contextmanager
def runner_lock(data_dir: str | Path, stage: str, wait_s: float = 5.0) -> Iterator[Path]:
    """Hold ``data_dir``'s lock exclusively while the block runs ``stage`` (the processes it starts inherit
    ``POSEINTEGRITY_RUNNER_LOCK``); :class:`WorkspaceBusy` when a notebook kernel or another stage holds it."""
    path = lock_path(data_dir)
    handle = _acquire(path, fcntl.LOCK_EX, wait_s)
    if handle is None:
        raise _busy(path, f"another stage run or a notebook kernel works on this folder, so {stage} does not start: "
                          f"shut down the project's notebook kernels in JupyterLab (Kernel > Shut Down All "
                          f"Kernels) or wait for the other run, then run again")
    previous = os.environ.get(RUNNER)
    os.environ[RUNNER] = str(path)
    try:
        yield path
    finally:
        if previous is None:
            os.environ.pop(RUNNER, None)
        else:
            os.environ[RUNNER] = previous
        os.close(handle)


def kernel_lock(data_dir: str | Path, wait_s: float = 5.0) -> None:
    """Share ``data_dir``'s lock for the rest of this process (a notebook kernel), unless the stage runner that
    started this process holds it; :class:`WorkspaceBusy` while a stage runs on the folder."""
    path = lock_path(data_dir)
    if os.environ.get(RUNNER) == str(path) or path in _kernel_locks:
        return
    handle = _acquire(path, fcntl.LOCK_SH, wait_s)
    if handle is None:
        raise _busy(path, "a stage of `dvc repro` (or `python -m poseintegrity.stage`) is writing this folder now; "
                          "wait for it to finish, then run this notebook again (or give it another data_dir)")
    _kernel_locks[path] = handle
