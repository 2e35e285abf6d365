"""The rows of ``generate.json`` (stage 01): the rendered datasets, the camera's calibration, the robot's errors, the
ground-truth board and the disk the datasets take (GB)."""

from __future__ import annotations

from poseintegrity.report.headlines.sections import Headline

DATASET_ROWS: list[Headline] = [
    Headline("generate", "n_viewing_angle_datasets", "viewing-angle datasets", "21 (7 scenes x 3 azimuths)"),
    Headline("generate", "n_straight_line_datasets", "straight-line datasets", "4"),
    Headline("generate", "n_images", "images (incl. model pairs)", "~4 850"),
    Headline("generate", "image_width_px", "image width (px)", "1936 (full sensor)"),
    Headline("generate", "focal_px", "focal length (px)", "not published"),
    Headline("generate", "clahe_keypoint_gain_bone", "SIFT keypoints on bone targets, CLAHE / raw",
             "CLAHE used 'to improve feature detection on low texture bone phantoms'"),
    Headline("generate", "calibration.rms_px", "camera calibration (ChArUco, rendered): reprojection RMS (px)", "-",
             "<= 0.5 (generate.calibration.max_rms_px)"),
    Headline("generate", "calibration.fx_error_pct", "... its focal length error (%)"),
    Headline("generate", "calibration.principal_point_error_px", "... its principal point error (px)"),
    Headline("generate", "calibration.ray_error_px_max", "... largest ray error over the image (px)"),
    Headline("generate", "robot.abs_position_mm_mean", "robot: absolute camera position error, mean (mm)",
             "Franka Panda (ours: a UR5e, docs/references.md)"),
    Headline("generate", "robot.baseline_error_mm_mean", "robot: the 20 mm model baseline's error, mean (mm)"),
    Headline("generate", "robot.theta_error_deg_mean", "robot: error of the recorded viewing angle theta (deg)"),
    Headline("generate", "board.type", "ground-truth board (generate.board)", "'an ArUco marker board [35]' (IV-C)",
             section="ground_truth"),
    Headline("generate", "board.placement", "... placed", section="ground_truth"),
    Headline("generate", "board.median_lever_arm_mm", "... board origin (where E_t is measured) to the target, median "
             "over scenes (mm)", section="ground_truth"),
    Headline("generate", "board.max_lever_arm_mm", "... largest (mm)", section="ground_truth"),
    Headline("generate", "board.min_in_view", "... share of the board in view at its worst pose, smallest over scenes",
             fmt="{:.0%}", section="ground_truth"),
    Headline("generate", "disk_gb", "disk (GB)", "-", "<= 3"),
]
