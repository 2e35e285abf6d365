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
from typing import Annotated

import cv2
import numpy as np
from pydantic import Field, ValidationError, ValidationInfo, field_validator, model_validator

from poseintegrity.scenes.catalog import TARGET_NAMES, TEXTURE_NAMES
from poseintegrity.scenes.foam import VOXEL_MM, ReliefVolume, relief_volume
from poseintegrity.scenes.kinematics import UR5E
from poseintegrity.scenes.mesh import Material
from poseintegrity.scenes.scapula import read_mesh
from poseintegrity.lens import LensError, check_folding
from poseintegrity.schema import KeyRule, OrderedRange, ProjectPath, Section, Seed, distinct

MIN_IMAGE_PX = 64  # the rendered image's shorter side: below it no target keeps enough pixels to be localized
MAX_SENSOR_PX = 4096  # a side of the sensor: larger frames take GBs of z-buffer per worker
NAME_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9_-]*$"  # scene names make folder names (no path, no hidden .partial folder)


Radial = Annotated[float, Field(ge=-2, le=2)]  # k_i beyond +-2 describe a fisheye, which plumb_bob does not model
Tangential = Annotated[float, Field(ge=-0.05, le=0.05)]  # a lens decentred enough for p_i = 0.05 is broken


class CameraParams(Section):
    """IDS U3-3060CP-M (Sony IMX174, mono) with a fixed-focal lens (docs/references.md, "Camera of the Windsor et al. experiments")."""

    sensor_width_px: int = Field(gt=0, le=MAX_SENSOR_PX)
    sensor_height_px: int = Field(gt=0, le=MAX_SENSOR_PX)
    pixel_um: float = Field(gt=0, le=50)
    lens_mm: float = Field(gt=0, le=75, description="focal length of the (unpublished) lens; ours. Below every "
                                                    "camera distance (>= 100 mm): the lens must focus")
    downscale: int = Field(ge=1, description="images are rendered at sensor size / downscale")
    f_number: float = Field(ge=0.5, le=64, description="aperture; sets the depth of field (focus at the model view)")
    principal_point_offset_px: tuple[Annotated[float, Field(ge=-100, le=100)], Annotated[float, Field(ge=-100, le=100)]] = (
        Field(description="where the optical axis meets the sensor, from its centre, full-resolution px (a lens is "
                          "mounted a few px off; 100 px would be a visibly decentred lens)"))
    distortion: tuple[Radial, Radial, Tangential, Tangential, Radial] = Field(
        description="k1, k2, p1, p2, k3 of the lens (Brown-Conrady as OpenCV models it, poseintegrity.lens)")

    @model_validator(mode="after")
    def _image_size(self) -> "CameraParams":
        shorter = min(self.sensor_width_px, self.sensor_height_px) // self.downscale
        if shorter < MIN_IMAGE_PX:
            raise KeyRule("downscale", f"the image's shorter side would be {shorter} px "
                                       f"({self.sensor_width_px} x {self.sensor_height_px} / {self.downscale}); "
                                       f"at most {min(self.sensor_width_px, self.sensor_height_px) // MIN_IMAGE_PX} "
                                       f"keeps it >= {MIN_IMAGE_PX} px")
        return self

    @model_validator(mode="after")
    def _lens_does_not_fold(self) -> "CameraParams":
        from poseintegrity.scenes.camera import Intrinsics  # camera.py imports this module for type hints only

        cam = Intrinsics.from_params(self)
        try:
            check_folding(cam.K, np.array(self.distortion), cam.width, cam.height)
        except LensError as error:
            raise KeyRule("distortion", str(error)) from None
        return self


class SensorParams(Section):
    """Image formation after the optics: exposure, noise, blur, flicker (8-bit output)."""

    exposure: float = Field(gt=0, le=1000, description="DN for a white Lambertian surface facing the ring light "
                                                       "(255 saturates; 1000 is white everywhere)")
    read_noise_dn: float = Field(ge=0, le=50)
    shot_noise_dn_per_dn: float = Field(ge=0, le=10, description="variance of shot noise per DN of signal")
    blur_sigma_px: float = Field(ge=0, le=20, description="optical blur, Gaussian sigma in pixels")
    flicker: float = Field(ge=0, le=0.1, description="std of the per-image illumination gain (above 0.1 a gain "
                                                     "1 + flicker x N(0, 1) would sometimes be <= 0: a black image)")


