"""Run one pipeline stage (a ``dvc.yaml`` cmd): execute its notebook with papermill, export it to HTML, and
record its wall time::

    python -m poseintegrity.stage notebooks/02_extract_artifacts.ipynb [--params params.yaml] [--data data]
                                  [--reports reports]

writes ``<reports>/notebooks/<name>.ipynb`` and ``.html`` and ``<reports>/metrics/timing/<name>.json``
(:class:`poseintegrity.stage_timing.StageTiming`). While the notebook runs, everything it prints (the progress lines of
:mod:`poseintegrity.workers`, tqdm bars) reaches this terminal as it comes, with one line per cell.

Before any work, the notebook must exist, the ``parallel`` section is validated, a Dask scheduler at
``parallel.address`` must answer and the data folder's lock must be free (no notebook kernel open on it, no other
stage on it: :mod:`poseintegrity.workspace_lock`; the runner holds it until the stage ends): each fails naming the
file, key or folder in one line on stderr, exit status 2, no traceback (a failing cell exits with status 1 and the
cell's error; a full disk, in a cell or in the runner, with one line naming the file or folder and the free space
left, no traceback). The stage's previous outputs are deleted first and the notebook executes into
``<name>.partial.ipynb``, renamed when the HTML is written; the timing file comes last. So an interrupted or
failed stage leaves nothing that looks complete (the partial notebook shows how far it got).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

# papermill -> nbformat -> jsonschema imports rfc3987_syntax when it is installed (jupyterlab pulls it in), and
# rfc3987_syntax compiles ~35 Earley grammars on import: 2.7 s of every stage's start, for IRI formats no notebook
# schema uses (python-jsonschema/jsonschema#1428). Marked absent, jsonschema skips those two format checkers.
sys.modules.setdefault("rfc3987_syntax", None)

# papermill and nbconvert (0.5 s) are imported by run_stage once the arguments and `parallel` are checked: a command
# refused before any work answers without them.
import psutil  # noqa: E402
from tqdm import tqdm  # noqa: E402

from poseintegrity.atomic_write import FULL, DiskFullError, disk_full  # noqa: E402
from poseintegrity.config import ParamsError, load_section  # noqa: E402
from poseintegrity.params.parallel import ParallelParams  # noqa: E402
from poseintegrity.project import ProjectError, project_root  # noqa: E402
from poseintegrity.stage_timing import StageTiming, usage_error  # noqa: E402
from poseintegrity.workers import worker_count  # noqa: E402
from poseintegrity.workspace_lock import WorkspaceBusy, runner_lock  # noqa: E402

KERNEL = "python3"  # the kernelspec `make install` writes into .venv's share/jupyter (kernel_search_path)


def kernel_search_path() -> None:
    """Put this interpreter's ``share/jupyter`` first on JUPYTER_PATH, where `make install` wrote the kernelspec
    ``python3`` (``ipykernel install --sys-prefix``): a ``python3`` kernel on the user's own JUPYTER_PATH (searched
    first) would otherwise run the notebooks with another Python (docs/references.md, "DVC and papermill"). So
    ``.venv/bin/dvc repro`` needs no environment of the Makefile's; the kernel inherits the setting."""
    ours = str(Path(sys.prefix) / "share" / "jupyter")
    paths = os.environ.get("JUPYTER_PATH", "")
    if paths.split(os.pathsep)[0] != ours:
        os.environ["JUPYTER_PATH"] = os.pathsep.join(filter(None, (ours, paths)))


def kernel_config():
    """jupyter_client's KernelManager by default starts the kernel over TCP without CurveZMQ keys, and the
    kernel (ipykernel's IPKernelApp.init_sockets) then warns "Kernel is running over TCP without encryption" on
    every start. Our kernelspec declares ``supported_encryption: [curve]`` (ipykernel >= 7), so asking the manager
    to provision keys when the kernel supports them encrypts the sockets, and the warning has no cause left.
    Returns a traitlets ``Config``."""
    from traitlets.config import Config

    config = Config()
    config.KernelManager.transport_encryption = "auto"
    return config


