"""A world of the population drawn from the declared distribution (``population.draw``, issue 49).

World ``<name>`` draws from its own generator, ``keyed_rng(population.seed, name)``: its ``generate.seed`` (which
draws its textures, foam relief, scene layouts, robot, calibration session and sensor noise in stage 01), its lights
and, per scene, the distance and elevation of the model view, the clutter, the target combination and a scapula's
glenoid tilts, each uniform within its range. Adding a world or reordering ``population.worlds`` changes no other
world. Values are rounded as a lab would set them (1 mm, 0.5 deg, 1 deg of tilt, 0.01 of a light).

The world's params file is an overlay on the project's params (``extends``), replacing only ``generate``'s seed,
images per stop, lights and scenes, with no lines and no validation world: every other setting (camera, sensor,
boards, robot model, materials, protocol, extract, fit, predict) is the main world's.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import yaml

from poseintegrity.config import load_params
from poseintegrity.errors import ArgumentError, PoseIntegrityError
from poseintegrity.params.population import PopulationParams
from poseintegrity.seeding import keyed_rng


def world_generate(population: PopulationParams, name: str) -> dict:
    """The ``generate`` keys world ``name`` replaces (module docstring), as plain YAML values."""
    draw, rng = population.draw, keyed_rng(population.seed, name)
    seed = int(rng.integers(0, 2**31))
    lights = {key: round(float(rng.uniform(*getattr(draw.lights, key))), 2)
              for key in ("ambient", "ring", "room", "background")}
    scenes = []
    for index in range(draw.scenes_per_world):
        targets = list(draw.targets[int(rng.integers(len(draw.targets)))])
        scene = {"name": f"{name}_s{index + 1}", "targets": targets,
                 "distance_mm": float(np.round(rng.uniform(*draw.distance_mm))),
                 "elevation_deg": float(np.round(2 * rng.uniform(*draw.elevation_deg)) / 2),
                 "n_clutter": int(rng.integers(draw.n_clutter[0], draw.n_clutter[1] + 1))}
        tilt = [float(np.round(rng.uniform(*draw.glenoid_tilt_deg))) for _ in range(2)]  # drawn for every scene,
        if any(target.startswith("scapula") for target in targets):  # so that each scene's draws stay in step
            scene["glenoid_tilt_deg"] = tilt
        scenes.append(scene)
    return {"seed": seed, "images_per_stop": draw.images_per_stop, "lights": lights, "scenes": scenes,
            "lines": None, "validation": None}


def write_world(params_path: str | Path, name: str, out: str | Path) -> Path:
    """World ``name`` of ``params_path``'s population written to ``out`` (an overlay on ``params_path``), checked by
    reading it back as the stages will (:class:`~poseintegrity.config.ParamsError` naming the key if a drawn value is
    refused); returns ``out``. ``name`` must be one of ``population.worlds``."""
    params = load_params(params_path)
    if name not in params.population.worlds:
        raise ArgumentError(f"world {name!r} is not one of population.worlds {params.population.worlds} of "
                            f"{params_path}")
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    overlay = {"extends": os.path.relpath(Path(params_path).resolve(), out.parent.resolve()),
               "generate": world_generate(params.population, name)}
    header = (f"# World {name} of the population (issue 49), drawn by poseintegrity.population.draw from "
              f"{Path(params_path).name}'s population section: an overlay on it.\n")
    tmp = out.with_name(out.name + ".partial")
    tmp.write_text(header + yaml.safe_dump(overlay, sort_keys=False, default_flow_style=None, width=120))
    try:
        load_params(tmp)
    except PoseIntegrityError:
        tmp.unlink()
        raise
    tmp.replace(out)
    return out