class PrintedBoardParams(Section):
    """Printed boards are not their drawings (both the calibration ChArUco and the scenes' ArUco ground-truth board):
    a printer scales each axis a little, and a sheet is not flat. Drawn once per board and world; every stage that
    uses a board assumes its drawing, as a lab does."""

    scale_std: float = Field(ge=0, le=0.01, description="per axis: laser printers scale by ~0.1-0.3 %; 1 % would be "
                                                        "seen with a ruler")
    calibration_sag_std_mm: float = Field(ge=0, le=5, description="bow of the ChArUco card at its centre")
    board_sag_std_mm: float = Field(ge=0, le=5, description="bow of the ground-truth board glued on its pedestal")


class CharucoParams(Section):
    """The calibration board: a ChArUco board (cv2.aruco.CharucoBoard) printed on paper."""

    squares_x: int = Field(ge=3, le=40)
    squares_y: int = Field(ge=3, le=40)
    square_mm: float = Field(gt=0, le=200)
    marker_mm: float = Field(gt=0, le=200, description="the ArUco marker inside each white square")
    dictionary: str = Field(pattern=r"^DICT_\w+$", description="an OpenCV ArUco dictionary, e.g. DICT_5X5_100")

    @field_validator("dictionary")
    @classmethod
    def _known(cls, name: str) -> str:
        if not isinstance(getattr(cv2.aruco, name, None), int):
            raise ValueError(f"OpenCV has no ArUco dictionary {name!r}")
        return name

    @model_validator(mode="after")
    def _marker_inside(self) -> "CharucoParams":
        if self.marker_mm >= self.square_mm:
            raise KeyRule("marker_mm", f"a marker lies inside its square: must be < square_mm ({self.square_mm:g}), "
                                       f"got {self.marker_mm:g}")
        n_markers = (self.squares_x * self.squares_y) // 2
        size = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary)).bytesList.shape[0]
        if n_markers > size:
            raise KeyRule("dictionary", f"{self.squares_x} x {self.squares_y} squares hold {n_markers} markers, "
                                        f"{self.dictionary} has {size}")
        return self


class CalibrationParams(Section):
    """The camera's calibration session before any data (:mod:`.calibration_views`): the board shown in ``n_views``
    poses; the estimate is what the pipeline uses as the camera."""

    board: CharucoParams
    n_views: int = Field(ge=5, le=200, description="views rendered (5: the fewest a calibration can use)")
    distance_mm: OrderedRange = Field(description="camera to board centre, drawn per view")
    max_tilt_deg: float = Field(ge=0, le=70, description="board tilt from facing the camera, drawn per view")
    max_rms_px: float = Field(gt=0, le=5, description="a calibration whose reprojection RMS exceeds this stops "
                                                      "stage 01: its camera would not be worth using")

    @field_validator("distance_mm")
    @classmethod
    def _in_focus_range(cls, distance: tuple[float, float]) -> tuple[float, float]:
        if distance[0] < 100 or distance[1] > 2000:
            raise ValueError(f"distances lie in [100, 2000] mm (the lens focuses beyond 100 mm), got {list(distance)}")
        return distance


class CaptureParams(Section):
    """How the images of a stop are taken once the robot reports it has stopped (IV-D: "stopping every 2.25 deg to
    capture 10 images"): a burst of exposures while the arm rings down (:mod:`.ringdown`). Ours: the paper gives no
    timing."""

    delay_ms: float = Field(ge=0, le=5000, description="from the reported stop to the first exposure's start")
    interval_ms: float = Field(gt=0, le=5000, description="between exposure starts (the frame period of the burst)")
    exposure_ms: float = Field(gt=0, le=200, description="shutter time; with the ring light a few ms suffice")
    blur_step_px: float = Field(gt=0, le=5, description="motion blur: sub-exposures no further apart in the image than "
                                                        "this (1 sub-exposure when the image moves less)")

    @model_validator(mode="after")
    def _one_at_a_time(self) -> "CaptureParams":
        if self.exposure_ms > self.interval_ms:
            raise KeyRule("exposure_ms", f"a camera exposes one frame at a time: must be <= interval_ms "
                                         f"({self.interval_ms:g}), got {self.exposure_ms:g}")
        return self


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