def kernel_manager_class() -> type:
    """jupyter_client's KernelManager sends the kernel an interrupt (SIGINT) before every shutdown request, so that
    a busy kernel can take the request. The notebook has run to its end by then: a kernel still sending its last
    message catches the interrupt and logs "[IPKernelApp] ERROR | KeyboardInterrupt caught in kernel." into the
    stage's output (seen once at the end of stage 04, under load). This manager does not interrupt a kernel it is
    shutting down; a kernel that does not answer the request is still terminated, then killed
    (``shutdown_wait_time``). Interrupts at any other time are jupyter_client's own."""
    from jupyter_client.manager import AsyncKernelManager

    class ShutdownWithoutInterrupt(AsyncKernelManager):
        async def _async_interrupt_kernel(self) -> None:
            if not self.shutting_down:
                await super()._async_interrupt_kernel()

    return ShutdownWithoutInterrupt


@dataclass(frozen=True)
class StageOutputs:
    """The files the runner writes for notebook ``name`` under ``reports_dir``."""

    reports_dir: Path
    name: str

    @property
    def notebook(self) -> Path:
        return self.reports_dir / "notebooks" / f"{self.name}.ipynb"

    @property
    def partial_notebook(self) -> Path:
        return self.reports_dir / "notebooks" / f"{self.name}.partial.ipynb"

    @property
    def html(self) -> Path:
        return self.reports_dir / "notebooks" / f"{self.name}.html"

    @property
    def timing(self) -> Path:
        return self.reports_dir / "metrics" / "timing" / f"{self.name}.json"


def notebook_parameter(path: Path) -> str:
    """``path`` (relative to the current folder, as a command line gives it) as the notebook reads it: the notebook
    resolves a relative path against the project's root (:mod:`poseintegrity.project`), so a path inside the project
    is passed relative to its root (``params.yaml`` stays ``params.yaml`` under ``dvc repro``, which runs in the
    root), any other absolute."""
    path = Path(os.path.abspath(path))  # `..` folded
    try:
        return str(path.relative_to(project_root()))
    except (ProjectError, ValueError):
        return str(path)


def run_stage(notebook: Path, params_path: Path, data_dir: Path, reports_dir: Path,
              started: float | None = None) -> StageTiming:
    """Execute ``notebook`` with the three pipeline parameters (relative paths resolve against the current
    directory; :func:`notebook_parameter`), export HTML, write the timing file; return its record.

    The wall time runs from ``started`` (epoch s; default: now; the command line passes its process's start, so
    that its own imports count) to the written HTML. Raises ParamsError or ConnectionError before any work, and
    papermill.PapermillExecutionError when a cell fails, WorkspaceBusy before any work when the data folder's lock
    is held."""
    start = time.time() if started is None else started
    name = notebook.stem
    kernel_search_path()
    parallel = load_section(params_path, "parallel")
    n_jobs = worker_count(parallel)
    with runner_lock(data_dir, name):
        return _run_locked(notebook, params_path, data_dir, reports_dir, start, parallel, n_jobs)


def _run_locked(notebook: Path, params_path: Path, data_dir: Path, reports_dir: Path, start: float,
                parallel: ParallelParams, n_jobs: int) -> StageTiming:
    """:func:`run_stage` once the data folder's lock is held."""
    import papermill
    from nbconvert import HTMLExporter

    name = notebook.stem
    outputs = StageOutputs(reports_dir, name)
    for path in (outputs.notebook, outputs.html, outputs.timing):
        path.unlink(missing_ok=True)
    for path in (outputs.notebook, outputs.timing):
        path.parent.mkdir(parents=True, exist_ok=True)

    def announce_cell(cell, cell_index) -> None:
        if not {"parameters", "injected-parameters"} & set(cell.metadata.get("tags", [])):
            print(f"[{name} {tqdm.format_interval(time.time() - start)}] cell {cell.id}", flush=True)

    nb = papermill.execute_notebook(
        str(notebook), str(outputs.partial_notebook), kernel_name=KERNEL, progress_bar=False,
        parameters={"params_path": notebook_parameter(params_path), "data_dir": notebook_parameter(data_dir),
                    "reports_dir": notebook_parameter(reports_dir)},
        stdout_file=sys.stdout, stderr_file=sys.stderr,  # the kernel's output, forwarded as it arrives
        config=kernel_config(), kernel_manager_class=kernel_manager_class(), on_cell_execute=announce_cell,
        coalesce_streams=True,  # the saved notebook keeps a tqdm bar's last state, not every redraw
    )
    body, _ = HTMLExporter().from_notebook_node(nb, resources={"metadata": {"name": name}})
    partial_html = outputs.html.with_name(f"{name}.partial.html")
    partial_html.write_text(body, encoding="utf-8")
    partial_html.replace(outputs.html)
    outputs.partial_notebook.replace(outputs.notebook)
    record = StageTiming(stage=name, wall_time_s=round(time.time() - start, 1), backend=parallel.backend,
                         n_jobs=n_jobs, address=parallel.address,
                         finished_at=datetime.now().isoformat(timespec="seconds"))
    record.write(outputs.timing)
    return record


