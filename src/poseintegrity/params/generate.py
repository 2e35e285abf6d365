"""Schema of the ``generate`` section of params.yaml (stage 01, Windsor et al. section IV-D).

params.yaml is the only source of these values: no field has a default that could disagree with it (the one
optional key, a scene's ``glenoid_tilt_deg``, is required with a scapula target and refused without one). Every
number is bounded, so that a value that would crash a later step (an image of 0 pixels, a foam of billions of
pores) or silently give something else than asked (two azimuths writing the same dataset folder, a flicker that
turns some images black) is refused here, before any work, with its key named.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Literal

import cv2
from pydantic import Field, ValidationError, ValidationInfo, field_validator, model_validator

from poseintegrity.errors import ArgumentError
from poseintegrity.mesh_file import check_mesh
from poseintegrity.params.boards import GroundTruthBoardParams, PrintedBoardParams
from poseintegrity.params.camera import CalibrationParams, CameraParams, CaptureParams, SensorParams
from poseintegrity.params.robot import RobotParams
from poseintegrity.schema import FromList, KeyRule, ProjectPath, Section, Seed, distinct

NAME_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9_-]*$"  # scene names make folder names (no path, no hidden .partial folder)

TARGET_NAMES = ("scapula", "scapula_drilled", "block_print", "block_mosaic")  # the targets scenes/catalog.py builds
VOXEL_MM = 0.125  # the voxel of the foam's relief volume (scenes/foam.py): the smallest pore radius it resolves
TEXTURE_NAMES = ("block_print", "block_mosaic", "table", "clutter_a", "clutter_b", "clutter_c", "clutter_print")


class LightParams(Section):
    """The lab's light: a ring light on the camera, a room light fixed to the scene, ambient light (radiances of a
    white surface facing each light); the background is the radiance seen past every object."""

    ambient: float = Field(ge=0, le=5)
    ring: float = Field(ge=0, le=5, description="on the lens: moves with the camera, lights what the camera sees")
    room: float = Field(ge=0, le=5, description="directional, fixed to the scene (direction drawn per scene)")
    background: float = Field(ge=0, le=5)

    @model_validator(mode="after")
    def _some_light(self) -> "LightParams":
        if self.ambient + self.ring + self.room <= 0:
            raise ValueError("ambient, ring and room are all 0: every object would be black")
        return self

    def intensities(self) -> tuple[float, float, float, float]:
        return self.ambient, self.ring, self.room, self.background


class DrillParams(Section):
    """The prepared phantom's hole: "pre-drilled for implant placement", "oversized" (IV-B, Fig. 3)."""

    diameter_mm: float = Field(gt=0, le=20, description="hole diameter (a glenoid baseplate peg hole is 6-8 mm)")
    depth_mm: float = Field(gt=0, le=40, description="depth below the glenoid centre")


MeshCoordinate = Annotated[float, Field(ge=-1e6, le=1e6)]  # mesh units (m to um): a 170 mm bone in um spans 1.7e5
UnitComponent = Annotated[float, Field(ge=-1, le=1)]  # a direction's component


class ScapulaParams(Section):
    """The anatomical scapula phantom (:mod:`poseintegrity.scenes.scapula`)."""

    mesh: ProjectPath = Field(description="closed triangle mesh of a left scapula (STL, OBJ, PLY: anything trimesh reads)")
    length_mm: float = Field(ge=50, le=400, description="the mesh is scaled so that its longest extent is this long")
    glenoid_centre: Annotated[tuple[MeshCoordinate, MeshCoordinate, MeshCoordinate], FromList] = Field(
        description="glenoid centre in the mesh file's own units")
    glenoid_normal: Annotated[tuple[UnitComponent, UnitComponent, UnitComponent], FromList] = Field(
        description="outward normal of the glenoid, mesh frame (normalised: any direction can be written with "
                    "components in [-1, 1])")
    drill: DrillParams

    @field_validator("mesh")
    @classmethod
    def _closed_mesh(cls, path: Path) -> Path:
        check_mesh(path, "mesh")  # unreadable or not closed: a MeshError naming the file, before any work
        return path

    @field_validator("glenoid_normal")
    @classmethod
    def _nonzero(cls, normal: tuple[float, float, float]) -> tuple[float, float, float]:
        if not math.hypot(*normal) > 1e-6:
            raise ValueError(f"glenoid_normal must be a non-zero vector, got {normal}")
        return normal


