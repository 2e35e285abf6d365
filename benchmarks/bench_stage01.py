"""Stage 01 outside its rendering floor, the code before issue 33 against this tree, measured in the same run.

1. The ring-down warp maps of one exposure (scenes/acquisition.rotation_maps, ~5 900 a run) at the paper-scale
   resolution: the compiled pass against the numpy expressions it replaced (kept below), paired medians over
   exposures' rotations, and whether every map value is equal to the bit.
2. Planning the worlds (calibration sessions, robot placement and drives): the tasks of scenes/world_plan.plan_worlds
   run one after the other in the notebook's process, as before, against this tree's run on two worker processes
   (started and warmed first, as the stage's rendering needs them anyway); wall times, and whether the plans are
   equal, value for value (routes, ring-downs, calibrations, robot accuracy).

Parameters: params.yaml (generate, protocol, parallel). Run from the repository root:
    .venv/bin/python benchmarks/bench_stage01.py [--rounds 2]
"""

import argparse
import dataclasses
import os
import time
from functools import partial

import cv2
import numpy as np
from scipy.spatial.transform import Rotation
from paired_timing import paired_medians  # benchmarks/paired_timing.py

from poseintegrity.config import load_params
from poseintegrity.scenes import world_plan
from poseintegrity.scenes.acquisition import rotation_maps
from poseintegrity.scenes.calibration_views import render_view
from poseintegrity.scenes.camera import true_camera
from poseintegrity.workers import Workers


def reference_rotation_maps(K, rotation, map_x, map_y):
    """rotation_maps before issue 33: whole-image numpy expressions in float64, then float32."""
    H = K @ Rotation.from_rotvec(rotation).as_matrix() @ np.linalg.inv(K)
    w = H[2, 0] * map_x + H[2, 1] * map_y + H[2, 2]
    return ((H[0, 0] * map_x + H[0, 1] * map_y + H[0, 2]) / w).astype(np.float32), (
        (H[1, 0] * map_x + H[1, 1] * map_y + H[1, 2]) / w).astype(np.float32)


def warp_maps(params) -> None:
    lens = true_camera(params.camera)
    K_canvas, _, _ = lens.canvas
    map_x, map_y = lens.sensor_maps
    rotations = np.random.default_rng(0).normal(0.0, 2e-4, (40, 3))  # ring-down rotations are ~1e-4 rad
    equal = all(np.array_equal(a.view(np.uint32), b.view(np.uint32))
                for r in rotations for a, b in zip(rotation_maps(K_canvas, r, map_x, map_y),
                                                    reference_rotation_maps(K_canvas, r, map_x, map_y)))
    cycle = iter(np.tile(rotations, (50, 1)))
    old, new = paired_medians(lambda: reference_rotation_maps(K_canvas, next(cycle), map_x, map_y),
                              lambda: rotation_maps(K_canvas, next(cycle), map_x, map_y), 40)
    print(f"warp maps of one exposure ({map_x.shape[1]} x {map_x.shape[0]} px): numpy {1e3 * old:6.2f} ms, compiled "
          f"{1e3 * new:6.2f} ms: ratio {new / old:.3f}; maps equal to the bit on {len(rotations)} rotations: {equal}")


def same(a, b) -> bool:
    """Equal values, recursively through dataclasses, dicts and sequences (arrays to the bit, NaN equal to NaN)."""
    if dataclasses.is_dataclass(a):
        return type(a) is type(b) and all(same(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a))
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return isinstance(b, (list, tuple)) and len(a) == len(b) and all(map(same, a, b))
    if isinstance(a, (np.ndarray, float, np.floating)):
        return np.array_equal(a, b, equal_nan=True)
    return a == b


def traced(function, task):
    """function(task), with the process it ran in and its CPU-seconds."""
    start = time.process_time()
    result = function(task)
    return result, (os.getpid(), time.process_time() - start)


class Traced:
    """The Workers interface of plan_worlds, recording each task's process and CPU-seconds."""

    def __init__(self, workers: Workers):
        self.workers, self.traces = workers, []

    def map(self, function, tasks, desc="tasks", progress=True):
        out = self.workers.map(partial(traced, function), tasks, desc, progress)
        self.traces += [trace for _, trace in out]
        return [result for result, _ in out]


def planning(everything, rounds: int) -> None:
    """Workers are started and warmed (imports, compiled kernels) first, as the stage's rendering needs them anyway.
    On a shared machine the wall times are noisy: beside them the CPU-seconds of the tasks, all of them (one process
    does them one after the other) and the most any one worker did (the wall time on two free cores)."""
    params, protocol = everything.generate, everything.protocol
    seconds, plans, traces = {1: [], 2: []}, {}, {}
    for n_jobs in (1, 2):  # 1: the tasks in this process, one after the other (the serial plan of before)
        with Workers(everything.parallel.model_copy(update={"n_jobs": n_jobs})) as workers:
            workers.map(warm, [params] * n_jobs, progress=False)
            for _ in range(rounds):
                traced_workers = Traced(workers)
                start = time.perf_counter()
                plans[n_jobs] = world_plan.plan_worlds(params, protocol, traced_workers, progress=False)
                seconds[n_jobs].append(time.perf_counter() - start)
                traces[n_jobs] = traced_workers.traces
    old, new = np.median(seconds[1]), np.median(seconds[2])
    serial = sum(cpu for _, cpu in traces[1])
    per_worker = {}
    for pid, cpu in traces[2]:
        per_worker[pid] = per_worker.get(pid, 0.0) + cpu
    busiest = max(per_worker.values())
    print(f"planning both worlds ({len(traces[1])} tasks): in the notebook's process {old:6.1f} s, on 2 warm workers "
          f"{new:6.1f} s (wall, medians of {rounds}): ratio {new / old:.3f}; CPU-seconds {serial:.1f} in one process, "
          f"{busiest:.1f} on the busiest worker: ratio {busiest / serial:.3f}; plans equal: {same(plans[1], plans[2])}")


def warm(params) -> None:
    """A calibration view rendered and exposed: the process imports and loads what planning runs."""
    render_view(params, np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 400], [0, 0, 0, 1]]),
                np.random.default_rng(0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    everything = load_params("params.yaml")
    warp_maps(everything.generate)
    planning(everything, args.rounds)


if __name__ == "__main__":
    main()