def process_start_epoch() -> float:
    """When this process started (epoch s), to the kernel's clock tick (10 ms): its age from ``/proc/self/stat``
    (start time in ticks since boot) against CLOCK_BOOTTIME. psutil's ``create_time`` adds that age to the boot
    time of ``/proc/stat``, which is whole seconds: a start up to 1 s early, and a wall time longer than the run.
    Elsewhere than Linux, psutil's figure."""
    try:
        with open("/proc/self/stat") as stat:
            start_ticks = int(stat.read().rsplit(")", 1)[1].split()[19])  # field 22, after the command name
        age_s = time.clock_gettime(time.CLOCK_BOOTTIME) - start_ticks / os.sysconf("SC_CLK_TCK")
        return time.time() - age_s
    except (OSError, AttributeError, ValueError, IndexError):
        return psutil.Process().create_time()


def _execution_error() -> type[Exception]:
    """papermill's error for a failing cell."""
    from papermill import PapermillExecutionError

    return PapermillExecutionError


def disk_full_in_cell(error, data_dir: Path) -> str | None:
    """The one line to show for a cell that failed on a full disk (papermill's ``error``: its ``ename``,
    ``evalue``): our writers' :class:`DiskFullError` names the file; any other ENOSPC (a table or figure written
    by a library) names the data folder and its free space. None for any other error."""
    if error.ename == "DiskFullError":
        return error.evalue
    if "[Errno 28]" in error.evalue or "No space left on device" in error.evalue:
        return str(disk_full(data_dir))
    return None


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("notebook", type=Path, help="source notebook, e.g. notebooks/02_extract_artifacts.ipynb")
    parser.add_argument("--params", type=Path, default=Path("params.yaml"), help="params_path of the notebook")
    parser.add_argument("--data", type=Path, default=Path("data"), help="data_dir of the notebook")
    parser.add_argument("--reports", type=Path, default=Path("reports"), help="reports_dir of the notebook")
    args = parser.parse_args(argv)
    name = args.notebook.stem
    if not args.notebook.is_file():  # bad input: one line, exit status 2, no traceback
        sys.exit(usage_error(f"{args.notebook}: no such notebook"))
    for option, folder in (("--data", args.data), ("--reports", args.reports)):
        if folder.exists() and not folder.is_dir():  # the stage writes under it: a file there is not replaced
            sys.exit(usage_error(f"{option} {folder}: exists and is not a folder"))
    partial = StageOutputs(args.reports, name).partial_notebook
    try:
        record = run_stage(args.notebook, args.params, args.data, args.reports,
                           started=process_start_epoch())
    except (ParamsError, ConnectionError, WorkspaceBusy) as error:
        sys.exit(usage_error(f"{name}: {error}"))
    except DiskFullError as error:  # the runner's own writes: the notebook, its HTML, the timing file
        sys.exit(f"{name} stopped, the disk is full: {error}")
    except OSError as error:
        if error.errno not in FULL:
            raise
        sys.exit(f"{name} stopped, the disk is full: {disk_full(error.filename or partial, error)}")
    except _execution_error() as error:  # run_stage imported papermill before any cell ran
        if (full := disk_full_in_cell(error, args.data)) is not None:
            sys.exit(f"{name} stopped, the disk is full: {full}; the notebook as far as it ran: {partial}")
        sys.exit(f"{error}\n{name} failed; the notebook as far as it ran: {partial}")
    except KeyboardInterrupt:
        sys.exit(f"{name} interrupted; the notebook as far as it ran: {partial}")
    print(record.line(), flush=True)


if __name__ == "__main__":
    main()
