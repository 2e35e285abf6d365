"""poseintegrity: when can a pose estimate be trusted?

Reproductions of Windsor et al., "Forward Prediction of Target Localization Failure Through Pose
Estimation Artifact Modelling" (IEEE RA-L 9(5), 2024) and Black & Salcudean, "Robust Object Pose Tracking for
Augmented Reality Guidance and Teleoperation" (IEEE Transactions on Instrumentation and Measurement, 2024,
DOI 10.1109/TIM.2024.3398108), as a DVC pipeline of papermill notebooks (docs/references.md).
"""

from poseintegrity.dispatch import check_dispatch, pin_dispatch

check_dispatch(pin_dispatch())  # before numpy, OpenBLAS, OpenCV, torch or numba load: they read it once (dispatch)

from poseintegrity.errors import ArgumentError, PoseIntegrityError  # noqa: E402

__all__ = ["ArgumentError", "PoseIntegrityError"]
__version__ = "0.1.0"
