"""The stage runner (`python -m poseintegrity.stage`, every dvc.yaml cmd) on a tiny notebook of its own: output
reaches the terminal while the notebook runs, no kernel warning, HTML and a timing file; a failed or refused stage
leaves nothing that looks complete."""

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import nbformat
import pytest

from poseintegrity.kernel_pin import cpu_flags, pinned_environment
from poseintegrity.stage_timing import StageTiming, summary

PARAMETERS = 'params_path = "params.yaml"\ndata_dir = "data"\nreports_dir = "reports"'
WORK = """\
import time
from pathlib import Path
from tqdm import tqdm
from poseintegrity.config import load_section
from poseintegrity.workers import Workers

with Workers(load_section(params_path, "parallel")) as workers:
    values = workers.map(abs, [-1, -2, -3], desc="values")"""
HANDSHAKE = """\
print("waiting for the test", flush=True)
deadline = time.monotonic() + 60
while not (Path(data_dir) / "go").exists():  # the test creates it once it has read the line above
    assert time.monotonic() < deadline, "the runner did not pass the first line on while the notebook ran"
    time.sleep(0.05)"""
BAR = 'for _ in tqdm(range(50), desc="bar", mininterval=0):\n    time.sleep(0.002)'
WRITE = '(Path(data_dir) / "values.txt").write_text(str(values))'


def make_notebook(path: Path, cells: dict[str, str]) -> Path:
    """An output-free notebook like the pipeline's: first cell tagged `parameters`, readable cell ids."""
    nb = nbformat.v4.new_notebook(metadata={"kernelspec": {"name": "python3", "display_name": "Python 3",
                                                           "language": "python"}})
    nb.cells = [nbformat.v4.new_code_cell(PARAMETERS, id="parameters", metadata={"tags": ["parameters"]})]
    nb.cells += [nbformat.v4.new_code_cell(source, id=cell_id) for cell_id, source in cells.items()]
    nbformat.write(nb, path)
    return path


def runner(notebook: Path, root: Path, parallel: str) -> list[str]:
    """The command line of a dvc.yaml stage, for a project in ``root`` whose params.yaml holds ``parallel``."""
    (root / "params.yaml").write_text(f"parallel: {parallel}\n")
    (root / "data").mkdir(exist_ok=True)
    return [sys.executable, "-m", "poseintegrity.stage", str(notebook), "--params", str(root / "params.yaml"),
            "--data", str(root / "data"), "--reports", str(root / "reports")]


@pytest.mark.pipeline
def test_runner_streams_output_while_running_and_writes_notebook_html_and_timing(tmp_path):
    notebook = make_notebook(tmp_path / "demo.ipynb", {"work": WORK, "handshake": HANDSHAKE, "bar": BAR,
                                                        "write": WRITE})
    command = runner(notebook, tmp_path, "{backend: local, n_jobs: 1}")
    start = time.time()
    with open(tmp_path / "stderr.txt", "w") as stderr:
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=stderr, text=True)
        stdout = []
        for line in process.stdout:
            stdout.append(line)
            if line.startswith("waiting for the test"):
                (tmp_path / "data" / "go").touch()
        process.wait(timeout=120)
    elapsed = time.time() - start
    stdout, stderr = "".join(stdout), (tmp_path / "stderr.txt").read_text()
    assert process.returncode == 0, stderr
    assert (tmp_path / "data" / "values.txt").read_text() == "[1, 2, 3]"

    # the terminal: one line per cell, the parallel layer's progress line, the tqdm bar, no kernel warning
    assert "[demo " in stdout and "] cell handshake\n" in stdout and "cell parameters" not in stdout
    assert "values (local, n_jobs 1): 3/3 (100 %) in " in stdout
    assert "bar: 100%" in stderr and "50/50" in stderr
    assert "without encryption" not in stderr + stdout

    reports = tmp_path / "reports"
    executed = nbformat.read(reports / "notebooks" / "demo.ipynb", as_version=4)
    bar_output = next(cell for cell in executed.cells if cell.get("id") == "bar").outputs[0]["text"]
    assert "50/50" in bar_output and "\r" not in bar_output  # the saved notebook keeps the bar's last state
    assert "waiting for the test" in (reports / "notebooks" / "demo.html").read_text()
    timing = json.loads((reports / "metrics" / "timing" / "demo.json").read_text())
    assert timing["stage"] == "demo" and timing["backend"] == "local" and timing["n_jobs"] == 1
    # the stored time is rounded to 0.1 s and the process start is known to a 10 ms clock tick
    assert 0 < timing["wall_time_s"] <= elapsed + 0.05 + 0.01 + 1e-6
    assert stdout.splitlines()[-1] == StageTiming(**timing).line()
    assert not list(reports.rglob("*partial*"))


@pytest.mark.pipeline
def test_failed_stage_leaves_nothing_that_looks_complete(tmp_path):
    notebook = make_notebook(tmp_path / "demo.ipynb", {"fail": 'raise RuntimeError("boom")'})
    reports = tmp_path / "reports"
    stale = [reports / "notebooks" / "demo.ipynb", reports / "notebooks" / "demo.html",
             reports / "metrics" / "timing" / "demo.json"]  # outputs of an earlier run
    for path in stale:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("earlier run")
    result = subprocess.run(runner(notebook, tmp_path, "{backend: local, n_jobs: 1}"), capture_output=True,
                            text=True, timeout=120)
    assert result.returncode != 0
    assert "boom" in result.stderr and "demo.partial.ipynb" in result.stderr
    assert not any(path.exists() for path in stale)
    assert (reports / "notebooks" / "demo.partial.ipynb").is_file()  # how far it got, named as such


