"""Where the ground-truth board stands (scenes/board_placement.py), checked by polygon geometry of our own: at every
commanded pose the chosen board overlaps no target's silhouette hull and keeps its share in view; a scene without
room is refused by name."""

import cv2
import numpy as np
import pytest

from poseintegrity.poses import inverse
from poseintegrity.scenes import board_placement as placement
from poseintegrity.scenes.board_stand import TABLE_CLEARANCE_MM, PlacementError
from poseintegrity.scenes.trajectories import arc_trajectories

K = np.array([[1024.0, 0.0, 483.5], [0.0, 1024.0, 303.5], [0.0, 0.0, 1.0]])
WIDTH, HEIGHT = 968, 608
AIM = np.array([0.0, 0.0, 60.0])
VIEW = np.array([0.0, -np.cos(np.radians(50)), np.sin(np.radians(50))])  # the model camera, 50 deg above the table


def box(centre, size):
    """The 8 corners (8, 3) of an axis-aligned box."""
    offsets = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    return np.asarray(centre) + offsets * size


def project(points, T_world_cam):
    view = inverse(T_world_cam)
    cam = points @ view[:3, :3].T + view[:3, 3]
    return (cam[:, :2] / cam[:, 2:3]) @ K[:2, :2].T + K[:2, 2]


def poses():
    pair, arcs = arc_trajectories(AIM, VIEW, 350.0, 20.0, [0.0, 90.0, 270.0], 45.0, 20)
    return [*pair] + [T for arc in arcs for T in arc]


def test_the_board_stays_in_view_and_clear_of_the_target_at_every_pose():
    target = box(AIM, (90.0, 60.0, 120.0))
    size, margin = (105.0, 75.0), 6.0
    where = placement.place_board(size, margin, [target], AIM, poses()[0], poses(), K, WIDTH, HEIGHT, "scene t")
    T = where.T_world_board
    w, h = size[0] + 2 * margin, size[1] + 2 * margin
    paper = (T @ np.array([[-margin, -margin, 0, 1], [size[0] + margin, -margin, 0, 1],
                           [size[0] + margin, size[1] + margin, 0, 1], [-margin, size[1] + margin, 0, 1]]).T).T[:, :3]
    image = np.array([[0, 0], [WIDTH - 1, 0], [WIDTH - 1, HEIGHT - 1], [0, HEIGHT - 1]], np.float32)
    for pose in poses():
        quad = project(paper, pose).astype(np.float32)
        hull = cv2.convexHull(project(target, pose).astype(np.float32))
        assert cv2.intersectConvexConvex(quad, hull.reshape(-1, 2))[0] == 0
        in_view = cv2.intersectConvexConvex(quad, image)[0] / cv2.contourArea(quad)
        assert in_view >= placement.MIN_IN_VIEW - 0.05  # the share is sampled on a grid
    assert np.isclose(np.linalg.det(T[:3, :3]), 1.0) and np.allclose(T[:3, 2], -VIEW)
    assert paper[:, 2].min() >= TABLE_CLEARANCE_MM and np.isclose(where.post_foot[2], 0.0)
    assert (w, h) == (117.0, 87.0)


def test_a_target_filling_every_view_leaves_no_room_and_is_named():
    giant = box(AIM, (900.0, 900.0, 600.0)) + [0, 0, 200.0]
    with pytest.raises(PlacementError, match="scene big: no place"):
        placement.place_board((105.0, 75.0), 6.0, [giant], AIM, poses()[0], poses(), K, WIDTH, HEIGHT, "scene big")

