"""One parallel layer, two backends: map a function over a list of tasks on local processes or a Dask cluster.

The ``parallel`` section of ``params.yaml`` chooses the backend (:class:`~poseintegrity.params.parallel.ParallelParams`); the code that runs
tasks does not change::

    from functools import partial
    from poseintegrity.config import load_section
    from poseintegrity.workers import Workers

    parallel = load_section("params.yaml", "parallel")
    with Workers(parallel) as workers:                    # connects (or starts a LocalCluster) before any work
        rows = workers.map(partial(localize_frame, model=model), frames, desc="scene_2_arc090 frames")

``map`` returns a list with one result per task, in the order of the tasks, whatever order they finish in. A
task and its function must be picklable, and a task draws random numbers only from a generator seeded by the
task itself (e.g. ``np.random.default_rng(task.seed)``): then both backends return byte-identical results
(tests/test_workers.py). Both run one task at a time per worker process with one BLAS/OpenMP thread and one
OpenCV thread (:func:`run_single_threaded`), so that float reductions run in the same order whichever backend runs
them, and two workers on two cores do not start four threads each. (The local backend with ``n_jobs: 1`` runs
the tasks one after the other in the calling process, where tracebacks and debuggers work as usual.)

Dask workers on other machines must see the same files at the same paths and run the same environment (README,
"Running on a Dask cluster"); connecting checks that every worker runs the same poseintegrity source.
"""

from __future__ import annotations

import hashlib
import os
import time
from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path
from typing import TypeVar

import cv2
import joblib
from tqdm import tqdm

from poseintegrity.params.parallel import ParallelParams

Task = TypeVar("Task")
Result = TypeVar("Result")

def worker_count(params: ParallelParams, connect_timeout_s: float = 10.0) -> int:
    """How many tasks run at once: ``n_jobs`` (-1: the cores of this machine) for local processes and a
    LocalCluster; the threads of the workers connected to the scheduler at ``address`` (which must answer:
    ConnectionError naming ``parallel.address`` otherwise)."""
    if params.address is None:
        return joblib.cpu_count() if params.n_jobs == -1 else params.n_jobs
    with _connect(params.address, connect_timeout_s) as client:
        return sum(client.nthreads().values())


def describe_backend(backend: str, address: str | None, n_jobs: int) -> str:
    """``"local, n_jobs 2"``, ``"dask LocalCluster, n_jobs 2"`` or ``"dask at tcp://10.0.0.5:8786, n_jobs 8"``."""
    if backend == "local":
        return f"local, n_jobs {n_jobs}"
    return f"dask {f'at {address}' if address else 'LocalCluster'}, n_jobs {n_jobs}"


def source_digest() -> str:
    """SHA-256 of poseintegrity's source files: the same on two machines exactly when they run the same code."""
    package = Path(__file__).parent
    digest = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        digest.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()


def _connect(address: str, timeout_s: float):
    """A client of the scheduler at ``address`` whose connected workers run this machine's poseintegrity code
    (a worker that cannot even load a task's function would otherwise leave the stage waiting forever)."""
    from distributed import Client  # imported on use: a second to import, and the local backend never needs it

    try:
        client = Client(address, timeout=timeout_s, set_as_default=False)
    except OSError as error:  # refused, unresolvable, or timed out (TimeoutError is an OSError)
        raise ConnectionError(
            f"parallel.address: no Dask scheduler answers at {address} within {timeout_s:g} s ({error}); start one "
            f"with `dask scheduler`, or set parallel.address: null to start a LocalCluster") from None
    try:
        _check_workers(client, address, source_digest())
    except ConnectionError:
        client.close()
        raise
    return client


def _check_workers(client, address: str, expected_digest: str) -> None:
    """ConnectionError naming ``parallel.address`` unless every connected worker has ``expected_digest``."""
    try:
        digests = client.run(source_digest)
    except Exception as error:  # a worker without poseintegrity cannot even unpickle source_digest
        raise ConnectionError(f"parallel.address: the workers of {address} cannot run poseintegrity ({error!r}); "
                              f"start them with the project's .venv") from None
    others = sorted(worker for worker, digest in digests.items() if digest != expected_digest)
    if others:
        raise ConnectionError(f"parallel.address: workers {others} of {address} run other poseintegrity code than "
                              f"this machine; start every worker from the same checkout")


_in_worker_task = False


def in_worker_task() -> bool:
    """True while a task of :meth:`Workers.map` runs in a worker process (not in the caller's own process, as
    with ``n_jobs: 1``). A task's own progress bar is then off: the workers share the terminal, their bars would
    interleave, and the map already prints a progress line for the tasks."""
    return _in_worker_task


def run_single_threaded(function: Callable[[Task], Result], task: Task, caller_pid: int) -> Result:
    """``function(task)`` with OpenCV's own thread pool limited to one thread (joblib and Dask limit BLAS and
    OpenMP, not OpenCV's pthreads pool): with one task per core, SIFT runs 5-8 % faster per frame than with every
    worker starting a thread per core (benchmarks/bench_opencv_threads.py). The previous setting is restored, so the
    in-process ``n_jobs: 1`` path leaves the caller's OpenCV as it was. ``caller_pid``: the process that mapped
    the task (:func:`in_worker_task` is True in any other)."""
    global _in_worker_task
    previous = cv2.getNumThreads(), _in_worker_task
    cv2.setNumThreads(1)
    _in_worker_task = os.getpid() != caller_pid
    try:
        return function(task)
    finally:
        cv2.setNumThreads(previous[0])
        _in_worker_task = previous[1]


