"""How far a frame's pose estimate disagrees with the robot's own kinematics (ours, issue 38).

The target stands still while the robot moves the camera (Windsor et al. IV-D: a static scene). The robot reports
where it put the camera (T_base_cam, from its joint encoders, forward kinematics and hand-eye calibration), so
the board (or reference frame) in which M_t is placed has one pose in the robot's base frame, fixed by the model
view: T_base_board = T_base_cam0 T_cam0_board, T_cam0_board the pose that placed M_t (IV-C). Every later estimate
T_cam_board_est then says where the robot would have to be for the two to agree; the disagreement

    E_t_kin, E_r_kin = E_t, E_r (IV-C's definitions) of T_base_cam T_cam_board_est against T_base_board

is an observation of the estimate's error that needs no ground truth: the estimate's E_t and E_r plus the
robot's error between the model view and this stop (its relative accuracy: a UR-class arm errs by ~0.05 mm over a
20 mm move and by 0.1-0.5 mm across an arc of a few hundred mm, docs/references.md "Robot"; the hand-eye
calibration's error turns with the camera). Where the target can move relative to the robot's base (a patient),
this is no observation of the estimate alone, and the predictors that use it (prediction/error_predictors.py,
``error_next_step_observed``) do not apply.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from poseintegrity.dataset_meta import pose_problem
from poseintegrity.poses import NAN_POSE, pose_errors


def reported_pose(values: Any) -> np.ndarray:
    """A frame's T_base_cam_robot (16 row-major numbers, frames.parquet) as (4, 4) mm; the NaN pose when the frame
    has none (a missing column or value) or one that is no rigid transform (its kinematic errors are then NaN)."""
    if values is None or pose_problem(values) is not None:
        return NAN_POSE
    return np.asarray(values, dtype=np.float64).reshape(4, 4)


def kinematic_errors(T_base_cam: np.ndarray, T_cam_board_est: np.ndarray, T_base_board: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray]:
    """(E_t_kin (...) mm, E_r_kin (...) deg): the disagreement of estimates T_cam_board_est (..., 4, 4) made with
    the camera where the robot reports it, T_base_cam (..., 4, 4), with the board's pose in the base frame
    T_base_board (4, 4) (module docstring). NaN where any pose is unknown (NaN: a frame without a pose, a dataset
    without the robot's poses); poses that are no rigid transform are refused (:func:`~poseintegrity.poses.pose_errors`
    names them)."""
    T_base_cam = np.asarray(T_base_cam, dtype=np.float64)
    T_cam_board_est = np.asarray(T_cam_board_est, dtype=np.float64)
    return pose_errors(T_base_cam @ T_cam_board_est, np.broadcast_to(T_base_board, T_cam_board_est.shape))
