"""The parallel layer: the same tasks give byte-identical results, in input order, on local processes and on a
Dask cluster; bad settings fail naming their key before any work; progress lines a person can follow."""

import hashlib
import socket
import sys
from pathlib import Path

import cloudpickle
import numpy as np
import pytest

from poseintegrity.config import ParamsError, parse_params
from poseintegrity.params.parallel import ParallelParams
from poseintegrity.workers import Progress, Workers, _check_workers, in_worker_task, source_digest, worker_count

# Worker processes cannot import this test module (pytest imports it from a path): send its functions by value,
# as for functions defined in a notebook. The pipeline's functions live in poseintegrity, which workers import.
cloudpickle.register_pickle_by_value(sys.modules[__name__])


@pytest.fixture(scope="module")
def cluster():
    """Two single-threaded worker processes on loopback, as `dask scheduler` + `dask worker` would give."""
    import distributed  # here, not at collection: every test process imported it, one uses it

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=":0") as local_cluster:
        yield local_cluster


def simulate(task: tuple[int, int, str]) -> tuple[int, np.ndarray]:
    """A small stage-like task: a Generator seeded by the task, LAPACK and float reductions, a file written.
    Returns (seed, result vector); task sizes differ so that tasks finish out of order on two workers."""
    seed, size, path = task
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((size, size))
    x = np.linalg.solve(a @ a.T + size * np.eye(size), rng.standard_normal(size))
    walk = np.cumsum(np.sin(rng.uniform(0.0, 2.0 * np.pi, 20_000)) * x.std())
    result = np.concatenate([x, walk[::100], [np.exp(-walk).sum()]])
    np.save(path, result)
    return seed, result


def run_tasks(workers: Workers, folder: Path) -> list[tuple[int, np.ndarray]]:
    folder.mkdir()
    tasks = [(1000 + i, (60, 220, 100, 180, 140)[i % 5], str(folder / f"{i}.npy")) for i in range(12)]
    return workers.map(simulate, tasks, desc="simulate", progress=False)


def digests(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.glob("*.npy"))}


def test_dask_cluster_gives_byte_identical_results_and_files_to_local_processes(cluster, tmp_path):
    with Workers(ParallelParams(backend="local", n_jobs=2)) as workers:
        local = run_tasks(workers, tmp_path / "local")
    with Workers(ParallelParams(backend="dask", address=cluster.scheduler_address)) as workers:
        assert workers.describe() == f"dask at {cluster.scheduler_address}, n_jobs 2"
        dask = run_tasks(workers, tmp_path / "dask")
    assert [seed for seed, _ in local] == [seed for seed, _ in dask] == list(range(1000, 1012))  # input order
    assert all(a.tobytes() == b.tobytes() for (_, a), (_, b) in zip(local, dask))
    assert digests(tmp_path / "local") == digests(tmp_path / "dask") and len(digests(tmp_path / "dask")) == 12
    assert np.load(tmp_path / "dask" / "3.npy").tobytes() == dask[3][1].tobytes()  # the file is the result


def test_without_address_dask_starts_its_own_local_cluster_of_n_jobs_workers(tmp_path):
    # one worker, not two: a cluster that ignored n_jobs would have as many as the cores (two here, and on CI), and
    # each worker process costs a second to start
    with Workers(ParallelParams(backend="dask", n_jobs=1)) as workers:
        assert workers.describe() == "dask LocalCluster, n_jobs 1"
        assert workers.map(abs, [-3, 2, -1], progress=False) == [3, 2, 1]
    with pytest.raises(RuntimeError, match="closed"):  # never a silent fall-back to local processes
        workers.map(abs, [-3])


def two_workers(request, backend: str) -> ParallelParams:
    """Two worker processes: local, or the module's Dask cluster (started only by the tests that ask for it)."""
    if backend == "dask":
        return ParallelParams(backend="dask", address=request.getfixturevalue("cluster").scheduler_address)
    return ParallelParams(n_jobs=2)


def opencv_threads(_: int) -> int:
    import cv2

    return cv2.getNumThreads()


@pytest.mark.parametrize("backend", ["local", "dask"])
def test_tasks_run_with_one_opencv_thread_and_the_caller_keeps_its_own(request, backend):
    import cv2

    params = two_workers(request, backend)
    caller = cv2.getNumThreads()
    with Workers(params) as workers:
        assert workers.map(opencv_threads, range(4), progress=False) == [1, 1, 1, 1]
    with Workers(ParallelParams(n_jobs=1)) as workers:  # in this process: limited while the task runs, then restored
        assert workers.map(opencv_threads, range(2), progress=False) == [1, 1]
    assert cv2.getNumThreads() == caller


def task_location(_: int) -> bool:
    return in_worker_task()


