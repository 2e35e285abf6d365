"""The ground-truth board planner (scenes/board_plan.plan_boards, issue 49) at a reference commit against this tree,
measured in the same run, on every session of params.yaml's worlds (main and validation: each scene's arcs, the
lines).

Each session is laid out once as stage 01 lays it out (scenes/world_checks.laid_out, this tree's planner), which gives
plan_boards' arguments; then the reference's plan_boards (its board_plan.py read from git at ``--reference``,
loaded as a module of its own) and this tree's are run alternately on them, ``--repeats`` times (this tree's kernels
compiled and loaded first). Per session and in total: medians of wall seconds and of CPU-seconds (one process: on a
shared machine the wall time also holds what other processes took), this tree's over the reference's, and whether
the plans are equal (every field: boards, their placements to the bit, sigma_t, board_of, unserved).
``--write-fixture PATH`` writes the reference's plans as JSON (tests/scenes/board_plans_3e10f65.json is
``--reference 3e10f65``'s, the planner before the speed-up).

    .venv/bin/python benchmarks/bench_board_plan.py [--reference 3e10f65] [--repeats 1] [--write-fixture PATH]

from the repository root.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import poseintegrity  # noqa: F401 (first: pins the kernels' dispatch before numpy loads)
import numpy as np

from poseintegrity.config import load_params
from poseintegrity.scenes import board_plan, world_checks

from git_reference import ROOT, module_at  # benchmarks/ (the scripts run from the repository root)


def reference_planner(commit: str):
    """scenes/board_plan.py at ``commit``, imported as the module ``board_plan_<commit>``."""
    return module_at(commit, "src/poseintegrity/scenes/board_plan.py")


def sessions(everything) -> list[tuple[str, int, str, tuple, dict]]:
    """(world, scene index, session, plan_boards' args and kwargs) of every session of every world, as laid out."""
    calls = []
    planner = board_plan.plan_boards

    def recorded(*args, **kwargs):
        calls.append((args, kwargs))
        return planner(*args, **kwargs)

    board_plan.plan_boards = recorded  # scenes/catalog.py calls it through the module
    try:
        out = []
        for world, params in everything.generate.worlds().items():
            for index, session in world_checks.sessions(params):
                world_checks.laid_out(params, everything.protocol, world, index, session)
                out.append((world, index, session, *calls[-1]))
        return out
    finally:
        board_plan.plan_boards = planner


def same(a, b) -> bool:
    """Equal values, recursively through dataclasses (by field names: the two planners' classes differ), sequences
    and arrays (to the bit, NaN equal to NaN)."""
    if dataclasses.is_dataclass(a):
        names = [f.name for f in dataclasses.fields(a)]
        return names == [f.name for f in dataclasses.fields(b)] and all(same(getattr(a, n), getattr(b, n))
                                                                          for n in names)
    if isinstance(a, (list, tuple)):
        return isinstance(b, (list, tuple)) and len(a) == len(b) and all(map(same, a, b))
    if isinstance(a, (np.ndarray, float, np.floating)):
        return np.array_equal(a, b, equal_nan=True)
    return a == b


def timed(planner, args, kwargs, wall: list, cpu: list):
    start, start_cpu = time.perf_counter(), time.process_time()
    plan = planner(*args, **kwargs)
    wall.append(time.perf_counter() - start)
    cpu.append(time.process_time() - start_cpu)
    return plan


def fixture(world: str, index: int, session: str, plan) -> dict:
    """A plan as JSON (json writes a float's repr, exact; NaN as NaN)."""
    return {"world": world, "scene": index, "session": session,
            "boards": [{"square_mm": b.square_mm, "first_id": b.first_id,
                        "T_world_board": b.placement.T_world_board.tolist(),
                        "post_foot": b.placement.post_foot.tolist(), "post_top": b.placement.post_top.tolist(),
                        "in_view": b.placement.in_view, "sigma_t_mm": b.sigma_t_mm} for b in plan.boards],
            "board_of": list(plan.board_of), "unserved": list(plan.unserved)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", default="3e10f65")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--write-fixture", type=Path)
    args = parser.parse_args()
    everything = load_params(ROOT / "params.yaml")
    reference = reference_planner(args.reference)
    laid_out = sessions(everything)  # this tree's kernels compiled (or loaded) on the way
    total = {"old": [0.0, 0.0], "new": [0.0, 0.0]}
    written, all_equal = [], True
    print(f"{'session':18s} {'old s':>7s} {'new s':>7s} {'ratio':>6s}   {'old CPU':>7s} {'new CPU':>7s} {'ratio':>6s}  "
          f"equal")
    for world, index, session, call_args, call_kwargs in laid_out:
        wall, cpu = {"old": [], "new": []}, {"old": [], "new": []}
        for _ in range(args.repeats):
            old = timed(reference.plan_boards, call_args, call_kwargs, wall["old"], cpu["old"])
            new = timed(board_plan.plan_boards, call_args, call_kwargs, wall["new"], cpu["new"])
        equal = same(old, new)
        all_equal &= equal
        medians = {k: (float(np.median(wall[k])), float(np.median(cpu[k]))) for k in wall}
        for k in total:
            total[k] = [t + m for t, m in zip(total[k], medians[k])]
        (ow, oc), (nw, nc) = medians["old"], medians["new"]
        label = f"{world} {index} {session}"
        print(f"{label:18s} {ow:7.2f} {nw:7.2f} {nw / ow:6.3f}   {oc:7.2f} {nc:7.2f} {nc / oc:6.3f}  {equal}",
              flush=True)
        written.append(fixture(world, index, session, old))
    (ow, oc), (nw, nc) = total["old"], total["new"]
    print(f"{'total':18s} {ow:7.2f} {nw:7.2f} {nw / ow:6.3f}   {oc:7.2f} {nc:7.2f} {nc / oc:6.3f}  {all_equal}")
    print(f"{len(laid_out)} sessions, medians of {args.repeats} (reference {args.reference}; CPU: one process's "
          f"CPU-seconds); plans equal in every field, to the bit: {all_equal}")
    if args.write_fixture:
        about = (f"The board plans of every session of params.yaml's worlds as the planner of commit {args.reference} "
                 f"made them (scenes/board_plan.py): python benchmarks/bench_board_plan.py --reference "
                 f"{args.reference} --write-fixture {args.write_fixture}")
        sessions_json = ",\n".join(json.dumps(plan) for plan in written)  # one session a line
        args.write_fixture.write_text(f'{{"about": {json.dumps(about)},\n "reference": {json.dumps(args.reference)},\n'
                                      f' "sessions": [\n{sessions_json}\n]}}\n')


if __name__ == "__main__":
    main()
