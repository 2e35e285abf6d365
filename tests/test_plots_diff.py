"""README "Reading the results": the `dvc plots diff` line, run as written on two commits of a project copy (tiny
parameters, stages 01, 02, 05 and 04 run by `dvc repro`; the second commit with another static sweep), overlays both
revisions' SPL vs R_i curves and inlier decay in one page, each point the one its revision's file holds."""

from __future__ import annotations

import csv
import io
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from project_copy import DVC, environment, project_copy, run, write_params
from repository import ROOT

pytestmark = pytest.mark.pipeline
CURVES, DECAY = "reports/plots/04_spl_vs_r_i.csv", "reports/plots/02_inlier_decay.csv"
GITIGNORE = "/.venv\n/data/datasets\n/data/calibration\n/data/artifacts\n/data/features\n/data/predictions\n" \
            "/reports/notebooks\n**/.poseintegrity.lock\n/dvc_plots\n"


def readme_command() -> str:
    """The `dvc plots diff` command of README "Reading the results", as written there."""
    section = (ROOT / "README.md").read_text().split("## Reading the results", 1)[1].split("\n## ", 1)[0]
    (command,) = re.findall(r"`(\.venv/bin/dvc plots diff [^`]+)`", section)
    return command


def git(project: Path, *argv: str) -> str:
    return subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *argv], cwd=project, check=True,
                          capture_output=True, text=True).stdout


def plotted(page: str) -> list[list[dict]]:
    """The data points of each plot on a `dvc plots diff` page (the Vega-Lite specs it embeds)."""
    specs = re.findall(r"var spec = (\{.*?\});\s*vegaEmbed", page, flags=re.S)
    return [json.loads(spec)["data"]["values"] for spec in specs]


def test_the_readme_plots_diff_overlays_two_commits_curves(tmp_path):
    project = project_copy(tmp_path / "project")
    (project / ".venv").symlink_to(Path(sys.executable).parents[1])  # `.venv/bin/dvc` as the README writes it
    _, first, _ = run([str(DVC), "repro", "04_predictor_sweeps"], project)
    (project / ".dvc" / "config").write_text("")  # under git now: `dvc plots diff` reads revisions from it
    (project / ".dvc" / ".gitignore").write_text("/config.local\n/tmp\n/cache\n")
    (project / ".gitignore").write_text(GITIGNORE)
    git(project, "init", "-q", "-b", "main")
    git(project, "add", "-A")
    git(project, "commit", "-q", "-m", "experiment 1")
    write_params(project, {"predict": {"n_static": 7}})  # the tiny parameters' 31 static sizes, 7 instead
    _, second, _ = run([str(DVC), "repro", "04_predictor_sweeps"], project)
    git(project, "commit", "-q", "-am", "experiment 2: predict.n_static 7")
    print(f"stages 01, 02, 05 and 04: {first:.0f} s; stage 04 again: {second:.0f} s")

    command = readme_command()
    done = subprocess.run(command, shell=True, cwd=project, env=environment(), capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    plots = plotted((project / "dvc_plots" / "index.html").read_text())
    assert [{point["filename"] for point in plot} for plot in plots] == [{CURVES}, {DECAY}]  # each once, no other
    points = [point for plot in plots for point in plot]
    for rev in ("HEAD~1", "HEAD"):
        for path, keys in ((CURVES, ("world", "tolerance", "predictor", "operating_point", "R_i", "mean_SPL_deg")),
                           (DECAY, ("world", "dataset", "stop", "theta_deg", "n_inliers"))):
            written = {tuple(row[k] for k in keys) for row in csv.DictReader(io.StringIO(git(project, "show",
                                                                                           f"{rev}:{path}")))}
            drawn = {tuple(str(point[k]) for k in keys) for point in points
                     if point["rev"] == rev and point["filename"] == path}
            assert written and drawn == written, (rev, path)
    static = {rev: {p["operating_point"] for p in points if p["rev"] == rev and p.get("predictor") == "static"}
              for rev in ("HEAD~1", "HEAD")}
    assert len(static["HEAD~1"]) > len(static["HEAD"]) > 0  # the static sweep of each commit, 31 sizes and 7
