"""Stage 02's extraction on the parallel layer: the local backend (2 loky processes) and a Dask LocalCluster (2
workers) write byte-identical tables for the tiny synthetic datasets, each computing from scratch (no cache)."""

import shutil

import pytest

from poseintegrity.localization import extract_all
from poseintegrity.params.parallel import ParallelParams
from poseintegrity.workers import Workers

pytestmark = pytest.mark.pipeline  # stage 02 on two backends


@pytest.mark.parametrize("methods", [["usac_magsac"]])
def test_local_processes_and_a_dask_cluster_write_the_same_bytes(synthetic_data_dir, extract_params, tmp_path,
                                                                 protocol, methods):
    assert methods == [protocol.pnp_method]  # stage 02's work
    written = {}
    for backend in ("local", "dask"):
        data_dir = tmp_path / backend
        shutil.copytree(synthetic_data_dir / "datasets", data_dir / "datasets")  # no SIFT or evidence cache
        with Workers(ParallelParams(backend=backend, n_jobs=2)) as workers:
            table = extract_all(data_dir, extract_params, methods, workers, progress=False)
        table.to_parquet(data_dir / "artifacts.parquet", index=False)
        written[backend] = (data_dir / "artifacts.parquet").read_bytes()
        assert len(list((data_dir / extract_params.features_dir).rglob("*.evidence.npz"))) == 4 * 2 + 2 * 2 + 4
    assert written["local"] == written["dask"]
    assert len(table) == 4 * 2 + 2 * 2 + 5 and set(table["status"]) >= {"ok", "bad_image", "bad_pose"}
