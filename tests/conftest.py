"""Shared fixtures: the repository root, the tiny parameters every notebook test runs with, and work done once per
test session whichever xdist worker asks for it first; the order in which the workers take the test modules."""

import atexit
import copy
import fcntl
import os
import shutil
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import settings

import poseintegrity  # noqa: F401 (first: pins the kernel dispatch before any numpy import, dispatch. Here, at the top
# of the first conftest: a test module or folder given on the command line loads its folder's conftest before
# collection starts, and tests/prediction/conftest.py imports pandas first)

# Property tests explore new random examples on every local run; on CI (CI=true) they replay a fixed set, so a
# submission never fails on a case nobody has seen. Run locally to find new counterexamples.
settings.register_profile("ci", derandomize=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


def _exit_without_finalization() -> None:
    """An xdist worker's last act: its results are with the controller, its other exit handlers have run (registered
    after this one, they run before it); Python's finalization, the teardown of the ~4 000 modules a worker has
    imported (torch, numba, pandas, Dask), took each worker 2 s more, and every run waited for it at its end."""
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


if os.environ.get("PYTEST_XDIST_WORKER"):
    atexit.register(_exit_without_finalization)

# The notebooks the tests execute save every figure as the pipeline does, without also rendering each one into the
# notebook (the inline backend's second drawing of every figure: a fifth of stage 04's time on the tiny parameters).
os.environ.setdefault("MPLBACKEND", "Agg")

ROOT = Path(__file__).resolve().parents[1]
TINY_PARAMS = ROOT / "tests" / "params_tiny.yaml"

# The longest modules first, each given whole to one worker (pyproject.toml: --dist loadscope, in this order): the
# fault battery (~10 min of `dvc repro` runs) on one worker; on the other, stage 06's project, which the recorded run
# copies and the chain's report reads (run_once), then the pipeline chain and the recorded `dvc repro` run. The
# predictor sweep (run_once) next: made at the start, it is ready when test_model_choice.py asks for it, where the
# worker that asked second sat idle for 2.5 s of the fast tier while the other made it.
LONGEST_FIRST = ("tests/test_faults.py", "tests/tracking/test_notebook_06.py", "tests/test_notebooks.py",
                 "tests/recorded/test_dvc_repro.py", "tests/test_stage.py", "tests/prediction/test_sweeps.py")


def pytest_collectstart(collector):
    """Before any test module is imported: poseintegrity.stage, so that the papermill and nbformat imports of the
    notebook tests leave out jsonschema's IRI grammars (2.7 s of every xdist worker's collection; stage.py). Not at
    the top: the xdist controller collects nothing, and it started the workers 0.5 s later for it."""
    import poseintegrity.stage  # noqa: F401


def pytest_collection_modifyitems(config, items):
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(Path(item.path).relative_to(ROOT).as_posix(), len(rank)))  # stable


@pytest.fixture(scope="session")
def run_once(tmp_path_factory) -> Callable[[str, Callable[[Path], object]], Path]:
    """``run_once(name, produce)``: a folder filled by ``produce(folder)`` once per test session, whichever worker
    asks first; a worker asking meanwhile waits for it (a file lock in the session's folder, which the xdist workers
    share) and then reads the same folder. A ``produce`` that fails leaves no folder, so the next one tries again."""
    base = tmp_path_factory.getbasetemp()
    root = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base

    def run(name: str, produce: Callable[[Path], object]) -> Path:
        folder = root / f"once-{name}"
        with open(root / f"once-{name}.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
            if not (folder / ".done").is_file():
                shutil.rmtree(folder, ignore_errors=True)
                folder.mkdir()
                try:
                    produce(folder)
                except BaseException:
                    shutil.rmtree(folder, ignore_errors=True)
                    raise
                (folder / ".done").touch()
        return folder

    return run


@pytest.fixture(scope="session")
def _tiny_raw_once() -> dict:
    from poseintegrity.config import read_raw

    return read_raw(TINY_PARAMS)[0]


@pytest.fixture
def tiny_raw(_tiny_raw_once) -> dict:
    """tests/params_tiny.yaml merged onto params.yaml, as a plain dict to be altered by a test (a copy of the one
    read per session: reading and merging the YAML took a third of every bad-value case)."""
    return copy.deepcopy(_tiny_raw_once)


@pytest.fixture
def tiny_params(tiny_raw):
    from poseintegrity.config import parse_params

    return parse_params(tiny_raw, base_dir=ROOT)
