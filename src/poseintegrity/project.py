"""The project's root, against which a notebook's parameters (``params_path``, ``data_dir``, ``reports_dir``)
resolve, wherever its kernel started.

The stage runner (``dvc repro``, papermill) starts a notebook's kernel in the project's root; JupyterLab, VS Code and
``jupyter nbconvert --execute`` start it in the notebook's own folder, ``notebooks/``. The root is the nearest folder
holding ``dvc.yaml`` at or above the kernel's folder (the notebook's folder, or the root itself), so a notebook opened
either way reads and writes the files ``dvc repro`` does. Every pipeline notebook's first cell after its parameters
calls :func:`stage_paths`, which also takes its data folder's lock (:mod:`poseintegrity.workspace_lock`): a notebook
never writes the files a running ``dvc repro`` writes, nor the other way round.
"""

from __future__ import annotations

import os
from pathlib import Path

from poseintegrity.errors import ArgumentError, PoseIntegrityError
from poseintegrity.workspace_lock import kernel_lock

MARKER = "dvc.yaml"  # the file that makes a folder the project's root


class ProjectError(PoseIntegrityError):
    """No project's root (a folder holding dvc.yaml) at or above the folder a notebook's kernel started in."""


def project_root(start: str | Path | None = None) -> Path:
    """The nearest folder at or above ``start`` (default: the current folder, where the kernel started) that holds
    ``dvc.yaml``, as an absolute path; :class:`ProjectError` naming ``start`` when none does."""
    start = Path.cwd() if start is None else Path(start).absolute()
    for folder in (start, *start.parents):
        if (folder / MARKER).is_file():
            return folder
    raise ProjectError(f"no {MARKER} in {start} or any folder above it: a notebook's relative paths (params.yaml, "
                       f"data, reports) resolve against the project's root, the folder of {MARKER}, looked for from "
                       f"the folder its kernel started in (the notebook's folder in JupyterLab). Open the notebook in "
                       f"a clone of the project, or give absolute paths in its parameters cell")


def project_paths(*paths: str | os.PathLike, start: str | Path | None = None) -> tuple[Path, ...]:
    """``paths`` as absolute paths: an absolute one as it is, a relative one joined to :func:`project_root`
    (``start`` as there), which is looked for only when some path is relative, so that absolute paths work outside
    any project. ``params_path, data_dir, reports_dir = project_paths(params_path, data_dir, reports_dir)``."""
    for i, path in enumerate(paths):
        if not isinstance(path, (str, os.PathLike)):
            raise ArgumentError(f"paths[{i}]: expected a path (str or os.PathLike), got {type(path).__name__} "
                                f"{path!r:.60}")
    paths = tuple(Path(path) for path in paths)
    if all(path.is_absolute() for path in paths):
        return paths
    root = project_root(start)
    return tuple(root / path for path in paths)


def stage_paths(params_path: str | os.PathLike, data_dir: str | os.PathLike, reports_dir: str | os.PathLike,
                start: str | Path | None = None) -> tuple[Path, Path, Path]:
    """A pipeline notebook's three parameters as absolute paths (:func:`project_paths`), with ``data_dir``'s lock
    shared by this kernel for the rest of its life (:func:`~poseintegrity.workspace_lock.kernel_lock`; nothing to
    take when the stage runner started it): :class:`~poseintegrity.workspace_lock.WorkspaceBusy` naming the folder
    while a stage runs on it."""
    params_path, data_dir, reports_dir = project_paths(params_path, data_dir, reports_dir, start=start)
    kernel_lock(data_dir)
    return params_path, data_dir, reports_dir
