"""A world of the population drawn from the declared distribution (``population.draw``, issue 49).

World ``<name>`` draws its ``generate.seed`` (which draws its textures, foam relief, scene layouts, robot, calibration
session and sensor noise in stage 01) and its lights from ``keyed_rng(population.seed, name, "world")``, and each scene
from ``keyed_rng(population.seed, name, "scene", index, attempt)``: the distance and elevation of the model view, the
clutter, the target combination and a scapula's glenoid tilts, each uniform within its range. Adding a world or
reordering ``population.worlds`` changes no other world. Values are rounded as a lab would set them (1 mm, 0.5 deg,
1 deg of tilt, 0.01 of a light).

A lab only records a scene its robot can serve: a scene whose targets leave a model view, or which the world's robot
reaches from none of its base placements (:func:`~poseintegrity.scenes.world_checks.arc_problem`, the checks stage 01
makes, before any board is planned), is drawn again (``attempt`` + 1, at most MAX_ATTEMPTS times). The population is
therefore the declared distribution conditioned on scenes the robot serves; the world's file names every scene drawn
again and why.

The world's params file is an overlay on the project's params (``extends``), replacing only ``generate``'s seed,
images per stop, lights and scenes, with no lines and no validation world: every other setting (camera, sensor,
boards, robot model, materials, protocol, extract, fit, predict) is the main world's.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import yaml

from poseintegrity.config import load_params, merge, parse_params, read_raw
from poseintegrity.errors import ArgumentError, PoseIntegrityError
from poseintegrity.params.population import PopulationParams, WorldDraw
from poseintegrity.scenes.world_checks import arc_problem
from poseintegrity.seeding import keyed_rng

MAX_ATTEMPTS = 20  # draws of one scene before the world is refused: its ranges leave the robot almost nothing


def draw_scene(population: PopulationParams, name: str, index: int, attempt: int = 0) -> dict:
    """Scene ``index`` of world ``name`` (its ``attempt``-th draw), as plain YAML values of ``generate.scenes``."""
    draw: WorldDraw = population.draw
    rng = keyed_rng(population.seed, name, "scene", index, attempt)
    targets = list(draw.targets[int(rng.integers(len(draw.targets)))])
    scene = {"name": f"{name}_s{index + 1}", "targets": targets,
             "distance_mm": float(np.round(rng.uniform(*draw.distance_mm))),
             "elevation_deg": float(np.round(2 * rng.uniform(*draw.elevation_deg)) / 2),
             "n_clutter": int(rng.integers(draw.n_clutter[0], draw.n_clutter[1] + 1))}
    if any(target.startswith("scapula") for target in targets):
        scene["glenoid_tilt_deg"] = [float(np.round(rng.uniform(*draw.glenoid_tilt_deg))) for _ in range(2)]
    return scene


def world_generate(population: PopulationParams, name: str) -> dict:
    """The ``generate`` keys world ``name`` replaces (module docstring), every scene at its first draw."""
    draw, rng = population.draw, keyed_rng(population.seed, name, "world")
    seed = int(rng.integers(0, 2**31))
    lights = {key: round(float(rng.uniform(*getattr(draw.lights, key))), 2)
              for key in ("ambient", "ring", "room", "background")}
    return {"seed": seed, "images_per_stop": draw.images_per_stop, "lights": lights,
            "scenes": [draw_scene(population, name, index) for index in range(draw.scenes_per_world)],
            "lines": None, "validation": None}


def served_world(params_path: str | Path, name: str) -> tuple[dict, list[str]]:
    """(world ``name``'s ``generate`` keys with every scene the robot cannot serve drawn again, one line per scene
    drawn again saying why); :class:`ArgumentError` when ``name`` is not one of ``population.worlds`` or a scene stays
    unserved after MAX_ATTEMPTS draws."""
    raw, base_dir = read_raw(params_path)
    params = parse_params(raw, str(params_path), base_dir)
    population = params.population
    if name not in population.worlds:
        raise ArgumentError(f"world {name!r} is not one of population.worlds {population.worlds} of {params_path}")
    generate, redrawn = world_generate(population, name), []
    for index in range(population.draw.scenes_per_world):
        for attempt in range(1, MAX_ATTEMPTS + 1):
            world = parse_params(merge(raw, {"generate": generate}), f"world {name} of {params_path}", base_dir)
            problem = arc_problem(world.generate, world.protocol, index)
            if problem is None:
                break
            scene = generate["scenes"][index]
            redrawn.append(f"{scene['name']} drawn again (draw {attempt + 1}): {scene['distance_mm']:g} mm, "
                           f"{scene['elevation_deg']:g} deg, {'+'.join(scene['targets'])}: {problem}")
            generate["scenes"][index] = draw_scene(population, name, index, attempt)
        else:
            raise ArgumentError(f"world {name}: scene {index + 1} not served by the robot in {MAX_ATTEMPTS} draws of "
                                f"population.draw (last: {redrawn[-1]}); widen or move its distance_mm / "
                                f"elevation_deg ranges")
    return generate, redrawn


def write_world(params_path: str | Path, name: str, out: str | Path) -> Path:
    """World ``name`` of ``params_path``'s population (:func:`served_world`) written to ``out`` (an overlay on
    ``params_path``), checked by reading it back as the stages will (:class:`~poseintegrity.config.ParamsError`
    naming the key if a drawn value is refused); returns ``out``. Written atomically."""
    generate, redrawn = served_world(params_path, name)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    overlay = {"extends": os.path.relpath(Path(params_path).resolve(), out.parent.resolve()), "generate": generate}
    header = [f"World {name} of the population (issue 49), drawn by poseintegrity.population.draw from "
              f"{Path(params_path).name}'s population section: an overlay on it.",
              *(redrawn or ["Every scene at its first draw: the robot serves each."])]
    tmp = out.with_name(out.name + ".partial")
    tmp.write_text("".join(f"# {line}\n" for line in header)
                   + yaml.safe_dump(overlay, sort_keys=False, default_flow_style=None, width=120))
    try:
        load_params(tmp)
    except PoseIntegrityError:
        tmp.unlink()
        raise
    tmp.replace(out)
    return out
