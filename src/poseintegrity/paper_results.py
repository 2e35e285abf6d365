"""The papers' published figures, in one place: every report label and comparison reads them from here.

Windsor, Fontan, Pivonka, Milford, "Forward Prediction of Target Localization Failure Through Pose Estimation
Artifact Modelling", IEEE Robotics and Automation Letters 9(5), 2024: Tables I-III and section V. Black and Salcudean, "Robust Object Pose Tracking for Augmented Reality Guidance and Teleoperation",
IEEE Transactions on Instrumentation and Measurement, 2024 (DOI 10.1109/TIM.2024.3398108): section III.
Tolerances are named as in our tables ("2mm_3deg", "4mm_10deg"); SPL in degrees.
"""

from __future__ import annotations

TOLERANCES = ("2mm_3deg", "4mm_10deg")
TOLERANCE_LABELS = {"2mm_3deg": "2 mm/3 deg", "4mm_10deg": "4 mm/10 deg"}

# Table I (long range, static, MLP) and Table II (next step): maximum mean SPL at zero incursion, deg
WINDSOR_SPL_ZERO_INCURSION = {
    "static": {"2mm_3deg": 7.0, "4mm_10deg": 7.0},
    "mlp": {"2mm_3deg": 11.5, "4mm_10deg": 12.5},
    "long_range": {"2mm_3deg": 12.3, "4mm_10deg": 13.5},
    "next_step": {"2mm_3deg": 13.9, "4mm_10deg": 14.4},
}
# Table III: inlier thresholds n_t at maximum mean SPL and zero incursion
WINDSOR_THRESHOLDS = {
    "long_range": {"2mm_3deg": 23, "4mm_10deg": 28},
    "next_step": {"2mm_3deg": 12, "4mm_10deg": 15},
}
# Relative improvements on the mean over both tolerances (Tables I-II, V-A, V-B), as fractions
WINDSOR_IMPROVEMENTS = {
    "long_range_vs_static": 0.841,
    "long_range_vs_mlp": 0.074,
    "next_step_vs_static": 1.021,
    "next_step_vs_long_range": 0.098,
    "straight_line_vs_static": 0.462,
}
# V-C live trials: n_t = 15 (Table III, 4 mm/10 deg), 10 trials
WINDSOR_LIVE = {"n_t": 15, "n_trials": 10, "incursions": 0, "envelope_share": 0.747, "static_envelope_share": 0.604}

# Black and Salcudean, section III and Table I. rms_mm / rms_deg are their metric: the mean over the three axes of
# the RMS element-wise difference (position; Euler angles); success rates as fractions of 10 000 frames
BLACK_RESULTS = {
    "rms_mm": {"no_filter": 3.01, "ukf": 1.77},
    "rms_deg": {"no_filter": 1.75, "ukf": 1.51},
    "success_rate": {"markers4": 0.9863, "markers3": 0.9604},
    "lag_ms": 199.5,
    "failed_downdate_share": 16 / 25000,
}


def mean_spl(predictor: str) -> float:
    """The paper's "Mean" column of Tables I-II: the mean over both tolerances."""
    values = WINDSOR_SPL_ZERO_INCURSION[predictor]
    return sum(values.values()) / len(values)
