"""R11's rows (``artifacts.json`` ``<realism>.truth_accuracy``, stage 02): what the board's ground truth adds to the
errors E_t (mm) and E_r (deg), the model placement's own error and the share of frames whose board pose is trusted."""

from __future__ import annotations

from poseintegrity.report.headlines.sections import Headline


def truth_rows(stage: str, prefix: str, section: str, world: str = "") -> list[Headline]:
    """R11 (artifacts.json ``<prefix>.truth_accuracy``): what the board's ground truth adds to E_t and E_r, the model
    placement's own error, and how the board's checks went."""
    key = f"{prefix}.truth_accuracy"
    at = f"{world} world: " if world else ""
    return [
        Headline(stage, f"{key}.p99_E_t_truth_mm", f"{at}R11: what the ground truth adds to E_t, 99th percentile (mm)",
                 "ArUco board used as ground truth (IV-C)", "<= 0.5", section=section),
        Headline(stage, f"{key}.p99_E_r_truth_deg", f"{at}R11: ... to E_r, 99th percentile (deg)", "-", "<= 0.5",
                 section=section),
        Headline(stage, f"{key}.median_E_t_truth_mm", f"{at}... median (mm)", section=section),
        Headline(stage, f"{key}.by_tolerance.4mm_10deg.p99_E_t_truth_mm", f"{at}R11 at 4 mm / 10 deg, over the frames "
                 "fine enough for it (its bar 2 x 0.5 mm): 99th percentile (mm)", "-", "<= 1.0", section=section),
        Headline(stage, f"{key}.by_tolerance.4mm_10deg.p99_E_r_truth_deg", f"{at}... (deg; bar 3.3 x 0.5 deg)", "-",
                 "<= 1.67", section=section),
        Headline(stage, f"{key}.by_tolerance.4mm_10deg.judged_share", f"{at}frames whose board pose judges 4 mm / "
                 "10 deg", fmt="{:.1%}", section=section),
        Headline(stage, f"{key}.placement_max_E_t_mm",
                 f"{at}model placement: model image 0's board pose vs exact, largest over datasets (mm)",
                 section=section),
        Headline(stage, f"{key}.placement_max_E_r_deg", f"{at}... (deg)", section=section),
        Headline(stage, f"{key}.trusted_share", f"{at}frames whose board pose is trusted (else bad_ground_truth or "
                 "not found: not judged)", fmt="{:.1%}", section=section),
        Headline(stage, f"{key}.dropped_share", f"{at}frames whose board check dropped a marker or corner",
                 fmt="{:.1%}", section=section),
    ]
