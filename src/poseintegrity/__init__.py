"""poseintegrity: when can a pose estimate be trusted?

Reproductions of Windsor et al., "Forward Prediction of Target Localization Failure Through Pose
Estimation Artifact Modelling" (RA-L 2024) and Black & Salcudean, "Robust Object Pose Tracking for
Augmented Reality Guidance and Teleoperation" (2023), as a DVC pipeline of papermill notebooks.
"""

__version__ = "0.1.0"
