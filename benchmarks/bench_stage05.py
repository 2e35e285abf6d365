"""Stage 05's cost, the code at a reference commit against this tree, measured in the same run (issues 33 and 50).

Stage 05's frame loop (``extract_datasets`` -> ``frame_rows`` of every frame, its classic methods of params.yaml)
on frames spread evenly over every dataset of ``--data-dir``, one process, OpenCV on one thread as in a worker, the
evidence read from stage 02's cache as the stage does:

1. CPU-seconds of the loop of the code at ``--reference`` (extracted with git archive; issue 33 measured a1220b7,
   one ``solvePnPRansac`` per method, against EPnP, SQPnP and iterative sharing one RANSAC: 0.43, docs/references.md)
   and of this tree, each in fresh
   processes, run alternately ``--rounds`` times with the PnP cache emptied before each of their runs; the
   ratio of the medians, and whether the rows of the two codes are identical (every column of the reference's; the
   reference runs on params.yaml without the keys its own params.yaml did not have, which its schema refuses:
   ``extract.ground_truth`` of issue 39, ``extract.consensus`` of issue 50).
2. This tree again with the PnP cache its last run left (localization/frame_pnp.py): a rerun whose keys did not
   change, against the same reference; its rows against the reference's.

Both codes read and write a temporary features folder (``extract.features_dir``), seeded with the SIFT, evidence
and M_t caches of the chosen frames found under ``<data-dir>/<features_dir>``: the data folder is never written.
A warm-up run of this tree first fills whatever is missing there (SIFT of frames stage 02 did not cache).

    .venv/bin/python benchmarks/bench_stage05.py [--data-dir data] [--frames 200] [--reference 4ec2cf1] [--rounds 3]

from the repository root, with MALLOC_MMAP_THRESHOLD_=33554432 MALLOC_TRIM_THRESHOLD_=1073741824 as the stages run.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[1]
# stage 05 before issue 50's evidence (consensus, stop spread), which stage 05 does not compute: the ratio must be ~1.
# The first reference, a1220b7 (before the shared RANSAC and the PnP cache, issue 33), cannot read the datasets
# written since issue 39 (the boards' meta.json).
REFERENCE_COMMIT = "4ec2cf1"

LOOP = """
import dataclasses, inspect, json, sys, time
from pathlib import Path
import cv2
import numpy as np
from poseintegrity.config import load_section
from poseintegrity.localization import extract as E
from poseintegrity.localization.dataset import load_dataset, load_index

params_path, data_dir, features_dir, n_frames, out = sys.argv[1:]
cv2.setNumThreads(1)  # as in a worker task (poseintegrity.workers)
params = load_section(params_path, "extract").model_copy(update={"features_dir": features_dir})
datasets = [load_dataset(data_dir, row.path, row.dataset) for row in load_index(data_dir).itertuples()]
sizes = np.cumsum([0] + [len(d.frames) for d in datasets])
chosen = np.unique(np.linspace(0, sizes[-1] - 1, int(n_frames)).round().astype(int))
datasets = [dataclasses.replace(d, frames=d.frames.iloc[chosen[(chosen >= lo) & (chosen < hi)] - lo])
            for d, lo, hi in zip(datasets, sizes[:-1], sizes[1:])]
datasets = [d for d in datasets if len(d.frames)]


class Timed:  # the Workers interface of extract_datasets, in this process, timing each map
    seconds = {}

    def map(self, function, tasks, desc="", progress=True):
        start = time.process_time()
        results = [function(task) for task in tasks]
        self.seconds[function.__name__] = time.process_time() - start
        return results


# stage 05 computes no consensus (issue 50): the code that has the switch runs as the stage does
stage_05 = {"consensus": False} if "consensus" in inspect.signature(E.extract_datasets).parameters else {}
table = E.extract_datasets(datasets, params, list(params.pnp_methods), Timed(), progress=False, **stage_05)
table.to_parquet(out + ".parquet", index=False)
Path(out + ".json").write_text(json.dumps({"seconds": Timed.seconds, "frames": int(len(chosen)),
                                           "datasets": len(datasets), "rows": len(table)}))
"""


def seed_features(data_dir: Path, features_dir: str, into: Path) -> None:
    """Copy the cached SIFT, evidence and M_t files of data_dir's features folder (all of them: the small ones)."""
    source = Path(features_dir) if Path(features_dir).is_absolute() else data_dir / features_dir
    if source.is_dir():
        shutil.copytree(source, into, dirs_exist_ok=True, ignore=shutil.ignore_patterns("*.pnp.npz"))