@pytest.mark.parametrize("backend", ["local", "dask"])
def test_tasks_know_whether_they_run_in_a_worker_process(request, backend):
    """A task's own progress bar is off in worker processes, on in the caller's (n_jobs: 1)."""
    params = two_workers(request, backend)
    with Workers(params) as workers:
        assert workers.map(task_location, range(3), progress=False) == [True, True, True]
    with Workers(ParallelParams(n_jobs=1)) as workers:
        assert workers.map(task_location, range(2), progress=False) == [False, False]
    assert not in_worker_task()


def explode_on_three(value: int) -> int:
    if value == 3:
        raise ValueError("task 3 failed")
    return value


# After the other tests on two local processes: joblib stops them on a failing task, and they would start anew
@pytest.mark.parametrize("backend", ["local", "dask"])
def test_a_failing_task_raises_its_exception_in_the_caller(request, backend):
    params = two_workers(request, backend)
    with Workers(params) as workers, pytest.raises(ValueError, match="task 3 failed"):
        workers.map(explode_on_three, range(6), progress=False)


def test_empty_task_list_returns_without_starting_anything():
    assert Workers(ParallelParams(backend="local", n_jobs=2)).map(abs, []) == []


def test_unreachable_scheduler_fails_naming_the_key_before_any_work():
    with socket.socket() as probe:  # a loopback port nobody listens on
        probe.bind(("127.0.0.1", 0))
        address = f"tcp://127.0.0.1:{probe.getsockname()[1]}"
    params = ParallelParams(backend="dask", address=address)
    # nobody listens, so no timeout is long enough to matter: a short one keeps the two tries from idling 2 s
    for connect in (lambda: Workers(params, connect_timeout_s=0.2), lambda: worker_count(params, 0.2)):
        with pytest.raises(ConnectionError, match=f"parallel.address: no Dask scheduler answers at {address}"):
            connect()


def test_workers_running_other_code_are_refused_naming_the_key(cluster):
    """A worker from another checkout would compute other results, or hang a stage that it cannot unpickle."""
    with Workers(ParallelParams(backend="dask", address=cluster.scheduler_address)) as workers:
        _check_workers(workers._client, cluster.scheduler_address, source_digest())  # same code
        with pytest.raises(ConnectionError, match=r"parallel.address: workers \['tcp://127.0.0.1:\d+', 'tcp://"):
            _check_workers(workers._client, cluster.scheduler_address, "0" * 64)


@pytest.mark.parametrize("section, key", [
    ({"backend": "spark"}, "parallel.backend"),
    ({"n_jobs": 0}, "parallel.n_jobs"),
    ({"n_jobs": -2}, "parallel.n_jobs"),
    ({"backend": "local", "address": "tcp://10.0.0.5:8786"}, "parallel.address"),  # would be silently ignored
    ({"backend": "dask", "address": "10.0.0.5:8786"}, "parallel.address"),  # no scheme
    ({"backend": "dask", "address": "tcp://10.0.0.5"}, "parallel.address"),  # no port
    ({"backend": "dask", "address": "tcp://10.0.0.5:8786/x"}, "parallel.address"),
    ({"threads": 4}, "parallel.threads"),
])
def test_bad_value_names_its_key(tiny_raw, section, key):
    tiny_raw["parallel"] = section
    with pytest.raises(ParamsError, match=key.replace(".", r"\.")):
        parse_params(tiny_raw)


def test_good_values_are_accepted(tiny_raw):
    tiny_raw["parallel"] = {"backend": "dask", "address": "tcp://[::1]:8786", "n_jobs": -1}
    assert parse_params(tiny_raw).parallel.address == "tcp://[::1]:8786"
    assert worker_count(ParallelParams(n_jobs=-1)) >= 1 and worker_count(ParallelParams(n_jobs=3)) == 3


def test_progress_prints_a_line_per_interval_and_the_last_one(capsys):
    times = iter([0.0, 5.0, 32.0, 40.0, 64.0, 70.0, 78.0])
    progress = Progress(total=6, desc="frames", interval_s=30.0, clock=lambda: next(times))
    for _ in range(6):  # tasks done at 5, 32, 40, 64, 70 and 78 s: lines due at 32, 64 (30 s later) and the end
        progress.update()
    lines = capsys.readouterr().out.splitlines()
    # at 32 s: 2 done, 16 s each, 4 left -> 64 s; at 64 s: 4 done, 16 s each, 2 left -> 32 s; 78 s / 6 = 13 s
    assert lines == ["frames: 2/6 (33 %) in 00:32, 16 s each, ~01:04 left",
                     "frames: 4/6 (67 %) in 01:04, 16 s each, ~00:32 left",
                     "frames: 6/6 (100 %) in 01:18, 13 s each"]


def test_progress_shows_fast_rates_per_second_and_can_be_silenced(capsys):
    times = iter([0.0, 0.5, 1.0, 1.5, 2.0])
    progress = Progress(total=4, desc="x", clock=lambda: next(times))
    for _ in range(4):
        progress.update()
    assert capsys.readouterr().out == "x: 4/4 (100 %) in 00:02, 2.0/s\n"
    quiet = Progress(total=1, desc="x", enabled=False)
    quiet.update()
    assert capsys.readouterr().out == ""
