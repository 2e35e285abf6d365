"""The ``protocol`` section of ``params.yaml``: the facts of Windsor et al.'s protocol that stages 01-05 share.

Each fact is set once here and read by every stage that needs it: the trajectories' range ends (IV-D: arcs of
45 deg, straight lines of 150 mm), the PnP method of the paper's tables (Tables I-III; stage 05 runs the others),
the error tolerances (IV-E) and how many stops a robot samples before it predicts (IV-A). A section that names a
tolerance (``predict.tolerance_fig6_fig7``, ``predict.live_tolerance``) is checked against this one's names.
"""

from __future__ import annotations

from typing import Annotated, Literal, get_args

from pydantic import Field, field_validator

from poseintegrity.schema import FromList, Section

Trajectory = Literal["arc", "line"]
PnPMethod = Literal["usac_magsac", "epnp", "p3p", "ap3p", "sqpnp", "iterative"]
FailedFrameRule = Literal["fail_fraction", "capped", "infinite"]
FAILED_FRAME_RULES: tuple[str, ...] = get_args(FailedFrameRule)  # localization/envelope.py says what each means


def tolerance_name(tolerance: tuple[float, float]) -> str:
    """``(2, 3)`` -> ``"2mm_3deg"`` (the ``tolerance`` column of the envelope tables)."""
    E_t_mm, E_r_deg = tolerance
    return f"{E_t_mm:g}mm_{E_r_deg:g}deg"


class SampledStops(Section):
    """Stops a robot samples from the start of a trajectory before it predicts (IV-A: "the first 4 sampling
    positions"; 5 on the straight lines of V-C)."""

    arc: int = Field(ge=2, le=100)
    line: int = Field(ge=2, le=100)


class EnvelopeParams(Section):
    """How theta_a treats a frame without a pose (IV-E leaves it open; localization/envelope.py). Stage 02 computes
    theta_a under every rule; ``failed_frames`` is the one of the paper's tables."""

    failed_frames: FailedFrameRule = Field(description="the headline rule")
    max_failed_fraction: float = Field(gt=0, lt=1, description="fail_fraction: a stop fails when more of its frames "
                                                               "than this have no pose")
    cap_factor: float = Field(ge=1, le=1000, description="capped: a frame without a pose counts as this many times "
                                                         "the tolerance (>= 1: a failed frame is never a pass)")


class ProtocolParams(Section):
    """Windsor et al. IV: trajectories, PnP method, tolerances, sampled stops. Lengths in mm, angles in deg."""

    arc_span_deg: float = Field(gt=0, le=180, description="arcs: theta = 0 .. span, the model view at 0 (IV-D: 45); "
                                                          "a viewing angle is at most 180 deg")
    line_length_mm: float = Field(gt=0, le=1000, description="lines: x = 0 .. length from their start (IV-D: 150)")
    pnp_method: PnPMethod = Field(description="the PnP-RANSAC of the paper's tables (OpenCV USAC, MAGSAC)")
    tolerances: list[Annotated[tuple[Annotated[float, Field(gt=0, le=1000)], Annotated[float, Field(gt=0, le=180)]],
                               FromList]] = Field(
        min_length=1, description="(E_t mm, E_r deg) error tolerances of IV-E (paper: 2 mm/3 deg, 4 mm/10 deg); "
                                  "E_t up to a metre (no localization task tolerates more), E_r up to 180 deg (the "
                                  "largest rotation error)")
    sampled_stops: SampledStops
    envelope: EnvelopeParams

    @field_validator("tolerances")
    @classmethod
    def _tolerances(cls, tolerances: list[tuple[float, float]]) -> list[tuple[float, float]]:
        if any(E_t_mm <= 0 or E_r_deg <= 0 for E_t_mm, E_r_deg in tolerances):
            raise ValueError(f"tolerances are positive (mm, deg) pairs, got {tolerances}")
        names = [tolerance_name(t) for t in tolerances]
        if len(set(names)) != len(names):
            raise ValueError(f"tolerances must be distinct, got {names}")
        return tolerances

    @property
    def tolerance_names(self) -> list[str]:
        """``["2mm_3deg", "4mm_10deg"]``: how the tables and other sections name the tolerances."""
        return [tolerance_name(t) for t in self.tolerances]

    def stops_sampled(self, trajectory: Trajectory) -> int:
        """Stops a robot samples on a trajectory type before it predicts: k of the long range predictor, the
        next-step predictor's first fit and the headline RMSE of Fig. 2."""
        return getattr(self.sampled_stops, trajectory)

    def range_end(self, trajectory: Trajectory) -> float:
        """End of a trajectory type's range: the arc span (deg) or the line length (mm)."""
        return {"arc": self.arc_span_deg, "line": self.line_length_mm}[trajectory]
