"""A temporary copy of the project (dvc.yaml, notebooks, sources; its own params.yaml) in which the tests run
``.venv/bin/dvc repro`` exactly as the README says, with a PATH that holds no Python of ours."""

from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import yaml

from poseintegrity.config import merge, read_raw
from repository import ROOT

FOREIGN_PATH = "/usr/bin:/bin"  # a user's PATH: whatever `python` is there, it is not the project's venv
DVC = Path(sys.executable).parent / "dvc"  # the venv's dvc, as `.venv/bin/dvc repro`


def project_copy(folder: Path, overlay: dict, cache_dir: Path) -> Path:
    """``folder`` made a DVC project: the repository's dvc.yaml, .dvcignore, notebooks and src, and a params.yaml of
    tests/params_tiny.yaml merged with ``overlay``; its DVC cache is ``cache_dir``."""
    folder.mkdir(parents=True, exist_ok=True)
    for name in ("dvc.yaml", ".dvcignore"):
        shutil.copy(ROOT / name, folder / name)
    for name in ("notebooks", "src"):
        shutil.copytree(ROOT / name, folder / name, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    raw, _ = read_raw(ROOT / "tests" / "params_tiny.yaml")
    (folder / "params.yaml").write_text(yaml.safe_dump(merge(raw, overlay), sort_keys=False))
    (folder / ".dvc").mkdir()  # what `dvc init --no-scm` and `dvc config --local cache.dir` write, without two dvc starts
    (folder / ".dvc" / "config").write_text("[core]\n    no_scm = True\n")
    (folder / ".dvc" / "config.local").write_text(f"[cache]\n    dir = {cache_dir}\n")
    return folder


def run(argv: list[str], cwd: Path) -> tuple[str, float, float]:
    """(output, wall time s, CPU time s of the command and every process it waited for) of ``argv`` run in ``cwd``
    with the foreign PATH and none of the Makefile's settings; AssertionError with the output when it fails."""
    env = {key: value for key, value in os.environ.items()
           if key not in ("JUPYTER_PATH", "VIRTUAL_ENV") and not key.startswith(("MALLOC_", "PYTEST", "COV_"))}
    env["PATH"] = FOREIGN_PATH
    start, before = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    output = done.stdout + done.stderr
    assert done.returncode == 0, f"{' '.join(argv)} failed ({done.returncode}):\n{output[-6000:]}"
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    return output, time.perf_counter() - start, cpu