class ScapulaParams(Section):
    """The anatomical scapula phantom (:mod:`poseintegrity.scenes.scapula`)."""

    mesh: ProjectPath = Field(description="closed triangle mesh of a left scapula (STL, OBJ, PLY: anything trimesh reads)")
    length_mm: float = Field(ge=50, le=400, description="the mesh is scaled so that its longest extent is this long")
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

    def material(self) -> "Material":
        return Material(specular=self.specular, shininess=self.shininess, foam_albedo=self.albedo)

    def relief(self, seed: int, **grid) -> "ReliefVolume":
        """The foam's height field, seeded by ``generate.seed`` (one material: the same for every object);
        ``grid``: ``n`` / ``voxel_mm`` of :func:`~.foam.relief_volume` (tests shrink it)."""
        return relief_volume(np.random.default_rng([seed, 7]), pore_radius_mm=self.pore_radius_mm,
                             pore_fraction=self.pore_fraction, pore_depth=self.pore_depth,
                             bump_slope=self.bump_slope, albedo_std=self.albedo_std,
                             albedo_mottle_mm=self.albedo_mottle_mm, **grid)


Distance = Annotated[float, Field(ge=100, le=2000)]  # camera to target centre, mm


class SceneSpec(Section):
    """One physical arrangement on the table (Fig. 4)."""

    name: str = Field(pattern=NAME_PATTERN, max_length=64, description="names its dataset folders")
    targets: list[str] = Field(min_length=1)
    distance_mm: Distance = Field(description="camera to target centre at the model view")
    elevation_deg: float = Field(gt=5, lt=90, description="of the model view above the table")
    n_clutter: int = Field(ge=0, le=20)
    glenoid_tilt_deg: tuple[Annotated[float, Field(ge=-45, le=45)], Annotated[float, Field(ge=-45, le=45)]] | None = (
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

    def dataset_ids(self) -> list[str]:
        """The datasets of the lines, one per start offset (the id names its folder)."""
        return [f"{self.scene}_line{offset:02.0f}" for offset in self.offsets_deg]


class DHErrorParams(Section):
    """How far the physical arm's DH parameters are from the published ones (:mod:`.robot`): each joint's
    deviation is drawn once per world from N(0, std). A factory-calibrated UR-class arm that its user has not
    calibrated again reaches a commanded pose to about a millimetre (docs/references.md "Robot")."""

    length_std_mm: float = Field(ge=0, le=5, description="a_i and d_i; above 5 mm the arm would miss its poses by "
                                                         "centimetres, as an uncalibrated UR does (not a real arm)")
    twist_std_deg: float = Field(ge=0, le=1, description="alpha_i: misaligned joint axes; 1 deg moves the tool by "
                                                         "~15 mm at full reach")
    joint_offset_std_deg: float = Field(ge=0, le=1, description="theta_i: each encoder's zero; same bound")


class MountParams(Section):
    """The adapter holding the camera on the tool flange: T_flange_cam (:mod:`.robot`)."""

    translation_mm: tuple[Annotated[float, Field(ge=-300, le=300)], Annotated[float, Field(ge=-300, le=300)],
                          Annotated[float, Field(ge=-300, le=300)]] = Field(
        description="camera centre in the flange frame; within 300 mm: an adapter, not a second arm")
    rotation_deg: tuple[float, float, float] = Field(description="rotation vector (axis x angle) of the camera "
                                                                 "frame in the flange frame")

    @field_validator("rotation_deg")
    @classmethod
    def _angle(cls, rotation: tuple[float, float, float]) -> tuple[float, float, float]:
        if math.hypot(*rotation) > 180:
            raise ValueError(f"a rotation vector turns by at most 180 deg, got {math.hypot(*rotation):.1f}")
        return rotation


class HandEyeErrorParams(Section):
    """The hand-eye calibration's result = the true mount times a small pose error, N(0, std) per axis of its
    translation and rotation vector, drawn once per world (one calibration session)."""

    translation_std_mm: float = Field(ge=0, le=10, description="above 10 mm a calibration has failed, not erred")
    rotation_std_deg: float = Field(ge=0, le=5, description="same")


class PlacementParams(Section):
    """Where the robot's base stands on a scene's table (:meth:`.robot.Robot.placed`): the first candidate whose
    IK reaches every pose of the scene within the margins."""

    base_azimuths_deg: distinct(Annotated[float, Field(ge=-180, le=180)]) = Field(
        min_length=1, description="directions tried, from the direction aim point -> cameras, in this order")
    base_distances_mm: distinct(Annotated[float, Field(gt=0, le=1500)]) = Field(
        min_length=1, description="horizontal distances from the aim point tried at each azimuth, in this order; "
                                  "a UR5e reaches 850 mm")
    min_manipulability: float = Field(ge=0, lt=1, description="scaled |det J| (kinematics.manipulability) every pose "
                                                              "keeps: away from the arm's singularities")
    table_clearance_mm: float = Field(ge=0, le=500, description="every joint and the camera stay this far above the "
                                                                "table top")


class RingDownParams(Section):
    """The camera's vibration after a stop (:mod:`.ringdown`): one damped mode of the arm."""

    natural_frequency_hz: float = Field(ge=1, le=200, description="lowest mode of a lightweight arm: a few to tens "
                                                                  "of Hz")
    damping_ratio: float = Field(gt=0, lt=1, description="< 1: an oscillation that rings down, not a creep")
    amplitude_deg: float = Field(ge=0, le=1, description="envelope at the moment the controller reports the stop; "
                                                         "1 deg would be a visibly shaking arm")


class RobotParams(Section):
    """A UR5e carrying the eye-in-hand camera, and how its poses err (:mod:`.robot`, :mod:`.ringdown`):
    shared by both worlds, each of which draws its own arm, calibration and placement from its seed."""

    dh_errors: DHErrorParams
    joint_repeatability_std_deg: float = Field(ge=0, le=0.05, description="per joint and visit; 0.05 deg would "
                                                                          "give ~ten times the data sheet's 0.03 mm")
    mount: MountParams
    hand_eye_errors: HandEyeErrorParams
    placement: PlacementParams
    ring_down: RingDownParams

    def error_budget(self) -> tuple[dict[str, float], dict[str, float]]:
        """The variance (deg^2; mm^2) each key adds to the first-order error of a camera pose, orientation and
        position, keyed by its name under ``robot``. Each small joint rotation (offset, twist, repeatability; six
        of each) adds its variance to the orientation error whatever the pose; a rotation moves the camera by at
        most its distance from the axis, bounded by the arm's reach plus the mount; lengths add theirs directly.
        The hand-eye rotation turns the camera about its own centre."""
        lever_mm = UR5E.reach_mm + math.hypot(*self.mount.translation_mm)
        rotations = {"dh_errors.joint_offset_std_deg": 6 * self.dh_errors.joint_offset_std_deg**2,
                     "dh_errors.twist_std_deg": 6 * self.dh_errors.twist_std_deg**2,
                     "joint_repeatability_std_deg": 6 * self.joint_repeatability_std_deg**2}
        orientation = rotations | {"hand_eye_errors.rotation_std_deg": 3 * self.hand_eye_errors.rotation_std_deg**2}
        position = ({key: variance * (math.radians(1.0) * lever_mm) ** 2 for key, variance in rotations.items()}
                    | {"dh_errors.length_std_mm": 12 * self.dh_errors.length_std_mm**2,
                       "hand_eye_errors.translation_std_mm": 3 * self.hand_eye_errors.translation_std_mm**2})
        return orientation, position


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

    seed: Seed
    images_per_stop: int = Field(ge=1, le=100)
    model_baseline_mm: float = Field(gt=0, le=100)
    camera: CameraParams
    sensor: SensorParams
    calibration: CalibrationParams
    printed_boards: PrintedBoardParams
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
            raise ValueError(f"unknown world {name!r}; these params have {available}")
        if name == "main":
            return self.model_copy(update={"validation": None})
        fields = self.model_dump() | self.validation.model_dump() | {"validation": None}
        return GenerateParams.model_validate(fields, context=context)

    def worlds(self) -> dict[str, "GenerateParams"]:
        """Every world's params, the main world first."""
        return {name: self.world(name) for name in WORLDS if name == "main" or self.validation is not None}

    def dataset_ids(self) -> list[str]:
        """Every dataset, in the order of :func:`~.dataset.plan_datasets`: each scene's arcs, then the lines."""
        return ([i for spec in self.scenes for i in self.arcs.dataset_ids(spec.name)]
                + ([] if self.lines is None else self.lines.dataset_ids()))