class BoneFoamParams(Section):
    """The surface of the moulded bone-foam phantoms (:mod:`poseintegrity.scenes.foam`): physical sizes, the same
    for every phantom and offcut of the material."""

    pore_radius_mm: float = Field(ge=VOXEL_MM, le=2, description="smallest pore radius r0 (at least one voxel of "
                                                                 "the relief volume); octaves add 2 r0 and 4 r0")
    pore_fraction: float = Field(gt=0, lt=1, description="share of the surface covered by pores (per octave)")
    pore_depth: float = Field(gt=0, le=3, description="pore depth / pore radius")
    bump_slope: float = Field(ge=0, le=2, description="RMS slope of the fine bumps between pores")
    albedo: float = Field(gt=0, le=1, description="mean albedo of the pale foam")
    albedo_std: float = Field(ge=0, lt=0.5, description="relative std of its albedo mottling")
    albedo_mottle_mm: float = Field(gt=0, le=50, description="size of the mottles")
    specular: float = Field(ge=0, le=1, description="Blinn-Phong k_s: a mild lobe")
    shininess: float = Field(gt=0, le=1000, description="Blinn-Phong exponent")


Distance = Annotated[float, Field(ge=100, le=2000)]  # camera to target centre, mm


class SceneSpec(Section):
    """One physical arrangement on the table (Fig. 4)."""

    name: str = Field(pattern=NAME_PATTERN, max_length=64, description="names its dataset folders")
    targets: list[str] = Field(min_length=1)
    distance_mm: Distance = Field(description="camera to target centre at the model view")
    elevation_deg: float = Field(gt=5, lt=90, description="of the model view above the table")
    n_clutter: int = Field(ge=0, le=20)
    glenoid_tilt_deg: Annotated[tuple[Annotated[float, Field(ge=-45, le=45)], Annotated[float, Field(ge=-45, le=45)]],
                                FromList] | None = (
        Field(None, description="a scapula's glenoid normal turned from the model camera about its x, then y axis; "
                                "required with a scapula target, refused without one"))

    @field_validator("targets")
    @classmethod
    def _known_targets(cls, names: list[str]) -> list[str]:
        unknown = [n for n in names if n not in TARGET_NAMES]
        if unknown:
            raise ValueError(f"unknown target name(s) {unknown}; known: {sorted(TARGET_NAMES)}")
        if len(set(names)) != len(names):
            raise ValueError("a target appears twice")
        return names

    @model_validator(mode="after")
    def _tilt_of_a_scapula(self) -> "SceneSpec":
        scapula = any(name.startswith("scapula") for name in self.targets)
        if scapula and self.glenoid_tilt_deg is None:
            raise KeyRule("glenoid_tilt_deg", f"required with a scapula target ({self.targets}): how the glenoid "
                                              "is turned from the model camera, [about x, about y] deg")
        if not scapula and self.glenoid_tilt_deg is not None:
            raise KeyRule("glenoid_tilt_deg", f"only a scapula has a glenoid to tilt; targets {self.targets}")
        return self


Stops = Annotated[int, Field(ge=1, le=100)]


class ArcParams(Section):
    """Viewing-angle datasets: arcs about the target (IV-D)."""

    azimuths_deg: distinct(Annotated[float, Field(ge=0, lt=360)]) = Field(min_length=1)
    n_stops: Stops

    def dataset_ids(self, scene: str) -> list[str]:
        """The datasets of a scene's arcs, one per azimuth (the id names its folder)."""
        return [f"{scene}_arc{azimuth:03.0f}" for azimuth in self.azimuths_deg]


class LineParams(Section):
    """Straight-line datasets: the camera moves along its -z axis (IV-D)."""

    scene: str = Field(description="scene holding the drilled bone-like target")
    distance_mm: Distance = Field(description="camera to target centre at the lines' own model pair")
    offsets_deg: distinct(Annotated[float, Field(ge=0, le=90)]) = Field(min_length=1)
    n_stops: Stops
    focus: Literal["model_view", "range"] = Field(
        description="where the lab focuses the lens for the lines' session: model_view, at distance_mm (the far stops, "
        "up to 140 mm beyond, are then blurred by sigma 2.9 px at f/4 and 220 mm, and no board beside the target is "
        "read there); range, at the distance that blurs the near and the far end of the lines alike (focus_mm)")

    def dataset_ids(self) -> list[str]:
        """The datasets of the lines, one per start offset (the id names its folder)."""
        return [f"{self.scene}_line{offset:02.0f}" for offset in self.offsets_deg]

    def focus_mm(self, line_length_mm: float) -> float:
        """Where the lens is focused for the lines (``focus``): at their model view, or for the range they image, the
        target from distance_mm (model pair, first stop) to d_far = distance_mm + the last stop's x (the 0-deg line;
        the offset lines end nearer). The thin lens' circle of confusion grows as |d - d_f| / d
        (:func:`~poseintegrity.scenes.optics.defocus_sigma_px`), equal at both ends when
        d_f = 2 d_near d_far / (d_near + d_far), the harmonic mean (the usual depth-of-field split of a near and a far
        limit). At f/4 with the 12 mm lens and lines from 220 to 360 mm: 273 mm, and the target blurred by sigma
        1.4 px at both ends (model_view: 0 px near, 2.9 px far)."""
        if self.focus == "model_view":
            return float(self.distance_mm)
        near, far = float(self.distance_mm), self.distance_mm + line_length_mm * (self.n_stops - 1) / self.n_stops
        return 2 * near * far / (near + far)


