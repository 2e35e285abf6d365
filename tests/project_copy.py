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

from notebook_run import TINY_PARAMS
from poseintegrity.config import merge, read_raw
from repository import ROOT

FOREIGN_PATH = "/usr/bin:/bin"  # a user's PATH: whatever `python` is there, it is not the project's venv
DVC = Path(sys.executable).parent / "dvc"  # the venv's dvc, as `.venv/bin/dvc repro`


def project_copy(folder: Path) -> Path:
    """``folder`` made a DVC project: the repository's dvc.yaml, .dvcignore, population/ pipeline and its hazard models,
    notebooks and src, the plot templates (.dvc/plots), and tests/params_tiny.yaml as its params.yaml
    (:func:`write_params` changes it); its DVC cache is its own (.dvc/cache)."""
    folder.mkdir(parents=True, exist_ok=True)
    # stage 07 reads the population's lock; stage 04 applies the hazard models the population trained (in git)
    for name in ("dvc.yaml", ".dvcignore", "population/dvc.yaml", "population/dvc.lock", "data/hazard/model.json"):
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / name, folder / name)
    for name in ("notebooks", "src"):
        shutil.copytree(ROOT / name, folder / name, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    (folder / ".dvc").mkdir()  # what `dvc init --no-scm` writes, without a dvc start
    (folder / ".dvc" / "config").write_text("[core]\n    no_scm = True\n")
    shutil.copytree(ROOT / ".dvc" / "plots", folder / ".dvc" / "plots")  # the templates of dvc.yaml's data plots
    return write_params(folder, {})


def write_params(folder: Path, overlay: dict) -> Path:
    """``folder / "params.yaml"``: tests/params_tiny.yaml merged with ``overlay``; returns ``folder``."""
    raw, _ = read_raw(TINY_PARAMS)
    (folder / "params.yaml").write_text(yaml.safe_dump(merge(raw, overlay), sort_keys=False))
    return folder


def stage_06_project(folder: Path) -> None:
    """A project copy on the tiny parameters in ``folder`` with stage 06 run by `dvc repro 06_marker_tracking`.

    The marker-tracking study depends on no other stage and on no ``generate`` key, so the tests run it once per
    session (``run_once("stage_06", stage_06_project)``): tests/tracking/test_notebook_06.py checks its outputs, the
    notebook chain's report reads its metrics, and the recorded `dvc repro` starts from a copy of this project, where
    DVC finds stage 06 done (its lock entry, outputs and cache) and runs the other six."""
    project_copy(folder)
    run([str(DVC), "repro", "06_marker_tracking"], folder)


def environment() -> dict[str, str]:
    """The environment a command of the tests runs in: a user's PATH (:data:`FOREIGN_PATH`), none of the Makefile's or
    pytest's settings."""
    env = {key: value for key, value in os.environ.items()
           if key not in ("JUPYTER_PATH", "VIRTUAL_ENV") and not key.startswith(("MALLOC_", "PYTEST", "COV_"))}
    return env | {"PATH": FOREIGN_PATH}


def run(argv: list[str], cwd: Path) -> tuple[str, float, float]:
    """(output, wall time s, CPU time s of the command and every process it waited for) of ``argv`` run in ``cwd``
    with the foreign PATH and none of the Makefile's settings; AssertionError with the output when it fails."""
    env = environment()
    start, before = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    output = done.stdout + done.stderr
    assert done.returncode == 0, f"{' '.join(argv)} failed ({done.returncode}):\n{output[-6000:]}"
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    return output, time.perf_counter() - start, cpu
