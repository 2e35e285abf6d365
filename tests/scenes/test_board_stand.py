"""A board on its post (scenes/board_stand.py): clutter that would cover the board is told apart from clutter behind
it, by polygon geometry of our own."""

import numpy as np

from poseintegrity.scenes.board_stand import covers
from poseintegrity.scenes.camera import look_at

K = np.array([[1024.0, 0.0, 483.5], [0.0, 1024.0, 303.5], [0.0, 0.0, 1.0]])
AIM = np.array([0.0, 0.0, 60.0])
VIEW = np.array([0.0, -np.cos(np.radians(50)), np.sin(np.radians(50))])  # the model camera, 50 deg above the table


def test_clutter_in_front_of_the_board_covers_it_and_clutter_behind_does_not():
    camera = look_at(AIM + 350.0 * VIEW, AIM)
    centre = AIM + np.array([-100.0, 0.0, 0.0])
    paper = centre + np.array([[-50, -40, 0], [50, -40, 0], [50, 40, 0], [-50, 40, 0]], float)
    towards = camera[:3, 3] - centre
    front = (centre + 0.5 * towards)[:2]
    behind = (centre - 0.8 * towards)[:2]
    assert covers(front, 20.0, 160.0, paper, [camera], K)
    assert not covers(behind, 20.0, 160.0, paper, [camera], K)
