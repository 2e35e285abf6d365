"""Speed of the compiled correspondence (match_markers_unchecked) against the numpy code it replaced, on the same frames.

The frames are those stage 06 matches: a simulated accuracy recording (params.yaml's track section, detections of rendered
frames with their phantoms), each frame as the tracker matched it in run_filter (with the filter's prediction) and as
run_no_filter matches it (no prediction), plus the stress recording (motion (b)).  The reference is
tests/tracking/reference_matching.py (the numpy pipeline before compilation).  Both are timed alternately over all
frames (paired medians, benchmarks/paired_timing.py); the assignments are compared on every frame first.

Run: .venv/bin/python benchmarks/bench_matching.py [--duration 10] [--repeats 7] (from the repository root)
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core, as the stages run
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402
from unittest import mock  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # tests/tracking/reference_matching.py

from poseintegrity.config import load_section  # noqa: E402
from poseintegrity.tracking.filter import tracker  # noqa: E402
from poseintegrity.tracking.markers.correspondence import match_markers_unchecked  # noqa: E402
from poseintegrity.tracking.simulation.simulate import run_filter, simulate  # noqa: E402
from paired_timing import paired_medians  # noqa: E402
from tracking import reference_matching  # noqa: E402


def recorded_calls(params, duration_s: float) -> dict[str, list[tuple]]:
    """The arguments of every match_markers_unchecked call of stage 06's runs on simulated recordings, by kind."""
    calls: dict[str, list[tuple]] = {"with prediction (run_filter)": [], "no prediction (run_no_filter)": [], "stress, with prediction": []}
    recording = simulate(params, np.random.default_rng(7), duration_s=duration_s)[0]
    stress = simulate(params, np.random.default_rng(11), omega_std=params.evaluation.success_omega_std, duration_s=duration_s)[0]
    for name, sim in (("with prediction (run_filter)", recording), ("stress, with prediction", stress)):
        def record(points, geometry, previous, matching, _calls=calls[name]):
            if previous is not None:
                _calls.append((points, geometry, previous.copy(), matching))
            return match_markers_unchecked(points, geometry, previous, matching)

        with mock.patch.object(tracker, "match_markers_unchecked", record):
            run_filter(sim, params, use_gyro=True)
    calls["no prediction (run_no_filter)"] = [(points, recording.markers_body, None, params.matching) for points in recording.points]
    return calls


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=10.0, help="seconds of each simulated recording")
    parser.add_argument("--repeats", type=int, default=7)
    options = parser.parse_args()
    params = load_section(ROOT / "params.yaml", "track")
    calls = recorded_calls(params, options.duration)
    print(f"match_markers_unchecked per call: numpy reference vs compiled, paired medians of {options.repeats} passes")
    for name, frames in calls.items():
        differ = sum(not np.array_equal(match_markers_unchecked(*args), reference_matching.match_markers_unchecked(*args)) for args in frames)
        reference, compiled = paired_medians(lambda: [reference_matching.match_markers_unchecked(*args) for args in frames],
                                             lambda: [match_markers_unchecked(*args) for args in frames], options.repeats)
        points = np.mean([len(args[0]) for args in frames])
        print(f"  {name:30s} {len(frames):5d} frames ({points:4.1f} points on average): reference {reference / len(frames) * 1e6:8.1f} us, "
              f"compiled {compiled / len(frames) * 1e6:7.1f} us, {reference / compiled:5.1f}x faster; assignments differ in {differ}")


if __name__ == "__main__":
    main()
