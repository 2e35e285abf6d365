"""Cost of checking the stage tables: poseintegrity.table_checks' hand-written checks against pandera, on a paper-scale
artifacts table (60 datasets x 21 stops x 10 images x 6 PnP methods = 75 600 rows), in one run.

Prints the import time of each (a fresh interpreter each, median of 5) and the time to validate the table (median of
7), and their ratios. pandera is not a dependency of the project; without it installed the pandera rows say so
(to measure it: pip install pandera into a scratch folder and put it on PYTHONPATH).

Run: .venv/bin/python benchmarks/bench_tables.py (from the repository root)
"""

import subprocess
import sys
import time

import numpy as np
import pandas as pd

from poseintegrity.table_checks import ARTIFACT_KEYS, TRAJECTORIES, check_artifacts


def artifacts_table(rng: np.random.Generator) -> pd.DataFrame:
    """A valid artifacts table of paper scale."""
    datasets = [f"scene_{s}_arc{a:03d}" for s in range(1, 21) for a in (0, 90, 270)]
    stops, images, methods = np.arange(21), np.arange(10), ["usac_magsac", "epnp", "p3p", "ap3p", "sqpnp", "iterative"]
    index = pd.MultiIndex.from_product([datasets, stops, images, methods], names=["dataset", "stop", "image", "method"])
    table = index.to_frame(index=False)
    n = len(table)
    return table.assign(world="main", trajectory="arc", theta_deg=2.25 * table["stop"], x_mm=0.0, status="ok",
                        n_inliers=rng.integers(0, 300, n).astype(float), E_t_mm=rng.gamma(2.0, 0.2, n),
                        E_r_deg=rng.gamma(2.0, 0.1, n))


def median_s(function, repeats: int = 7) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def import_s(statement: str) -> float:
    """Median wall time of a fresh interpreter running ``statement`` minus one running ``import pandas``."""
    def run(code: str) -> float:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True)
        return time.perf_counter() - start
    base = np.median([run("import pandas") for _ in range(5)])
    return float(np.median([run(f"import pandas; {statement}") for _ in range(5)]) - base)


def pandera_schema():
    import pandera.pandas as pa

    count = pa.Check.ge(0)
    return pa.DataFrameSchema(
        {"world": pa.Column(str), "dataset": pa.Column(str), "trajectory": pa.Column(str, pa.Check.isin(TRAJECTORIES)),
         "stop": pa.Column(int, count), "image": pa.Column(int, count), "theta_deg": pa.Column(float),
         "x_mm": pa.Column(float), "method": pa.Column(str), "status": pa.Column(str),
         "n_inliers": pa.Column(float, count, nullable=True), "E_t_mm": pa.Column(float, count, nullable=True),
         "E_r_deg": pa.Column(float, count, nullable=True)},
        unique=list(ARTIFACT_KEYS))


def main() -> None:
    table = artifacts_table(np.random.default_rng(0))
    ours = median_s(lambda: check_artifacts(table))
    ours_import = import_s("import poseintegrity.table_checks")
    print(f"artifacts table: {len(table)} rows")
    print(f"poseintegrity.table_checks  import {ours_import * 1e3:7.0f} ms beyond pandas   check {ours * 1e3:7.1f} ms")
    try:
        schema = pandera_schema()
    except ImportError:
        print("pandera               not installed (not a dependency)")
        return
    theirs = median_s(lambda: schema.validate(table))
    theirs_import = import_s("import pandera.pandas")
    print(f"pandera               import {theirs_import * 1e3:7.0f} ms beyond pandas   check {theirs * 1e3:7.1f} ms")
    print(f"pandera / ours        import x{theirs_import / max(ours_import, 1e-3):.1f}   check x{theirs / ours:.2f}")


if __name__ == "__main__":
    main()
