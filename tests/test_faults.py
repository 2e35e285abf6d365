"""Faults lose nothing: `dvc repro` on the tiny parameters, hit by the faults a user meets, ends in outputs equal to a
clean run's, byte for byte.

One clean run (stages 01, 02 and 05: the renders and every cache) is the reference: the md5 DVC records for each
output (dvc.lock), and every cache file's bytes. Then, each in a copy of it:

- the same stages run again (``dvc repro -f``): every output the same bytes (run records aside: the executed
  notebooks and the timing files, which hold times by nature);
- SIGKILL of the whole run at seeded moments, then a plain ``dvc repro``;
- a SIFT cache file cut in half and bits flipped in another frame's PnP results and a third's evidence: the rerun says
  which files it recomputed and why, and no damaged file survives;
- a full disk (a small tmpfs in a mount namespace of its own): one line naming the file and the free space, no
  traceback; with space back, a plain ``dvc repro``;
- a notebook kernel opening the data folder while a stage runs on it (refused by ours), and the same ``dvc repro``
  run again meanwhile (refused at once by DVC's read-write lock on the files the first run uses);
- two experiments queued (``dvc exp run --queue``) and run by two queue workers at once, against the same two run
  one by one.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from poseintegrity.cache_entry import MAGIC, TRAILER, Miss, read_whole
from project_copy import DVC, environment, project_copy, run

pytestmark = pytest.mark.pipeline
STAGES = "05_pnp_variants"  # with the stages before it: 01 (renders) and 02 (every cache)
RUN_RECORDS = ("reports/notebooks/", "reports/metrics/timing/")  # hold times by nature: not compared


def locked_outputs(project: Path) -> dict[str, str]:
    """``{output path: md5}`` of every output dvc.lock records, the run records aside."""
    lock = yaml.safe_load((project / "dvc.lock").read_text())
    return {out["path"]: out["md5"] for stage in lock["stages"].values() for out in stage.get("outs", [])
            if not out["path"].startswith(RUN_RECORDS)}


def cache_files(project: Path) -> dict[str, str]:
    """``{path under data/features: md5}`` of every file there."""
    root = project / "data" / "features"
    return {p.relative_to(root).as_posix(): hashlib.md5(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


def copy_of(clean: Path, folder: Path) -> Path:
    shutil.copytree(clean, folder, symlinks=True)
    return folder


def whole(path: Path) -> bool:
    """Whether a cache file proves it is whole: it ends in the trailer, and asked for a key none has, it answers
    "stale" (a damaged one "damaged")."""
    return path.read_bytes()[-TRAILER:].startswith(MAGIC) and read_whole(path, "no entry's key") == Miss("stale")


def without_pnp(files: dict[str, str]) -> dict[str, str]:
    """The cache files but the PnP results, which stages 02 and 05 both write (DVC ignores them)."""
    return {name: md5 for name, md5 in files.items() if not name.endswith(".pnp.npz")}


def assert_as_clean(project: Path, clean: Path, same_caches: bool = True) -> None:
    """Every output as the clean run wrote it, no staging file left, every cache file whole (and, with
    ``same_caches``, every one the clean run's bytes)."""
    assert locked_outputs(project) == locked_outputs(clean)
    ours = cache_files(project)
    assert [name for name in ours if not name.endswith(".npz")] == []  # no staging file of a killed writer
    assert [name for name in ours if not whole(project / "data" / "features" / name)] == []
    assert (ours if same_caches else without_pnp(ours)) == (cache_files(clean) if same_caches
                                                            else without_pnp(cache_files(clean)))


@pytest.fixture(scope="module")
def clean(tmp_path_factory) -> Path:
    project = project_copy(tmp_path_factory.mktemp("clean"))
    output, seconds, _ = run([str(DVC), "repro", STAGES], project)
    print(f"clean run of stages 01, 02, 05: {seconds:.0f} s")
    (project / "seconds").write_text(f"{seconds:.1f}")
    return project


def test_a_stage_run_again_writes_the_same_bytes(clean, tmp_path):
    """Every output of every stage run again (``dvc repro -f``), the caches reused: the md5 of the clean run."""
    project = copy_of(clean, tmp_path / "again")
    run([str(DVC), "repro", "-f", STAGES], project)
    assert_as_clean(project, clean)


def test_sigkill_at_seeded_moments_then_a_rerun_equals_a_clean_run(clean, tmp_path):
    """The whole run (DVC, the stage runner, its kernel and workers) killed at three seeded moments of a forced
    rerun; each time a plain `dvc repro` succeeds and every output equals the clean run's."""
    duration = float((clean / "seconds").read_text())
    rng = np.random.default_rng(51)
    project = copy_of(clean, tmp_path / "killed")
    for delay in sorted(rng.uniform(2.0, 0.9 * duration, 3)):
        started = subprocess.Popen([str(DVC), "repro", "-f", STAGES], cwd=project, env=environment(),
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        time.sleep(delay)
        os.killpg(started.pid, signal.SIGKILL)
        started.wait()
        output, _, _ = run([str(DVC), "repro", STAGES], project)
        print(f"SIGKILL after {delay:.1f} s; the rerun ran:", *[line for line in output.splitlines()
                                                              if line.startswith(("Running stage", "cache of"))],
              sep="\n  ")
        assert_as_clean(project, clean)


def damage(data: bytes) -> bytes:
    """64 bytes flipped a third of the way in."""
    data = bytearray(data)
    at = len(data) // 3
    data[at:at + 64] = bytes(b ^ 0x5A for b in data[at:at + 64])
    return bytes(data)


def test_damaged_cache_files_are_recomputed_and_said_so(clean, tmp_path):
    project = copy_of(clean, tmp_path / "damaged")
    images = sorted((project / "data" / "features").glob("*/images"))[0]
    frames = sorted(p.name.removesuffix(".evidence.npz") for p in images.glob("*.evidence.npz"))
    cut = images / f"{frames[0]}.npz"
    cut.write_bytes(cut.read_bytes()[:cut.stat().st_size // 2])
    for path in (images / f"{frames[1]}.pnp.npz", images / f"{frames[2]}.evidence.npz"):
        path.write_bytes(damage(path.read_bytes()))
    output, _, _ = run([str(DVC), "repro", STAGES], project)
    print("damaged caches, the rerun said:", *[line for line in output.splitlines() if line.startswith("cache of")],
          sep="\n  ")
    assert (f"cache of {images.parent.name}: 3 of " in output
            and "cache files recomputed (3 damaged: cut short or altered)" in output), output[-3000:]
    # the PnP file lost stage 05's entries with its damage: stage 02 rewrote its own (DVC ignores *.pnp.npz, so
    # stage 05 does not run); whole, and stage 05's next run adds its entries back
    assert_as_clean(project, clean, same_caches=False)
    differing = {name for name, md5 in cache_files(project).items() if cache_files(clean)[name] != md5}
    assert differing == {f"{images.parent.name}/images/{frames[1]}.pnp.npz"}
    run([str(DVC), "repro", "-f", STAGES], project)
    assert cache_files(project) == cache_files(clean)


FULL_DISK = textwrap.dedent("""
    set -u
    mount -t tmpfs -o size={size_kb}k tmpfs {mount}
    cp -a {source}/. {mount}/
    cd {mount}
    {dvc} repro 02_extract_artifacts > {out}/full.log 2>&1; echo $? > {out}/full.rc
    mount -o remount,size=4g {mount}
    {dvc} repro 02_extract_artifacts > {out}/again.log 2>&1; echo $? > {out}/again.rc
    cp -a {mount}/. {out}/project/
""")


def namespace_command() -> list[str] | None:
    """A command that runs a shell in a mount namespace of its own (root, or an unprivileged user namespace), or
    None where the machine allows neither."""
    for argv in (["unshare", "--mount", "--propagation", "private"],
                 ["unshare", "--user", "--map-root-user", "--mount", "--propagation", "private"]):
        if shutil.which("unshare") and subprocess.run([*argv, "true"], capture_output=True).returncode == 0:
            return argv
    return None


def test_a_full_disk_stops_in_one_line_and_a_rerun_with_space_equals_a_clean_run(clean, tmp_path):
    argv = namespace_command()
    if argv is None:
        pytest.skip("no mount namespace on this machine: the full-disk unit tests (tests/test_cache_entry.py) remain")
    source = copy_of(clean, tmp_path / "source")
    for name in ("data/features", "data/artifacts"):
        shutil.rmtree(source / name)
    used_kb = sum(p.stat().st_size for p in source.rglob("*") if p.is_file()) // 1024
    features_kb = sum(p.stat().st_size for p in (clean / "data" / "features").rglob("*") if p.is_file()) // 1024
    (tmp_path / "out").mkdir()
    (tmp_path / "mount").mkdir()
    script = FULL_DISK.format(size_kb=used_kb + features_kb // 2 + 1024, mount=tmp_path / "mount", source=source,
                              out=tmp_path / "out", dvc=DVC)
    subprocess.run([*argv, "bash", "-c", script], env=environment(), check=True, timeout=1800)
    out = tmp_path / "out"
    full = (out / "full.log").read_text()
    assert (out / "full.rc").read_text().strip() != "0", full[-3000:]
    assert "Traceback" not in full, full[-3000:]
    said = [line for line in full.splitlines() if "the disk is full" in line]
    print("full disk, the run said:", *said, sep="\n  ")
    assert len(said) == 1 and "free there" in said[0] and str(tmp_path / "mount") in said[0], full[-3000:]
    assert (out / "again.rc").read_text().strip() == "0", (out / "again.log").read_text()[-3000:]
    assert_as_clean(out / "project", clean, same_caches=False)  # stage 05's PnP entries: added by its next run


NOTEBOOK_KERNEL = textwrap.dedent("""
    import sys
    from poseintegrity.workspace_lock import WorkspaceBusy, kernel_lock
    try:
        kernel_lock(sys.argv[1], wait_s=0.5)
    except WorkspaceBusy as error:
        print(error)
""")


def test_runs_side_by_side_are_refused_at_once_and_the_first_run_is_untouched(clean, tmp_path):
    """While `dvc repro -f 02_extract_artifacts` runs stage 02: a notebook kernel opening the same data folder is
    refused by ours (stage_paths), and the same command run again is refused at once by DVC's lock on the files the
    first run uses (stage 01's outputs, stage 02's inputs); the first run then ends as a clean run. (A second run whose
    stages share no file with the running one is not refused by DVC: its stage runner then waits for the data
    folder's lock, workspace_lock, so that no two stages on one data folder ever run at once.)"""
    project = copy_of(clean, tmp_path / "side")
    command = [str(DVC), "repro", "-f", "02_extract_artifacts"]
    first = subprocess.Popen(command, cwd=project, env=environment(), stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True)
    lines = []
    for line in first.stdout:  # until stage 02's kernel runs its cells: the runner holds the data folder
        lines.append(line)
        if line.startswith("[02_extract_artifacts") and " cell " in line:
            break
    notebook = subprocess.run([sys.executable, "-c", NOTEBOOK_KERNEL, str(project / "data")], capture_output=True,
                              text=True, env=environment(), check=True)
    start = time.monotonic()
    second = subprocess.run(command, cwd=project, env=environment(), capture_output=True, text=True)
    said = second.stdout + second.stderr  # DVC's lock on the repository, or on the files the first run uses
    print("side by side, a notebook said:", notebook.stdout.strip(), "the second dvc repro said:", said.strip(),
          sep="\n  ")
    assert "a stage of `dvc repro`" in notebook.stdout and "python -m poseintegrity.stage" in notebook.stdout
    assert second.returncode != 0 and time.monotonic() - start < 30, said
    assert "Unable to acquire lock" in said or re.search(rf"is being blocked by:\s+\(PID {first.pid}\)", said), said
    rest = first.stdout.read()
    assert first.wait() == 0, "".join(lines) + rest
    assert_as_clean(project, clean)


GITIGNORE = """/data/datasets
/data/calibration
/data/artifacts
/data/fits
/data/predictions
/reports/notebooks
**/.poseintegrity.lock
/seconds
"""
EXPERIMENTS = {"a": "predict.n_static=21", "b": "predict.n_static=41"}


def git(project: Path, *argv: str) -> str:
    return subprocess.run(["git", *argv], cwd=project, check=True, capture_output=True, text=True).stdout


def experiment_outputs(project: Path, name: str) -> dict[str, str]:
    """The md5 of every output of experiment ``name``'s dvc.lock (run records aside)."""
    ref = next(ref for ref in git(project, "for-each-ref", "--format=%(refname)", "refs/exps").split()
               if ref.endswith(f"/{name}"))
    lock = yaml.safe_load(git(project, "show", f"{ref}:dvc.lock"))
    return {out["path"]: out["md5"] for stage in lock["stages"].values() for out in stage.get("outs", [])
            if not out["path"].startswith(RUN_RECORDS)}


def test_experiments_queued_on_two_workers_equal_the_same_experiments_run_one_by_one(clean, tmp_path):
    """`dvc exp run --queue` of two experiments on stage 04, run by two queue workers at once (each in a workspace of
    its own), gives the outputs the same two experiments give run one after the other in the workspace."""
    project = copy_of(clean, tmp_path / "queue")
    run([str(DVC), "repro", "04_predictor_sweeps"], project)
    (project / ".dvc" / "config").write_text("")  # under git now: DVC experiments need it
    (project / ".dvc" / ".gitignore").write_text("/config.local\n/tmp\n/cache\n")
    (project / ".gitignore").write_text(GITIGNORE)
    git(project, "init", "-q", "-b", "main")
    git(project, "-c", "user.name=t", "-c", "user.email=t@t", "add", "-A")
    git(project, "add", "-f", "data/features")  # the caches stage 02 persists: present in each experiment's workspace
    git(project, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "baseline")
    for name, setting in EXPERIMENTS.items():
        run([str(DVC), "exp", "run", "--queue", "04_predictor_sweeps", "-S", setting, "-n", f"queued_{name}"], project)
    try:
        run([str(DVC), "queue", "start", "-j", "2"], project)
        deadline = time.monotonic() + 1800
        while True:
            status, _, _ = run([str(DVC), "queue", "status"], project)
            if not any(word in status for word in ("Queued", "Running")) or time.monotonic() > deadline:
                break
            time.sleep(5)
    finally:
        subprocess.run([str(DVC), "queue", "stop", "--kill"], cwd=project, env=environment(), capture_output=True)
    assert status.count("Success") == 2, status
    for name, setting in EXPERIMENTS.items():
        run([str(DVC), "exp", "run", "04_predictor_sweeps", "-S", setting, "-n", f"one_by_one_{name}"], project)
    for name in EXPERIMENTS:
        queued, alone = experiment_outputs(project, f"queued_{name}"), experiment_outputs(project, f"one_by_one_{name}")
        assert queued == alone and "data/predictions" in queued
    assert experiment_outputs(project, "queued_a") != experiment_outputs(project, "queued_b")  # the setting mattered