def run_loop(src: Path, params: Path, data_dir: Path, features: Path, frames: int, out: Path) -> dict:
    """The frame loop of the package at src in a fresh process: its CPU-seconds and where its rows are."""
    env = {**os.environ, "PYTHONPATH": str(src), "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    subprocess.run([sys.executable, "-c", LOOP, str(params), str(data_dir), str(features), str(frames), str(out)],
                   env=env, check=True)
    result = json.loads(out.with_suffix(".json").read_text())
    return result | {"table": pd.read_parquet(out.with_suffix(".parquet"))}


def reference_params(params: Path, commit: str, into: Path) -> Path:
    """``params`` without the keys the params.yaml of ``commit`` did not have (its schema refuses them), to ``into``."""
    values = yaml.safe_load(params.read_text())
    known = yaml.safe_load(subprocess.run(["git", "-C", str(ROOT), "show", f"{commit}:params.yaml"], check=True,
                                          capture_output=True, text=True).stdout)
    for section, entries in values.items():
        if isinstance(entries, dict) and isinstance(known.get(section), dict):
            values[section] = {key: value for key, value in entries.items() if key in known[section]}
    into.write_text(yaml.safe_dump(values, sort_keys=False))
    return into


def same_rows(table: pd.DataFrame, reference: pd.DataFrame) -> bool:
    """Whether ``table`` holds the reference's rows exactly, in every column the reference has."""
    return set(reference.columns) <= set(table.columns) and table[list(reference.columns)].equals(reference)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-dir", type=Path, default=ROOT / "data")
    parser.add_argument("--params", type=Path, default=ROOT / "params.yaml")
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--reference", default=REFERENCE_COMMIT)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT / "src"))
    from poseintegrity.config import load_section  # noqa: PLC0415 (after the path of this tree)

    features_dir = load_section(args.params, "extract").features_dir
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", args.reference, "src"], check=True,
                                 capture_output=True).stdout
        (folder / "reference").mkdir()
        subprocess.run(["tar", "-x", "-C", str(folder / "reference")], input=archive, check=True)
        sources = {"reference": folder / "reference" / "src", "this tree": ROOT / "src"}
        params = {"reference": reference_params(args.params, args.reference, folder / "reference_params.yaml"),
                  "this tree": args.params}
        features = folder / "features"
        seed_features(args.data_dir.resolve(), features_dir, features)
        run_loop(sources["this tree"], args.params, args.data_dir, features, args.frames, folder / "warm")
        runs = {"reference": [], "this tree": [], "this tree, cached": []}
        for _ in range(args.rounds):
            for name in ("reference", "this tree"):
                for pnp in features.rglob("*.pnp.npz"):  # each computes its PnP: a reference with the same cache
                    pnp.unlink()                        # would leave this tree nothing to compute
                runs[name].append(run_loop(sources[name], params[name], args.data_dir, features, args.frames,
                                           folder / name.replace(" ", "_")))
            runs["this tree, cached"].append(run_loop(sources["this tree"], args.params, args.data_dir, features,
                                                      args.frames, folder / "cached"))
    first = runs["reference"][0]
    print(f"stage 05 frame loop (frame_rows, {first['frames']} frames of {first['datasets']} datasets, "
          f"{first['rows']} method rows, one process, OpenCV on one thread; medians of {args.rounds} alternating "
          f"runs, CPU-seconds)")
    reference = float(np.median([run["seconds"]["frame_rows"] for run in runs["reference"]]))
    for name, name_runs in runs.items():
        seconds = float(np.median([run["seconds"]["frame_rows"] for run in name_runs]))
        models = float(np.median([run["seconds"]["store_model"] for run in name_runs]))
        differing = sum(not same_rows(run["table"], first["table"]) for run in name_runs)
        print(f"  {name:18s} {seconds:8.2f} s ({1e3 * seconds / first['frames']:6.1f} ms a frame; M_t of the datasets "
              f"{models:5.2f} s)  ratio to {args.reference}: {seconds / reference:5.3f}  rows identical to "
              f"{args.reference}'s: {len(name_runs) - differing} of {len(name_runs)} runs")


if __name__ == "__main__":
    main()