def test_bad_parallel_value_stops_before_any_work_naming_the_key(tmp_path):
    notebook = make_notebook(tmp_path / "demo.ipynb", {"work": WORK})
    result = subprocess.run(runner(notebook, tmp_path, "{backend: local, n_jobs: 0}"), capture_output=True,
                            text=True, timeout=120)
    assert result.returncode != 0 and "parallel.n_jobs" in result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "reports").exists()  # no kernel started, no folder made


def test_a_file_where_the_reports_or_data_folder_goes_is_refused_before_any_work(tmp_path):
    notebook = make_notebook(tmp_path / "demo.ipynb", {"work": WORK})
    argv = runner(notebook, tmp_path, "{backend: local, n_jobs: 1}")
    (tmp_path / "reports").write_text("mine")
    result = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    assert result.returncode == 2 and f"--reports {tmp_path / 'reports'}: exists and is not a folder" in result.stderr
    assert (tmp_path / "reports").read_text() == "mine" and "Traceback" not in result.stderr


def test_process_start_is_when_the_process_started_not_a_whole_second_before():
    """psutil's create_time rests on the boot time of /proc/stat, whole seconds: up to 1 s early, which once made
    a stage's wall time exceed the time the test measured around it."""
    before = time.time()
    result = subprocess.run([sys.executable, "-c", "import time; from poseintegrity.stage import process_start_epoch;"
                             " print(process_start_epoch(), time.time())"], capture_output=True, text=True, check=True)
    after = time.time()
    started, printed = map(float, result.stdout.split())
    assert before - 0.011 <= started <= printed <= after


def test_summary_lists_stages_in_name_order_with_their_total(tmp_path):
    for stage, seconds, backend, address in [("02_b", 30.4, "dask", "tcp://10.0.0.5:8786"),
                                             ("01_a", 12.0, "local", None)]:
        StageTiming(stage, seconds, backend, 4, address, "2025-11-23T14:02:07").write(tmp_path / f"{stage}.json")
    lines = summary(tmp_path)
    assert [line.split()[0] for line in lines] == ["01_a", "02_b", "total"]
    assert "dask at tcp://10.0.0.5:8786, n_jobs 4" in lines[1] and "finished 2025-11-23 14:02" in lines[1]
    assert lines[2].split()[1] == "42"
    assert summary(tmp_path / "missing") == []


PINNED = """\
import os
import cv2
from poseintegrity.kernel_pin import unpinned_dispatch
with Workers(load_section(params_path, "parallel")) as workers:
    in_workers = workers.map(os.getenv, ["OPENCV_CPU_DISABLE", "NUMBA_CPU_NAME", "OPENBLAS_CORETYPE"])
(Path(data_dir) / "pinned.txt").write_text(repr([os.getenv("OPENCV_CPU_DISABLE"), cv2.getCPUFeaturesLine(),
                                                 unpinned_dispatch(), in_workers]))"""


@pytest.mark.pipeline
def test_the_kernel_and_its_workers_run_pinned_whatever_the_callers_environment(tmp_path):
    """dispatch: the runner imports poseintegrity, which pins the environment its kernel and workers inherit; a
    caller's OPENCV_CPU_DISABLE=AVX2 (a lower level) and OPENBLAS_CORETYPE=Sandybridge do not reach them."""
    notebook = make_notebook(tmp_path / "pinned.ipynb", {"work": WORK, "pinned": PINNED})
    command = runner(notebook, tmp_path, "{backend: local, n_jobs: 2}")
    caller = {"OPENCV_CPU_DISABLE": "AVX2", "OPENBLAS_CORETYPE": "Sandybridge"}
    env = {k: v for k, v in os.environ.items() if k != "POSEINTEGRITY_CPU_DISPATCH"} | caller
    subprocess.run(command, env=env, check=True, capture_output=True)
    disabled, features, above, in_workers = eval((tmp_path / "data" / "pinned.txt").read_text())
    expected = pinned_environment(cpu_flags())
    assert disabled == expected["OPENCV_CPU_DISABLE"] and above == []
    assert in_workers == [expected["OPENCV_CPU_DISABLE"], "haswell", expected.get("OPENBLAS_CORETYPE")]
    if "avx2" in cpu_flags():
        assert "*AVX2 " in features  # enabled: a disabled one reads "*AVX2?"


@pytest.mark.parametrize("ours", [True, False])
def test_the_kernel_is_shut_down_without_an_interrupt(ours):
    """jupyter_client interrupts (SIGINT) a kernel before every shutdown; the runner's manager does not (a kernel still
    sending its last message logged "KeyboardInterrupt caught in kernel" into a stage's output). The other case
    checks the premise: jupyter_client's own manager does send it."""
    import asyncio
    import signal

    from jupyter_client.manager import AsyncKernelManager

    from poseintegrity.stage import KERNEL, kernel_config, kernel_manager_class, kernel_search_path

    kernel_search_path()
    manager = (kernel_manager_class() if ours else AsyncKernelManager)(kernel_name=KERNEL, config=kernel_config())
    sent = []

    async def run() -> None:
        await manager.start_kernel()
        signal_kernel = manager._async_signal_kernel

        async def spy(signum: int) -> None:
            sent.append(signum)
            await signal_kernel(signum)

        manager._async_signal_kernel = spy
        await manager.shutdown_kernel()

    asyncio.run(run())
    assert (signal.SIGINT in sent) is not ours
    assert not manager.has_kernel
