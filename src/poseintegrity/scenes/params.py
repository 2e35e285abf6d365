"""Schema of the ``generate`` section of params.yaml (stage 01, Windsor et al. section IV-D)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import cv2
import numpy as np
from pydantic import Field, ValidationInfo, field_validator, model_validator

from poseintegrity.scenes.catalog import TARGET_NAMES, TEXTURE_NAMES
from poseintegrity.scenes.foam import ReliefVolume, relief_volume
from poseintegrity.scenes.mesh import Material
from poseintegrity.scenes.scapula import read_mesh
from poseintegrity.schema import KeyRule, ProjectPath, Section

PositiveInt = Annotated[int, Field(gt=0)]


class CameraParams(Section):
    """IDS U3-3060CP-M (Sony IMX174, mono) with a fixed-focal lens (docs/references.md, "Camera of the Windsor et al. experiments")."""

    sensor_width_px: PositiveInt = 1936
    sensor_height_px: PositiveInt = 1216
    pixel_um: float = Field(5.86, gt=0)
    lens_mm: float = Field(12.0, gt=0, description="focal length of the (unpublished) lens; ours")
    downscale: PositiveInt = Field(2, description="images are rendered at sensor size / downscale")
    f_number: float = Field(4.0, gt=0, description="aperture; sets the depth of field (focus at the model view)")


class SensorParams(Section):
    """Image formation after the optics: exposure, noise, blur, flicker (8-bit output)."""

    exposure: float = Field(215.0, gt=0, description="DN for a white Lambertian surface facing the ring light")
    read_noise_dn: float = Field(1.2, ge=0)
    shot_noise_dn_per_dn: float = Field(0.02, ge=0, description="variance of shot noise per DN of signal")
    blur_sigma_px: float = Field(0.6, ge=0, description="optical blur, Gaussian sigma in pixels")
    flicker: float = Field(0.006, ge=0, lt=0.5, description="std of the per-image illumination gain")


class LightParams(Section):
    """The lab's light: a ring light on the camera, a room light fixed to the scene, ambient light (radiances of a
    white surface facing each light); the background is the radiance seen past every object."""

    ambient: float = Field(ge=0)
    ring: float = Field(ge=0, description="on the lens: moves with the camera, lights what the camera sees")
    room: float = Field(ge=0, description="directional, fixed to the scene (direction drawn per scene)")
    background: float = Field(ge=0)

    def intensities(self) -> tuple[float, float, float, float]:
        return self.ambient, self.ring, self.room, self.background


class DrillParams(Section):
    """The prepared phantom's hole: "pre-drilled for implant placement", "oversized" (IV-B, Fig. 3)."""

    diameter_mm: float = Field(gt=0, le=20, description="hole diameter (a glenoid baseplate peg hole is 6-8 mm)")
    depth_mm: float = Field(gt=0, le=40, description="depth below the glenoid centre")


class ScapulaParams(Section):
    """The anatomical scapula phantom (:mod:`poseintegrity.scenes.scapula`)."""

    mesh: ProjectPath = Field(description="closed triangle mesh of a left scapula (STL, OBJ, PLY: anything trimesh reads)")
    length_mm: float = Field(gt=0, description="the mesh is scaled so that its longest extent is this long")
    glenoid_centre: tuple[float, float, float] = Field(description="glenoid centre in the mesh file's own units")
    glenoid_normal: tuple[float, float, float] = Field(description="outward normal of the glenoid, mesh frame")
    drill: DrillParams

    @field_validator("mesh")
    @classmethod
    def _closed_mesh(cls, path: Path) -> Path:
        read_mesh(path, "mesh")  # unreadable or not closed: a MeshError naming the file, before any work
        return path

    @field_validator("glenoid_normal")
    @classmethod
    def _nonzero(cls, normal: tuple[float, float, float]) -> tuple[float, float, float]:
        if not (all(math.isfinite(c) for c in normal) and math.hypot(*normal) > 1e-6):
            raise ValueError(f"glenoid_normal must be a finite, non-zero vector, got {normal}")
        return normal


