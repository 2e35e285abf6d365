"""Throughput of ``import-rosbag`` (poseintegrity.recorded.rosbag) against plain ``cv2.imdecode`` of the same images,
measured in one run (alternately, benchmarks/paired_timing.py), on bags written by rosbags' own writer.

Two ROS 2 bags of the same N camera-sized (968 x 608) noisy 8-bit gray images: CompressedImage (the PNG bytes;
import copies them) and Image mono8 (raw pixels; import encodes each as PNG). The reference decodes the same N PNG
files with cv2.imdecode (what any reader of the images pays at least once). Prints images/s of each and the ratio
import / imdecode (> 1: importing is faster than decoding the images once). Not a timed unit test.

Run: .venv/bin/python benchmarks/bench_rosbag_import.py [--images N] [--repeats R] (from the repository root)
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1] / "tests" / "recorded")]
from recorded_tools import write_bag  # noqa: E402 (test helper: rosbags' writers)
from paired_timing import paired_medians  # noqa: E402

from poseintegrity.lens import Camera  # noqa: E402
from poseintegrity.recorded.rosbag import import_rosbag  # noqa: E402

WIDTH, HEIGHT = 968, 608  # the paper's camera (params.yaml generate.camera)


def images(n: int, rng: np.random.Generator) -> list[np.ndarray]:
    """n (HEIGHT, WIDTH) uint8 images: a smooth scene plus sensor noise, as camera images compress."""
    scene = cv2.resize(rng.random((HEIGHT // 16, WIDTH // 16)).astype(np.float32), (WIDTH, HEIGHT)) * 200 + 20
    return [np.clip(scene + rng.normal(0, 3, scene.shape), 0, 255).astype(np.uint8) for _ in range(n)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--images", type=int, default=60)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    arrays = images(args.images, rng)
    pngs = [cv2.imencode(".png", image)[1].tobytes() for image in arrays]
    camera = Camera(np.array([[1000.0, 0, WIDTH / 2], [0, 1000.0, HEIGHT / 2], [0, 0, 1]]), np.zeros(5), WIDTH, HEIGHT)
    tmp = Path(tempfile.mkdtemp())
    try:
        stops = tmp / "stops.csv"
        stops.write_text("index,stop\n0,model0\n1,model1\n" + "".join(f"{k},{k - 2}\n" for k in range(2, args.images)))
        bags = {"CompressedImage (PNG bytes)": write_bag(tmp / "compressed", 2, pngs, camera),
                "Image mono8 (raw pixels)": write_bag(tmp / "raw", 2, arrays, camera, encodings=["mono8"] * args.images)}
        decode = lambda: [cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED) for data in pngs]  # noqa: E731
        print(f"{args.images} images of {WIDTH} x {HEIGHT} px, median of {args.repeats} paired runs")
        for name, bag in bags.items():
            out = tmp / "out"
            run = lambda: import_rosbag(bag, "/camera/image", "/camera/camera_info", stops, out,  # noqa: E731
                                        trajectory="arc")
            reference, subject = paired_medians(decode, run, args.repeats)
            ours, theirs = args.images / subject, args.images / reference
            print(f"{name:28s} import {ours:7.1f} images/s   cv2.imdecode {theirs:7.1f} images/s   "
                  f"import / imdecode x{ours / theirs:.2f}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
