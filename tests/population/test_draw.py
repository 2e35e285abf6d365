"""A world of the population drawn from the declared distribution (population/draw.py, issue 49)."""

from __future__ import annotations

import subprocess
import sys

import pytest
import yaml

from poseintegrity.config import load_params
from poseintegrity.errors import PoseIntegrityError
from poseintegrity.population.draw import world_generate, write_world
from repository import ROOT

PARAMS = load_params(ROOT / "params.yaml")


def test_a_world_is_the_same_whatever_the_other_worlds():
    population = PARAMS.population
    more = population.model_copy(update={"worlds": ["zz", *reversed(population.worlds)]})
    assert world_generate(population, "w03") == world_generate(more, "w03")  # keyed by its name, not its place
    assert world_generate(population, "w03") != world_generate(population, "w04")


def test_every_drawn_value_lies_in_its_range_and_a_scapula_has_its_tilt():
    draw = PARAMS.population.draw
    for name in PARAMS.population.worlds:
        world = world_generate(PARAMS.population, name)
        assert world["images_per_stop"] == draw.images_per_stop and world["lines"] is None
        for key, value in world["lights"].items():
            low, high = getattr(draw.lights, key)
            assert low - 0.005 <= value <= high + 0.005
        assert len(world["scenes"]) == draw.scenes_per_world
        for scene in world["scenes"]:
            assert draw.distance_mm[0] - 0.5 <= scene["distance_mm"] <= draw.distance_mm[1] + 0.5
            assert draw.elevation_deg[0] - 0.25 <= scene["elevation_deg"] <= draw.elevation_deg[1] + 0.25
            assert draw.n_clutter[0] <= scene["n_clutter"] <= draw.n_clutter[1]
            assert tuple(scene["targets"]) in draw.targets
            assert ("glenoid_tilt_deg" in scene) == any(t.startswith("scapula") for t in scene["targets"])


def test_the_ranges_contain_the_main_and_validation_worlds():
    draw, generate = PARAMS.population.draw, PARAMS.generate
    for world in generate.worlds().values():
        for scene in world.scenes:
            assert draw.distance_mm[0] <= scene.distance_mm <= draw.distance_mm[1], scene.name
            assert draw.elevation_deg[0] <= scene.elevation_deg <= draw.elevation_deg[1], scene.name
            assert draw.n_clutter[0] <= scene.n_clutter <= draw.n_clutter[1], scene.name
            assert tuple(scene.targets) in draw.targets, scene.name
            for tilt in scene.glenoid_tilt_deg or ():
                assert draw.glenoid_tilt_deg[0] <= tilt <= draw.glenoid_tilt_deg[1], scene.name
        for key in ("ambient", "ring", "room", "background"):
            low, high = getattr(draw.lights, key)
            assert low <= getattr(world.lights, key) <= high, key


def test_the_world_file_is_an_overlay_the_stages_read(tmp_path):
    out = write_world(ROOT / "params.yaml", "w01", tmp_path / "w01" / "params.yaml")
    overlay = yaml.safe_load(out.read_text())
    assert set(overlay) == {"extends", "generate"}
    world = load_params(out)
    assert world.generate.scenes[0].name == "w01_s1" and world.generate.validation is None
    assert world.extract == PARAMS.extract and world.predict == PARAMS.predict  # everything else is the main world's
    assert not (tmp_path / "w01" / "params.yaml.partial").exists()


def test_a_world_not_in_the_list_is_refused_naming_it(tmp_path):
    with pytest.raises(PoseIntegrityError, match="world 'w99' is not one of population.worlds"):
        write_world(ROOT / "params.yaml", "w99", tmp_path / "w99.yaml")
    run = subprocess.run([sys.executable, "-m", "poseintegrity.population", "draw", "w99", "--out",
                          str(tmp_path / "w99.yaml"), "--params", str(ROOT / "params.yaml")],
                         capture_output=True, text=True)
    assert run.returncode == 2 and "w99" in run.stderr and "Traceback" not in run.stderr
    assert not (tmp_path / "w99.yaml").exists()


def test_a_scene_the_robot_cannot_serve_is_drawn_again_and_the_file_says_why(tmp_path, monkeypatch):
    from poseintegrity.population import draw

    refused = []

    def problem(generate, protocol, index):  # the third scene refused at its first two draws
        scene = generate.scenes[index]
        if index == 2 and len(refused) < 2:
            refused.append(scene.distance_mm)
            return f"scene {scene.name}: refused"
        return None

    monkeypatch.setattr(draw, "arc_problem", problem)
    generate, redrawn = draw.served_world(ROOT / "params.yaml", "w01")
    assert [line.split(":")[0] for line in redrawn] == ["w01_s3 drawn again (draw 2)", "w01_s3 drawn again (draw 3)"]
    assert generate["scenes"][2] == draw.draw_scene(PARAMS.population, "w01", 2, 2)  # its third draw
    assert generate["scenes"][1] == draw.draw_scene(PARAMS.population, "w01", 1)  # the others at their first
    monkeypatch.setattr(draw, "arc_problem", lambda *args: "scene: never")
    with pytest.raises(PoseIntegrityError, match="scene 1 not served by the robot in 20 draws"):
        draw.served_world(ROOT / "params.yaml", "w01")


def test_the_robot_check_refuses_a_scene_stage_01_would_refuse():
    """arc_problem is stage 01's own check (robot placement): a scene at 900 mm, far beyond a UR5e's reach, and the
    main world's own scenes, which stage 01 renders."""
    from poseintegrity.scenes.world_checks import arc_problem

    far = PARAMS.generate.model_copy(update={"lines": None, "scenes": [PARAMS.generate.scenes[0].model_copy(
        update={"distance_mm": 900.0})]})
    assert "base placements" in arc_problem(far, PARAMS.protocol, 0)
    assert arc_problem(PARAMS.generate, PARAMS.protocol, 0) is None


@pytest.mark.parametrize(("key", "value", "message"), [
    ("n_clutter", [9, 3], "population.draw.n_clutter: a range"),
    ("targets", [["scapula"], ["femur"]], "population.draw.targets.1: must be distinct target names"),
    ("distance_mm", [440.0, 270.0], "population.draw.distance_mm"),
    ("scenes_per_world", 1, "population.draw.scenes_per_world"),
])
def test_a_bad_distribution_is_refused_naming_its_key(key, value, message):
    from poseintegrity.config import ParamsError, merge, parse_params, read_raw

    raw, base = read_raw(ROOT / "params.yaml")
    with pytest.raises(ParamsError, match=message.replace(".", r"\.")):
        parse_params(merge(raw, {"population": {"draw": {key: value}}}), "params.yaml", base)
