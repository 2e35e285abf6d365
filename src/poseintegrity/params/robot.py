"""Schema of ``generate.robot`` (stage 01): the UR5e carrying the camera, how its poses err, where it stands and how
it rings down after a stop (:mod:`poseintegrity.scenes.robot`, :mod:`poseintegrity.kinematics`,
:mod:`poseintegrity.scenes.ringdown`). Every number bounded with its reason; a robot whose expected error reaches
the stops' spacing is refused by the ``generate`` section."""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import Field, field_validator

from poseintegrity.denavit_hartenberg import UR5E
from poseintegrity.schema import FromList, Section, distinct


class DHErrorParams(Section):
    """How far the physical arm's DH parameters are from the published ones (scenes/robot.py): each joint's
    deviation is drawn once per world from N(0, std). A factory-calibrated UR-class arm that its user has not
    calibrated again reaches a commanded pose to about a millimetre (docs/references.md "Robot")."""

    length_std_mm: float = Field(ge=0, le=5, description="a_i and d_i; above 5 mm the arm would miss its poses by "
                                                         "centimetres, as an uncalibrated UR does (not a real arm)")
    twist_std_deg: float = Field(ge=0, le=1, description="alpha_i: misaligned joint axes; 1 deg moves the tool by "
                                                         "~15 mm at full reach")
    joint_offset_std_deg: float = Field(ge=0, le=1, description="theta_i: each encoder's zero; same bound")


Turn = Annotated[float, Field(ge=-360, le=360)]  # deg: a component beyond a full turn is a typo (the length rule is tighter)


class MountParams(Section):
    """The adapter holding the camera on the tool flange: T_flange_cam (scenes/robot.py)."""

    translation_mm: Annotated[tuple[Annotated[float, Field(ge=-300, le=300)], Annotated[float, Field(ge=-300, le=300)],
                                    Annotated[float, Field(ge=-300, le=300)]], FromList] = Field(
        description="camera centre in the flange frame; within 300 mm: an adapter, not a second arm")
    rotation_deg: Annotated[tuple[Turn, Turn, Turn], FromList] = Field(
        description="rotation vector (axis x angle) of the camera frame in the flange frame; its length at most "
                    "180 deg (checked below)")

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
    """Where the robot's base stands on a scene's table (scenes/robot.py Robot.placed): the first candidate whose
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
    """The camera's vibration after a stop (scenes/ringdown.py): one damped mode of the arm."""

    natural_frequency_hz: float = Field(ge=1, le=200, description="lowest mode of a lightweight arm: a few to tens "
                                                                  "of Hz")
    damping_ratio: float = Field(gt=0, lt=1, description="< 1: an oscillation that rings down, not a creep")
    amplitude_deg: float = Field(ge=0, le=1, description="envelope at the moment the controller reports the stop; "
                                                         "1 deg would be a visibly shaking arm")


class RobotParams(Section):
    """A UR5e carrying the eye-in-hand camera, and how its poses err (scenes/robot.py, scenes/ringdown.py):
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
