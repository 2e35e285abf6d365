"""Schema of the ``generate`` section of params.yaml (stage 01, Windsor et al. section IV-D)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import cv2
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from poseintegrity.scenes.catalog import TARGET_NAMES, TEXTURE_NAMES

_frozen = ConfigDict(extra="forbid", frozen=True)
PositiveInt = Annotated[int, Field(gt=0)]


class CameraParams(BaseModel):
    """IDS U3-3060CP-M (Sony IMX174, mono) with a fixed-focal lens (FACTS.md)."""

    model_config = _frozen
    sensor_width_px: PositiveInt = 1936
    sensor_height_px: PositiveInt = 1216
    pixel_um: float = Field(5.86, gt=0)
    lens_mm: float = Field(12.0, gt=0, description="focal length of the (unpublished) lens; ours")
    downscale: PositiveInt = Field(2, description="images are rendered at sensor size / downscale")
    f_number: float = Field(4.0, gt=0, description="aperture; sets the depth of field (focus at the model view)")


class SensorParams(BaseModel):
    """Image formation after the optics: exposure, noise, blur, flicker (8-bit output)."""

    model_config = _frozen
    exposure: float = Field(215.0, gt=0, description="DN for a white Lambertian surface facing the ring light")
    read_noise_dn: float = Field(1.2, ge=0)
    shot_noise_dn_per_dn: float = Field(0.02, ge=0, description="variance of shot noise per DN of signal")
    blur_sigma_px: float = Field(0.6, ge=0, description="optical blur, Gaussian sigma in pixels")
    flicker: float = Field(0.006, ge=0, lt=0.5, description="std of the per-image illumination gain")


class SceneSpec(BaseModel):
    """One physical arrangement on the table (Fig. 4)."""

    model_config = _frozen
    name: str = Field(min_length=1)
    targets: list[str] = Field(min_length=1)
    distance_mm: float = Field(320.0, gt=50, description="camera to target centre at the model view")
    elevation_deg: float = Field(50.0, gt=5, lt=90, description="of the model view above the table")
    n_clutter: int = Field(4, ge=0, le=20)

    @field_validator("targets")
    @classmethod
    def _known_targets(cls, names: list[str]) -> list[str]:
        unknown = [n for n in names if n not in TARGET_NAMES]
        if unknown:
            raise ValueError(f"unknown target name(s) {unknown}; known: {sorted(TARGET_NAMES)}")
        if len(set(names)) != len(names):
            raise ValueError("a target appears twice")
        return names


class ArcParams(BaseModel):
    """Viewing-angle datasets: arcs about the target (IV-D)."""

    model_config = _frozen
    azimuths_deg: list[float] = Field(default=[0.0, 90.0, 270.0], min_length=1)
    span_deg: float = Field(45.0, gt=0, le=90, description="arc length; stops at span/n_stops * (1..n_stops)")
    n_stops: PositiveInt = 20


class LineParams(BaseModel):
    """Straight-line datasets: the camera moves along its -z axis (IV-D)."""

    model_config = _frozen
    scene: str = Field("scene_2", description="scene holding the drilled bone-like target")
    distance_mm: float = Field(220.0, gt=50, description="camera to target centre at the lines' own model pair")
    offsets_deg: list[float] = Field(default=[0.0, 5.0, 10.0, 15.0])
    n_stops: PositiveInt = 15
    step_mm: float = Field(10.0, gt=0)

    @field_validator("offsets_deg")
    @classmethod
    def _offsets(cls, offsets: list[float]) -> list[float]:
        if any(not 0 <= o <= 90 for o in offsets):
            raise ValueError("offsets must lie in [0, 90] deg")
        return offsets


class GenerateParams(BaseModel):
    """Stage 01: render the robot datasets."""

    model_config = _frozen
    seed: int = Field(20240501, ge=0)
    n_jobs: int = Field(2, ge=1)
    images_per_stop: PositiveInt = 10
    model_baseline_mm: float = Field(20.0, gt=0)
    camera: CameraParams = CameraParams()
    sensor: SensorParams = SensorParams()
    arcs: ArcParams = ArcParams()
    lines: LineParams | None = LineParams()
    scenes: list[SceneSpec] = Field(min_length=1)
    textures: dict[str, Path] = Field(
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
    def _line_scene_exists(self) -> "GenerateParams":
        names = [s.name for s in self.scenes]
        if len(set(names)) != len(names):
            raise ValueError("scene names must be unique")
        if self.lines is not None and self.lines.scene not in names:
            raise ValueError(f"lines.scene {self.lines.scene!r} is not one of the scenes {names}")
        return self