WORLDS = ("main", "validation")  # the main world, calibrated to the paper; a second one nothing was tuned on


class ValidationWorld(Section):
    """A second world for the generalisation check (issue: "a headline that survives a world nobody tuned on"):
    its own seed (so its own textures, foam relief, layouts, room-light directions, robot, calibration session and
    sensor noise), its own scenes (targets, distances, elevations, clutter), straight lines and lighting, and fewer
    images per stop; camera, sensor, robot model, materials and protocol are the main world's. Its scene names must
    differ from the main world's (they name the dataset folders of both)."""

    seed: Seed
    images_per_stop: int = Field(ge=1, le=100)
    lights: LightParams
    scenes: list[SceneSpec] = Field(min_length=1)
    lines: LineParams | None = Field(description="null: no straight-line datasets in this world")


class GenerateParams(Section):
    """Stage 01: render the robot datasets of the main world and, if given, of the validation world."""

    source: Literal["rendered"] | ProjectPath = Field(
        description="rendered: render the datasets of this section; a folder: materialize the recorded dataset "
                    "folders in it instead (poseintegrity.recorded, docs/recorded-data.md)")
    seed: Seed
    images_per_stop: int = Field(ge=1, le=100)
    model_baseline_mm: float = Field(gt=0, le=100)
    camera: CameraParams
    sensor: SensorParams
    calibration: CalibrationParams
    printed_boards: PrintedBoardParams
    board: GroundTruthBoardParams
    capture: CaptureParams
    robot: RobotParams
    arcs: ArcParams
    lines: LineParams | None = Field(description="null: no straight-line datasets")
    lights: LightParams
    scapula: ScapulaParams
    bone_foam: BoneFoamParams
    scenes: list[SceneSpec] = Field(min_length=1)
    textures: dict[str, ProjectPath] = Field(description="texture name -> image file replacing the procedural texture")
    validation: ValidationWorld | None = Field(description="the second world; null: the main world only")

    @field_validator("source")
    @classmethod
    def _recorded_folder(cls, source: str | Path) -> str | Path:
        if source != "rendered" and not Path(source).is_dir():
            raise ValueError(f"{str(source)!r} is neither 'rendered' nor a folder (of recorded dataset folders)")
        return source

    @field_validator("textures")
    @classmethod
    def _readable_textures(cls, textures: dict[str, Path]) -> dict[str, Path]:
        for name, path in textures.items():
            if name not in TEXTURE_NAMES:
                raise ValueError(f"unknown texture name {name!r}; known: {sorted(TEXTURE_NAMES)}")
            if cv2.imread(str(path), cv2.IMREAD_GRAYSCALE) is None:
                raise ValueError(f"texture file {str(path)!r} for {name!r} cannot be read as an image")
        return textures

    @model_validator(mode="after")
    def _line_scene_exists(self, info: ValidationInfo) -> "GenerateParams":
        names = [s.name for s in self.scenes]
        if len(set(names)) != len(names):
            raise KeyRule("scenes", f"scene names must be unique, got {names}")
        if self.lines is not None and self.lines.scene not in names:
            raise KeyRule("lines.scene", f"{self.lines.scene!r} is not one of the scenes {names}")
        self._distinct_dataset_ids()
        protocol = (info.context or {}).get("protocol")  # a robot must move past the stops it samples (IV-A)
        for key, trajectory in (("arcs", self.arcs), ("lines", self.lines)):
            if protocol is not None and trajectory is not None and trajectory.n_stops <= protocol.stops_sampled(key[:-1]):
                raise KeyRule(f"{key}.n_stops", f"must exceed protocol.sampled_stops.{key[:-1]} "
                                                f"({protocol.stops_sampled(key[:-1])}), got {trajectory.n_stops}")
        return self

    def _distinct_dataset_ids(self) -> None:
        """Each dataset writes the folder its id names: two equal ids would overwrite one folder and list it
        twice in the index (azimuths 0 and 0.4 both name ``*_arc000``)."""
        for key, ids in (("arcs.azimuths_deg", self.arcs.dataset_ids(self.scenes[0].name)),
                         ("lines.offsets_deg", [] if self.lines is None else self.lines.dataset_ids())):
            repeated = sorted({i for i in ids if ids.count(i) > 1})
            if repeated:
                raise KeyRule(key, f"two entries name the same dataset {', '.join(repeated)} (ids round to "
                                   f"whole degrees): make them differ by at least 1 deg")
        ids = self.dataset_ids()
        repeated = sorted({i for i in ids if ids.count(i) > 1})
        if repeated:
            raise KeyRule("scenes", f"scene names give datasets of the same id: {', '.join(repeated)}")

    @model_validator(mode="after")
    def _robot_error_below_stop_spacing(self, info: ValidationInfo) -> "GenerateParams":
        """The robot's expected pose error (:meth:`RobotParams.error_budget`, RMS) must stay below the spacing of
        the stops (IV-D: 2.25 deg along the arcs, 10 mm along the lines), or a stop's recorded theta or x would be
        the robot's error rather than the protocol's step. Names the key that adds the most."""
        protocol = (info.context or {}).get("protocol")
        if protocol is None:
            return self
        orientation, position = self.robot.error_budget()
        checks = [(orientation, "orientation", "deg", protocol.arc_span_deg / self.arcs.n_stops,
                   "protocol.arc_span_deg / arcs.n_stops")]
        if self.lines is not None:
            checks.append((position, "position", "mm", protocol.line_length_mm / self.lines.n_stops,
                           "protocol.line_length_mm / lines.n_stops"))
        for budget, kind, unit, spacing, spacing_keys in checks:
            rms = math.sqrt(sum(budget.values()))
            if rms >= spacing:
                largest = max(budget, key=budget.get)
                raise KeyRule(f"robot.{largest}", f"the robot's expected {kind} error of a stop, {rms:.3g} {unit} "
                                                  f"(first order, mostly from this key), is not below the stops' "
                                                  f"spacing {spacing:.3g} {unit} ({spacing_keys})")
        return self

    @model_validator(mode="after")
    def _validation_world(self, info: ValidationInfo) -> "GenerateParams":
        """The validation world must itself be valid (scene names, the lines' scene, stops), and name datasets the
        main world does not."""
        if self.validation is None:
            return self
        try:
            other = self.world("validation", info.context)
        except ValidationError as error:
            item = error.errors()[0]
            rule = item.get("ctx", {}).get("error")
            key = ".".join(map(str, (*item["loc"], *(rule.key.split(".") if isinstance(rule, KeyRule) else ()))))
            raise KeyRule(f"validation.{key}", str(rule) if rule is not None else item["msg"]) from None
        shared = sorted(set(self.dataset_ids()) & set(other.dataset_ids()))
        if shared:
            raise KeyRule("validation.scenes", f"the validation world names datasets the main world has too: "
                                               f"{', '.join(shared[:4])}; give its scenes other names")
        return self

    def world(self, name: str, context: dict | None = None) -> "GenerateParams":
        """The params of one world (:data:`WORLDS`), without a validation world of its own: "main" is these params,
        "validation" these with ``validation``'s keys in place of the main world's."""
        if name not in WORLDS or (name == "validation" and self.validation is None):
            available = [w for w in WORLDS if w == "main" or self.validation is not None]
            raise ArgumentError(f"name: unknown world {name!r}; these params have {available}")
        if name == "main":
            return self.model_copy(update={"validation": None})
        fields = self.model_dump() | self.validation.model_dump() | {"validation": None}
        return GenerateParams.model_validate(fields, context=context)

    def worlds(self) -> dict[str, "GenerateParams"]:
        """Every world's params, the main world first."""
        return {name: self.world(name) for name in WORLDS if name == "main" or self.validation is not None}

    def dataset_ids(self) -> list[str]:
        """Every dataset, in the order of scenes/trips.py plan_datasets: each scene's arcs, then the lines."""
        return ([i for spec in self.scenes for i in self.arcs.dataset_ids(spec.name)]
                + ([] if self.lines is None else self.lines.dataset_ids()))
