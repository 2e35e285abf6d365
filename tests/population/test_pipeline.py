"""The population's pipeline (population/dvc.yaml, issue 49) through `.venv/bin/dvc repro`, as `make population` runs
it, in a copy of the project on the tiny parameters (tests/params_tiny.yaml: two worlds of two scenes).

One module fixture: the first world rendered, extracted and swept with its tasks on a Dask cluster on loopback (two
worker processes, as `dask scheduler` + `dask worker` give: README "Running on a Dask cluster"); then the whole
population on the local backend (DVC re-runs that world, its `parallel` param changed: the same bytes); then a third
world added to `population.worlds`, which must run that world alone (and the judge)."""

from __future__ import annotations

import hashlib
import json
import re
import shutil

import pytest
import yaml

from notebook_run import NotebookServer
from project_copy import DVC, project_copy, run, write_params
from repository import ROOT

pytestmark = pytest.mark.pipeline
TINY_WORLDS = ["w01", "w02"]
PRODUCTS = ("artifacts/artifacts.parquet", "artifacts/envelopes.parquet", "predictions/predictions.parquet",
            "datasets/index.parquet")  # a world's data files, the same on every backend


def digests(world) -> dict[str, str]:
    return {name: hashlib.md5((world / name).read_bytes()).hexdigest() for name in PRODUCTS}


@pytest.fixture(scope="module")
def population(tmp_path_factory):
    import distributed

    work = project_copy(tmp_path_factory.mktemp("population"))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=":0") as cluster:
        write_params(work, {"parallel": {"backend": "dask", "address": cluster.scheduler_address}})
        run([str(DVC), "repro", "population/dvc.yaml:predict@w01"], work)
    on_dask = digests(work / "data" / "population" / "w01")
    write_params(work, {})
    first, _, _ = run([str(DVC), "repro", "population/dvc.yaml"], work)
    on_local = digests(work / "data" / "population" / "w01")
    write_params(work, {"population": {"worlds": [*TINY_WORLDS, "w03"]}})
    added, _, _ = run([str(DVC), "repro", "population/dvc.yaml"], work)
    return work, on_dask, on_local, first, added


def test_a_world_on_a_dask_cluster_gives_the_bytes_of_the_local_workers(population):
    _, on_dask, on_local, first, _ = population
    assert "Running stage 'population/dvc.yaml:generate@w01'" in first  # its `parallel` param changed
    assert on_dask == on_local


def test_a_world_added_runs_that_world_alone(population):
    _, _, _, _, added = population
    ran = re.findall(r"Running stage '([^']+)'", added)
    # and the paper-scale stage 04, which reads the hazard models through population/dvc.lock (the first run changed it)
    assert sorted(ran) == ["04_predictor_sweeps", "population/dvc.yaml:extract@w03", "population/dvc.yaml:generate@w03",
                           "population/dvc.yaml:hazard", "population/dvc.yaml:judge", "population/dvc.yaml:predict@w03"]


def test_the_population_s_metrics_judge_every_predictor_on_every_world(population):
    work = population[0]
    metrics = json.loads((work / "reports" / "metrics" / "population.json").read_text())
    assert metrics["n_worlds"] == 3 and metrics["worlds"] == [*TINY_WORLDS, "w03"]
    for tolerance, entry in metrics["across"].items():
        for predictor in ("static", "long_range", "next_step", "error_next_step"):
            assert set(entry[predictor]) == {"own", "main", "others"}, (tolerance, predictor)
            assert entry[predictor]["own"]["n_worlds"] == 3
            assert 0.0 <= entry[predictor]["others"]["zero_incursion_worlds"] <= 1.0
    assert set(metrics["applied"]) == {"main", "validation"}  # the population's points on the paper-scale worlds
    assert (work / "reports" / "figures" / "08_population.png").stat().st_size > 10_000
    hazard = json.loads((work / "reports" / "metrics" / "hazard.json").read_text())
    assert hazard == {"trained": False, "note": hazard["note"]} and "at least 4 worlds" in hazard["note"]
    model = json.loads((work / "data" / "hazard" / "model.json").read_text())
    assert model["tolerances"] == {} and model["note"] == hazard["note"]  # stage 04 runs no hazard rows on it
    world = yaml.safe_load((work / "data" / "population" / "w03" / "params.yaml").read_text())
    assert world["extends"] == "../../../params.yaml" and world["generate"]["scenes"][0]["name"] == "w03_s1"


def test_make_population_runs_the_population_then_the_summary():
    import subprocess

    dry = subprocess.run(["make", "--no-print-directory", "-n", "population"], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout.splitlines()
    commands = [line for line in dry if "dvc repro" in line]
    assert commands[0].endswith("dvc repro population/dvc.yaml") and commands[1].endswith("dvc repro")
    assert "make population" in (ROOT / "README.md").read_text()


def test_the_population_s_notebook_runs_as_it_is_in_jupyterlab(population):
    """Notebook 08 opened in JupyterLab and run (Run All Cells, no parameters injected) in the population's project:
    it reads and writes the files its stage does."""
    work = population[0]
    written = work / "reports" / "metrics" / "population.json"
    before = written.read_text()
    written.unlink()
    with NotebookServer(work) as server:
        server.run("notebooks/08_population.ipynb")
    assert written.read_text() == before  # the same bytes as its stage's run


def test_the_hazard_notebook_runs_as_it_is_in_jupyterlab(population):
    """Notebook 09 opened in JupyterLab and run as it is: the same files as its stage (here, with 3 tiny worlds, the
    flagged model file and metrics that say why nothing was trained)."""
    work = population[0]
    written = [work / "reports" / "metrics" / "hazard.json", work / "data" / "hazard" / "model.json"]
    before = [path.read_text() for path in written]
    for path in written:
        path.unlink()
    with NotebookServer(work) as server:
        server.run("notebooks/09_hazard.ipynb")
    assert [path.read_text() for path in written] == before