class BoneFoamParams(Section):
    """The surface of the moulded bone-foam phantoms (:mod:`poseintegrity.scenes.foam`): physical sizes, the same
    for every phantom and offcut of the material."""

    pore_radius_mm: float = Field(gt=0, le=2, description="smallest pore radius r0; octaves add 2 r0 and 4 r0")
    pore_fraction: float = Field(gt=0, lt=1, description="share of the surface covered by pores (per octave)")
    pore_depth: float = Field(gt=0, le=3, description="pore depth / pore radius")
    bump_slope: float = Field(ge=0, le=2, description="RMS slope of the fine bumps between pores")
    albedo: float = Field(gt=0, le=1, description="mean albedo of the pale foam")
    albedo_std: float = Field(ge=0, lt=0.5, description="relative std of its albedo mottling")
    albedo_mottle_mm: float = Field(gt=0, description="size of the mottles")
    specular: float = Field(ge=0, le=1, description="Blinn-Phong k_s: a mild lobe")
    shininess: float = Field(gt=0, description="Blinn-Phong exponent")

    def material(self) -> "Material":
        return Material(specular=self.specular, shininess=self.shininess, foam_albedo=self.albedo)

    def relief(self, seed: int) -> "ReliefVolume":
        """The foam's height field, seeded by ``generate.seed`` (one material: the same for every object)."""
        return relief_volume(np.random.default_rng([seed, 7]), pore_radius_mm=self.pore_radius_mm,
                             pore_fraction=self.pore_fraction, pore_depth=self.pore_depth,
                             bump_slope=self.bump_slope, albedo_std=self.albedo_std,
                             albedo_mottle_mm=self.albedo_mottle_mm)


class SceneSpec(Section):
    """One physical arrangement on the table (Fig. 4)."""

    name: str = Field(min_length=1)
    targets: list[str] = Field(min_length=1)
    distance_mm: float = Field(320.0, gt=50, description="camera to target centre at the model view")
    elevation_deg: float = Field(50.0, gt=5, lt=90, description="of the model view above the table")
    n_clutter: int = Field(4, ge=0, le=20)
    glenoid_tilt_deg: tuple[float, float] = Field(
        (0.0, 0.0), description="a scapula's glenoid normal turned from the model camera about its x, then y axis")

    @field_validator("targets")
    @classmethod
    def _known_targets(cls, names: list[str]) -> list[str]:
        unknown = [n for n in names if n not in TARGET_NAMES]
        if unknown:
            raise ValueError(f"unknown target name(s) {unknown}; known: {sorted(TARGET_NAMES)}")
        if len(set(names)) != len(names):
            raise ValueError("a target appears twice")
        return names


class ArcParams(Section):
    """Viewing-angle datasets: arcs about the target (IV-D)."""

    azimuths_deg: list[float] = Field(default=[0.0, 90.0, 270.0], min_length=1)
    n_stops: PositiveInt = 20


class LineParams(Section):
    """Straight-line datasets: the camera moves along its -z axis (IV-D)."""

    scene: str = Field("scene_2", description="scene holding the drilled bone-like target")
    distance_mm: float = Field(220.0, gt=50, description="camera to target centre at the lines' own model pair")
    offsets_deg: list[float] = Field(default=[0.0, 5.0, 10.0, 15.0])
    n_stops: PositiveInt = 15

    @field_validator("offsets_deg")
    @classmethod
    def _offsets(cls, offsets: list[float]) -> list[float]:
        if any(not 0 <= o <= 90 for o in offsets):
            raise ValueError("offsets must lie in [0, 90] deg")
        return offsets


class GenerateParams(Section):
    """Stage 01: render the robot datasets."""

    seed: int = Field(20240501, ge=0)
    n_jobs: int = Field(2, ge=1)
    images_per_stop: PositiveInt = 10
    model_baseline_mm: float = Field(20.0, gt=0)
    camera: CameraParams = CameraParams()
    sensor: SensorParams = SensorParams()
    arcs: ArcParams = ArcParams()
    lines: LineParams | None = LineParams()
    lights: LightParams
    scapula: ScapulaParams
    bone_foam: BoneFoamParams
    scenes: list[SceneSpec] = Field(min_length=1)
    textures: dict[str, ProjectPath] = Field(
        default_factory=dict, description="texture name -> image file replacing the procedural texture"
    )

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
        protocol = (info.context or {}).get("protocol")  # a robot must move past the stops it samples (IV-A)
        for key, trajectory in (("arcs", self.arcs), ("lines", self.lines)):
            if protocol is not None and trajectory is not None and trajectory.n_stops <= protocol.stops_sampled(key[:-1]):
                raise KeyRule(f"{key}.n_stops", f"must exceed protocol.sampled_stops.{key[:-1]} "
                                                f"({protocol.stops_sampled(key[:-1])}), got {trajectory.n_stops}")
        return self
