"""Schema of the ``population`` section of ``params.yaml``: the declared distribution of rendered worlds the
predictors are judged on (ours, issue 49; ``population/dvc.yaml``, ``make population``).

Each world is a whole rendered world as ``generate`` describes one (the camera, sensor, boards, robot model, materials
and protocol are ``generate``'s), with its own seed (so its own textures, foam relief, layouts, robot, calibration
session and sensor noise) and scenes, lights and images per stop drawn from the ranges here
(:mod:`poseintegrity.population.draw`). The ranges contain the main and the validation worlds' values, so that those
two are members of the population, not outliers of it. Lengths in mm, angles in degrees.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field, model_validator

from poseintegrity.params.generate import NAME_PATTERN, TARGET_NAMES
from poseintegrity.schema import FromList, KeyRule, Seed, Section, distinct, ordered_range

WorldName = Annotated[str, Field(pattern=NAME_PATTERN, max_length=16)]
Share = ordered_range(ge=0, le=1)  # a light's intensity range (a white surface facing everything: ~1.2 in all)


class LightRanges(Section):
    """The ranges of ``generate.lights`` (each drawn uniformly and independently)."""

    ambient: Share
    ring: Share
    room: Share
    background: Share


class WorldDraw(Section):
    """How one world is drawn: uniform within each range, one target combination of ``targets`` per scene."""

    scenes_per_world: int = Field(ge=2, le=20, description="scenes per world (paper: 7); each has its three arcs")
    images_per_stop: int = Field(ge=1, le=100, description="images per stop (the validation world's 3)")
    distance_mm: ordered_range(ge=100, le=2000) = Field(description="camera to target centre at the model view")
    elevation_deg: ordered_range(gt=5, lt=90) = Field(description="of the model view above the table")
    n_clutter: Annotated[tuple[Annotated[int, Field(ge=0, le=20)], Annotated[int, Field(ge=0, le=20)]], FromList] = (
        Field(description="[fewest, most] clutter objects per scene"))
    glenoid_tilt_deg: ordered_range(ge=-45, le=45) = Field(description="each of a scapula's two glenoid tilts")
    targets: distinct(Annotated[tuple[str, ...], FromList]) = Field(
        min_length=1, description="the target combinations a scene draws from")
    lights: LightRanges

    @model_validator(mode="after")
    def _check(self) -> WorldDraw:
        if self.n_clutter[0] > self.n_clutter[1]:
            raise KeyRule("n_clutter", f"a range [fewest, most] needs fewest <= most, got {list(self.n_clutter)}")
        for index, combination in enumerate(self.targets):
            unknown = [name for name in combination if name not in TARGET_NAMES]
            if not combination or unknown or len(set(combination)) != len(combination):
                raise KeyRule(f"targets.{index}", f"must be distinct target names of {list(TARGET_NAMES)}, got "
                                                  f"{list(combination)}")
        return self


class TransferParams(Section):
    """How an operating point is chosen on several worlds and applied to another (leave one world out)."""

    zero_incursion_worlds: float = Field(
        gt=0, le=1, description="the share of the other worlds in which the chosen point must have zero incursion; "
        "among those points, the one of largest mean SPL over them (population/judge.py says why)")


class HazardTrainingParams(Section):
    """Ours (issue 50): how the failure hazard is trained on the worlds (population/hazard.py)."""

    C: float = Field(gt=0, le=1e6, description="inverse L2 strength of the logistic regression (scikit-learn's C)")
    calibration_folds: int = Field(ge=2, le=100, description="folds by world whose held-out log odds calibrate it")
    importance_repeats: int = Field(ge=1, le=1000, description="shuffles per column of the permutation importance")
    seed: Seed = Field(description="seed of the permutation importance's shuffles")


class PopulationParams(Section):
    """A population of rendered worlds (issue 49): which worlds, how each is drawn, how points transfer."""

    seed: Seed = Field(description="world <name> draws from keyed_rng(seed, name): adding a world changes no other")
    worlds: distinct(WorldName) = Field(min_length=2, description="the worlds' names; each a DVC stage of its own")
    draw: WorldDraw
    transfer: TransferParams
    hazard: HazardTrainingParams
