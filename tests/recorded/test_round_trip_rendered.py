"""The round trip on the renderer's own output (stage 01 on the tiny parameters, main world): its datasets exported
to the recorded format, checked by validate and materialized back give stage 02 artifact rows identical to the
originals'. Unlike the synthetic scenes, these images come through a distorting lens (plumb_bob camera.yaml of a
calibration), the model pair's relative pose is the robot's report rather than the exact one, and every stop holds
the robot's recorded theta / x."""

from __future__ import annotations

import pytest

from poseintegrity.config import load_params
from poseintegrity.localization.dataset import load_index
from poseintegrity.localization.extract import extract_dataset
from poseintegrity.recorded.export import export_all
from poseintegrity.recorded.materialize import materialize_source
from poseintegrity.recorded.reader import problems, read_recorded
from poseintegrity.scenes import dataset
from poseintegrity.workers import Workers
from recorded_tools import assert_rows_identical
from repository import ROOT

pytestmark = pytest.mark.pipeline  # stages 01 and 02 on the tiny parameters

TINY = load_params(ROOT / "tests" / "params_tiny.yaml")


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """Stage 01's datasets of one azimuth per scene and the line (main world only)."""
    params = TINY.generate.model_copy(update={"validation": None,
                                              "arcs": TINY.generate.arcs.model_copy(update={"azimuths_deg": [0.0]})})
    top = tmp_path_factory.mktemp("stage01")
    with Workers(TINY.parallel) as workers:
        dataset.generate(params, TINY.protocol, top / "datasets", workers, calibration_dir=top / "calibration",
                         progress=False)
    return top


def test_rendered_datasets_round_trip_to_identical_artifact_rows(rendered, tmp_path):
    export_all(rendered, tmp_path / "recorded")
    assert all(problems(folder) == [] for folder in (tmp_path / "recorded").iterdir())
    materialize_source(tmp_path / "recorded", tmp_path / "data")
    index = load_index(rendered)
    assert set(index["trajectory"]) == {"arc", "line"}
    with Workers(TINY.parallel) as workers:
        for row in index.itertuples():
            original = extract_dataset(rendered, row.path, TINY.extract, ["epnp"], workers, progress=False)
            again = extract_dataset(tmp_path / "data", row.path, TINY.extract, ["epnp"], workers, progress=False)
            assert (original["status"] == "ok").any()
            assert_rows_identical(original, again)


def test_positions_from_the_exact_poses_match_what_the_robot_recorded(rendered, tmp_path):
    """Stops without theta_deg / x_mm: computed from the renderer's exact poses they agree with the robot's records
    (theta from the model view for arcs; for the line x from its first position and theta its offset), to the
    robot's landing and ring-down error."""
    export_all(rendered, tmp_path / "recorded")
    for folder in sorted((tmp_path / "recorded").iterdir()):
        recorded = read_recorded(folder)
        stops = folder / "stops.csv"
        lines = stops.read_text().splitlines()
        stops.write_text("\n".join(",".join(line.split(",")[:2] + line.split(",")[4:]) for line in lines) + "\n")
        computed = read_recorded(folder)
        assert "theta_deg" not in stops.read_text()
        for robot, ours in zip(recorded.frames, computed.frames):
            assert abs(robot.theta_deg - ours.theta_deg) < 0.1 and abs(robot.x_mm - ours.x_mm) < 0.5  # measured 0.05, 0.09
        assert max(f.x_mm for f in computed.frames) > 50 or max(f.theta_deg for f in computed.frames) > 10
