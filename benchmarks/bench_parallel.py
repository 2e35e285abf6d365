"""Dask LocalCluster (2 workers) vs the local backend (2 loky processes) on stage 02's extraction, in one run.

Issue 13's figure "Dask LocalCluster with 2 workers vs local backend on stage 02 tiny (ratio)". The work is stage
02's own: :func:`poseintegrity.localization.extract_all` with ``protocol.pnp_method`` over every dataset in
--data-dir (stage 01 output), with the ``extract`` and ``protocol`` sections of --params, from an empty cache (SIFT
features and per-frame evidence written to a fresh folder). Each measurement is a fresh process, as each stage is
a fresh kernel, and times
- "start": opening the workers and the first extraction (what a stage pays: a LocalCluster starts its processes
  on opening, loky in the first map);
- "warm": a second extraction from another empty cache on the same workers (the per-task cost once running).
Backends alternate over --rounds rounds (the machine is shared); the tables of both must be byte-identical. Run it
with the Makefile's malloc settings (as below): without them, Dask's workers default to MALLOC_TRIM_THRESHOLD_=65536
and SIFT pays its page faults again (benchmarks/bench_malloc.py), which is not what `make repro` sees.

    .venv/bin/python -m poseintegrity.stage notebooks/01_generate_datasets.ipynb --params tests/params_tiny.yaml \\
        --data /tmp/tiny/data --reports /tmp/tiny/reports          # stage 01 tiny, if there is no data yet
    MALLOC_MMAP_THRESHOLD_=33554432 MALLOC_TRIM_THRESHOLD_=1073741824 \\
        .venv/bin/python benchmarks/bench_parallel.py --data-dir /tmp/tiny/data [--rounds 3]
"""

from __future__ import annotations

import argparse
import hashlib
import io
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from poseintegrity.config import load_params
from poseintegrity.localization import extract_all
from poseintegrity.params.parallel import ParallelParams
from poseintegrity.workers import Workers

BACKENDS = {"local": ParallelParams(backend="local", n_jobs=2), "dask": ParallelParams(backend="dask", n_jobs=2)}
ROOT = Path(__file__).resolve().parents[1]


def table_digest(table) -> str:
    """SHA-256 of the parquet bytes stage 02 would write for ``table``."""
    buffer = io.BytesIO()
    table.to_parquet(buffer, index=False)
    return hashlib.sha256(buffer.getvalue()).hexdigest()


def measure(backend: str, data_dir: Path, params_path: Path) -> dict:
    """One backend in this process: seconds of start (open + first extraction) and of a warm extraction, each from
    an empty cache; the tables' digest."""
    params = load_params(params_path)
    with tempfile.TemporaryDirectory() as cache:
        fresh = [params.extract.model_copy(update=dict(features_dir=str(Path(cache) / name))) for name in ("a", "b")]
        methods = [params.protocol.pnp_method]
        start = time.perf_counter()
        with Workers(BACKENDS[backend]) as workers:
            first = extract_all(data_dir, fresh[0], methods, workers, progress=False)
            started = time.perf_counter()
            second = extract_all(data_dir, fresh[1], methods, workers, progress=False)
            warm = time.perf_counter()
    assert table_digest(first) == table_digest(second), "a warm run changed the table"
    return {"start_s": started - start, "warm_s": warm - started, "frames": int(first[["dataset", "stop", "image"]]
            .drop_duplicates().shape[0]), "digest": table_digest(first)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-dir", type=Path, default=Path("data"))
    parser.add_argument("--params", type=Path, default=ROOT / "tests" / "params_tiny.yaml")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--measure", choices=sorted(BACKENDS), help=argparse.SUPPRESS)  # the child process
    args = parser.parse_args()
    if args.measure:
        print(json.dumps(measure(args.measure, args.data_dir, args.params)))
        return
    runs = {backend: [] for backend in BACKENDS}
    for _ in range(args.rounds):
        for backend in BACKENDS:
            child = [sys.executable, __file__, "--measure", backend, "--data-dir", str(args.data_dir),
                     "--params", str(args.params)]
            output = subprocess.run(child, check=True, capture_output=True, text=True).stdout
            runs[backend].append(json.loads(output.strip().splitlines()[-1]))
    assert len({run["digest"] for rows in runs.values() for run in rows}) == 1, "backends disagree"
    print(f"{runs['local'][0]['frames']} frames of {args.data_dir}, {args.rounds} rounds, byte-identical tables")
    for backend, rows in runs.items():
        print(f"{backend:5s} start {np.median([run['start_s'] for run in rows]):6.2f} s   "
              f"warm {np.median([run['warm_s'] for run in rows]):6.2f} s   (medians)")
    pairs = list(zip(runs["dask"], runs["local"]))  # same round: same machine load
    for key in ("start_s", "warm_s"):
        ratio = np.median([dask[key] / local[key] for dask, local in pairs])
        print(f"dask LocalCluster / local wall time, {key[:-2]}: {ratio:.2f}")


if __name__ == "__main__":
    main()
