"""A notebook kernel and the stage runner never work on one data folder at once (poseintegrity.workspace_lock): the
second is refused at once, naming the folder and who holds it; notebooks share the folder; a killed holder frees it."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from poseintegrity.stage import main as stage_main
from poseintegrity.workspace_lock import RUNNER, WorkspaceBusy, kernel_lock, lock_path, runner_lock
from repository import ROOT

HOLD = textwrap.dedent("""
    import sys, time
    from poseintegrity.workspace_lock import kernel_lock, runner_lock
    if sys.argv[2] == "kernel":
        kernel_lock(sys.argv[1])
        print("held", flush=True)
        time.sleep(60)
    else:
        with runner_lock(sys.argv[1], "02_extract_artifacts"):
            print("held", flush=True)
            time.sleep(60)
""")


@pytest.fixture
def holder(tmp_path):
    """``holder(kind)``: a process holding ``tmp_path / "data"``'s lock as a notebook kernel or a stage runner."""
    started = []

    def hold(kind: str) -> subprocess.Popen:
        process = subprocess.Popen([sys.executable, "-c", HOLD, str(tmp_path / "data"), kind], stdout=subprocess.PIPE,
                                   text=True, env={k: v for k, v in os.environ.items() if k != RUNNER})
        assert process.stdout.readline().strip() == "held"
        started.append(process)
        return process

    yield hold
    for process in started:
        process.kill()
        process.wait()


def test_a_notebook_is_refused_while_a_stage_writes_its_folder(tmp_path, holder):
    runner = holder("runner")
    with pytest.raises(WorkspaceBusy) as refused:
        kernel_lock(tmp_path / "data", wait_s=0.2)
    message = str(refused.value)
    assert message.startswith(f"{tmp_path / 'data'}: a stage of `dvc repro`") and f"pid {runner.pid}" in message


def test_a_stage_is_refused_while_a_notebook_kernel_is_open_on_its_folder(tmp_path, holder):
    kernel = holder("kernel")
    with pytest.raises(WorkspaceBusy) as refused:
        with runner_lock(tmp_path / "data", "02_extract_artifacts", wait_s=0.2):
            pass
    assert "so 02_extract_artifacts does not start" in str(refused.value) and f"pid {kernel.pid}" in str(refused.value)


def test_notebooks_share_a_folder_and_a_killed_holder_frees_it(tmp_path, holder):
    first = holder("kernel")
    holder("kernel")  # a second notebook open on the same data: allowed
    first.send_signal(signal.SIGKILL)
    first.wait()
    with pytest.raises(WorkspaceBusy):  # the second kernel still holds it
        with runner_lock(tmp_path / "data", "04_predictor_sweeps", wait_s=0.2):
            pass


def test_the_kernel_a_stage_starts_uses_the_stage_s_lock(tmp_path, holder, monkeypatch):
    killed = holder("runner")
    killed.kill()
    killed.wait()
    with runner_lock(tmp_path / "data", "02_extract_artifacts", wait_s=0.2) as path:  # freed by the kill
        assert os.environ[RUNNER] == str(path) == str(lock_path(tmp_path / "data"))
        kernel_lock(tmp_path / "data", wait_s=0.2)  # the runner's kernel: no lock of its own, no refusal
    assert RUNNER not in os.environ


def test_the_stage_runner_refuses_in_one_line_before_any_work(tmp_path, holder, capsys):
    """`python -m poseintegrity.stage` on a folder a notebook kernel holds: exit status 2, one line, no output
    touched."""
    holder("kernel")
    (tmp_path / "reports").mkdir()
    start = time.monotonic()
    with pytest.raises(SystemExit) as stopped:
        stage_main([str(ROOT / "notebooks" / "07_report.ipynb"), "--params", str(ROOT / "tests" / "params_tiny.yaml"),
                    "--data", str(tmp_path / "data"), "--reports", str(tmp_path / "reports")])
    assert stopped.value.code == 2 and time.monotonic() - start < 30
    error = capsys.readouterr().err.strip()
    assert "\n" not in error and error.startswith(f"07_report: {tmp_path / 'data'}: another stage run or a notebook")
    assert list((tmp_path / "reports").iterdir()) == []