class Workers:
    """The worker processes of one :class:`ParallelParams`, open from construction to :meth:`close` (or the end
    of a ``with`` block).

    local: joblib's loky processes, started on the first map and reused. dask with an address: a client of that
    scheduler; a ConnectionError naming ``parallel.address`` is raised here, before any work, when it does not
    answer within ``connect_timeout_s``. dask without one: a ``distributed.LocalCluster`` of ``n_jobs``
    single-threaded worker processes, closed again by :meth:`close`.
    """

    def __init__(self, params: ParallelParams, connect_timeout_s: float = 10.0):
        self.params = params
        self._cluster = None
        self._client = None
        self._closed = False
        if params.backend == "dask" and params.address is not None:
            self._client = _connect(params.address, connect_timeout_s)
        elif params.backend == "dask":
            from distributed import Client, LocalCluster

            self._cluster = LocalCluster(n_workers=worker_count(params), threads_per_worker=1, processes=True,
                                         dashboard_address=":0")  # any free port: 8787 may be another cluster's
            self._client = Client(self._cluster, set_as_default=False)

    def __enter__(self) -> Workers:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def close(self) -> None:
        """Disconnect from the scheduler and stop the LocalCluster this object started (no-op for local)."""
        if self._client is not None:
            self._client.close()
        if self._cluster is not None:
            self._cluster.close()
        self._client = self._cluster = None
        self._closed = True

    def describe(self) -> str:
        """Where the tasks run, for progress lines: see :func:`describe_backend`."""
        n_jobs = worker_count(self.params) if self._client is None else sum(self._client.nthreads().values())
        return describe_backend(self.params.backend, self.params.address, n_jobs)

    def map(self, function: Callable[[Task], Result], tasks: Sequence[Task], desc: str = "tasks",
            progress: bool = True) -> list[Result]:
        """``[function(task) for task in tasks]`` (n tasks -> a list of n results, in task order), computed on
        the workers, printing progress lines labelled ``desc`` to stdout (:class:`Progress`) unless ``progress``
        is False. An exception raised by a task is raised here (the tasks not yet run are cancelled)."""
        if self._closed:
            raise RuntimeError("these Workers are closed: open new ones")
        tasks = list(tasks)
        if not tasks:
            return []
        meter = Progress(len(tasks), f"{desc} ({self.describe()})", enabled=progress)
        if self._client is None:
            return self._map_local(function, tasks, meter)
        return self._map_dask(function, tasks, meter)

    def _map_local(self, function, tasks, meter: Progress) -> list:
        results = []
        with joblib.parallel_config(backend="loky", inner_max_num_threads=1):
            for result in joblib.Parallel(n_jobs=self.params.n_jobs, return_as="generator")(
                    joblib.delayed(run_single_threaded)(function, task, os.getpid()) for task in tasks):
                results.append(result)
                meter.update()
        return results

    def _map_dask(self, function, tasks, meter: Progress) -> list:
        from distributed import as_completed

        # pure=False: every task runs, even two equal ones (Dask would otherwise compute a key's result once)
        futures = self._client.map(partial(run_single_threaded, function, caller_pid=os.getpid()), tasks, pure=False)
        position = {future.key: index for index, future in enumerate(futures)}
        results = [None] * len(tasks)
        try:
            for future, result in as_completed(futures, loop=self._client.loop, with_results=True):
                results[position[future.key]] = result
                meter.update()
        except BaseException:
            self._client.cancel(futures)
            raise
        return results


class Progress:
    """Progress of ``total`` tasks as whole lines a person (or a log file) can follow, printed to stdout:

        scene_2_arc090 frames (local, n_jobs 2): 120/480 (25 %) in 00:45, 2.7/s, ~02:15 left

    one line when ``interval_s`` seconds have passed since the previous one, and a last one when every task is
    done. Lines, not a carriage-return bar: they pass through papermill to the terminal and stay readable in the
    executed notebook.
    """

    def __init__(self, total: int, desc: str, interval_s: float = 30.0, enabled: bool = True,
                 clock: Callable[[], float] = time.monotonic):
        self.total, self.desc, self.interval_s, self.enabled, self.clock = total, desc, interval_s, enabled, clock
        self.done = 0
        self.start = self.last_line = clock()

    def update(self, n: int = 1) -> None:
        """Count ``n`` more finished tasks; print a line if one is due."""
        self.done += n
        now = self.clock()
        if self.enabled and (self.done >= self.total or now - self.last_line >= self.interval_s):
            print(self.line(now), flush=True)
            self.last_line = now

    def line(self, now: float) -> str:
        """The progress line at time ``now`` (clock seconds)."""
        elapsed = now - self.start
        rate = self.done / elapsed if elapsed > 0 else float("inf")
        text = (f"{self.desc}: {self.done}/{self.total} ({100 * self.done / self.total:.0f} %) in "
                f"{tqdm.format_interval(elapsed)}, {_rate(rate)}")
        if self.done < self.total:
            text += f", ~{tqdm.format_interval((self.total - self.done) / rate)} left"
        return text


def _rate(tasks_per_s: float) -> str:
    """``"2.7/s"``; ``"41 s each"`` below one task per second."""
    return f"{tasks_per_s:.1f}/s" if tasks_per_s >= 1 else f"{1 / tasks_per_s:.0f} s each"
