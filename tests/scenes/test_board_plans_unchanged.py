"""The board planner made fast (issue 49) plans what it planned before: every session of params.yaml's worlds (main
and validation: each scene's arcs, the lines' scene's lines), laid out as stage 01 lays it out
(scenes/world_checks.laid_out), gets the plan the planner of commit 3e10f65 made, to the bit: the same boards (square
size, first marker id, T_world_board, post foot and top, share in view), their worst predicted sigma_t, each
trajectory's board and its poses left unserved.

board_plans_3e10f65.json holds those plans, written by ``python benchmarks/bench_board_plan.py --reference 3e10f65
--write-fixture tests/scenes/board_plans_3e10f65.json`` (which runs 3e10f65's board_plan.py, read from git, beside
this tree's and checks they agree). Where params.yaml's worlds change, write it again: the planner of 3e10f65
plans any world.
"""

import json
import math
from pathlib import Path

import numpy as np

from poseintegrity.config import load_params
from poseintegrity.scenes import world_checks
from repository import ROOT

BEFORE = Path(__file__).with_name("board_plans_3e10f65.json")


def test_every_session_of_the_committed_worlds_is_planned_as_before():
    everything = load_params(ROOT / "params.yaml")
    before = json.loads(BEFORE.read_text())["sessions"]
    worlds = everything.generate.worlds()
    assert [(s["world"], s["scene"], s["session"]) for s in before] == [
        (world, index, session) for world, params in worlds.items()
        for index, session in world_checks.sessions(params)]
    differences = []
    for expected in before:
        where = f"{expected['world']} scene {expected['scene']} {expected['session']}s"
        plan = world_checks.laid_out(worlds[expected["world"]], everything.protocol, expected["world"],
                                     expected["scene"], expected["session"]).plan
        got = {"board_of": list(plan.board_of), "unserved": list(plan.unserved), "boards": [
            {"square_mm": b.square_mm, "first_id": b.first_id, "T_world_board": b.placement.T_world_board.tolist(),
             "post_foot": b.placement.post_foot.tolist(), "post_top": b.placement.post_top.tolist(),
             "in_view": b.placement.in_view, "sigma_t_mm": b.sigma_t_mm} for b in plan.boards]}
        differences += [f"{where}: {key} {expected[key]} -> {got[key]}" for key in ("board_of", "unserved")
                        if got[key] != expected[key]]
        if len(got["boards"]) != len(expected["boards"]):
            differences.append(f"{where}: {len(expected['boards'])} -> {len(got['boards'])} boards")
            continue
        for k, (old, new) in enumerate(zip(expected["boards"], got["boards"])):
            differences += [f"{where}, board {k}: {key} {old[key]} -> {new[key]}" for key in old
                            if not _same(old[key], new[key])]
    assert not differences, "\n".join(differences)


def _same(a, b) -> bool:
    """Equal to the bit (floats as JSON wrote them, repr: exact), NaN equal to NaN."""
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return np.array_equal(np.asarray(a, float), np.asarray(b, float)) if isinstance(a, list) else a == b
