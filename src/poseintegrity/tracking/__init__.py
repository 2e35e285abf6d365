"""Marker tracking after Black and Salcudean (IEEE TIM 2024): IR marker detection, point correspondence, Kabsch,
square-root UKF with gyro fusion, and the simulation study of their sections II-F and III.

Module map (paper section -> module):
    II-B  detection      :mod:`detection`       (threshold, contours, circularity, centroid, depth, unprojection)
    II-B  sensor frames  :mod:`frames`          (AHAT-like IR + depth synthesis, ours)
    II-D  Alg. 1, 2, 3   :mod:`correspondence`  (+ gated optimal assignment)
    Alg. 4               :mod:`kabsch`
    II-E  eqs. 3-30      :mod:`model`           (state, process model, P_proc, P_mes)
    Alg. 5               :mod:`srukf`, :mod:`cholesky`, :mod:`unscented`; reference :mod:`ukf`
    II-F  simulation     :mod:`motion`
    loop                 :mod:`tracker`
    III   results        :mod:`evaluation`
"""

from poseintegrity.tracking.correspondence import match_brute_force, match_frobenius, match_gated, match_markers, match_voting
from poseintegrity.tracking.detection import detect_markers, validate_frame
from poseintegrity.tracking.geometry import MARKERS_BODY
from poseintegrity.tracking.kabsch import kabsch, pose_from_points
from poseintegrity.tracking.params import TrackParams
from poseintegrity.tracking.srukf import SquareRootUKF
from poseintegrity.tracking.tracker import MarkerTracker
from poseintegrity.tracking.ukf import UnscentedKalmanFilter

__all__ = [
    "MARKERS_BODY",
    "MarkerTracker",
    "SquareRootUKF",
    "TrackParams",
    "UnscentedKalmanFilter",
    "detect_markers",
    "kabsch",
    "match_brute_force",
    "match_frobenius",
    "match_gated",
    "match_markers",
    "match_voting",
    "pose_from_points",
    "validate_frame",
]
