"""What checking a cache file costs (poseintegrity.cache_entry): reading an entry whole (its SHA-256 over every byte,
its key) against the plain ``np.load`` of the same arrays that the caches used before (no check), measured in the
same run, on the real cache files of a features folder, per kind of file (SIFT features, evidence, PnP results,
consensus columns); and, as the scale it is judged on, the CPU time CLAHE + SIFT takes on one of those frames.

    .venv/bin/python benchmarks/bench_cache_entry.py [--features data/features] [--files 200] [--rounds 5]

Per kind: the median time per file of each reader over ``--rounds`` interleaved rounds (every file read once per
round, from the page cache after a first pass), their ratio, and the extra time per frame of the check (the four
files of a frame) against the SIFT time per frame.
"""

from __future__ import annotations

import argparse
import io
import time
from pathlib import Path

import poseintegrity  # noqa: F401 (first: the pinned kernels)
import numpy as np

from poseintegrity.cache_entry import TRAILER, read_whole
from poseintegrity.localization.features import detect_features, read_gray

KINDS = {"SIFT features": "[0-9].npz", "evidence": ".evidence.npz", "PnP results": ".pnp.npz",
         "consensus": ".consensus.npz"}


def plain_load(path: Path) -> dict:
    """The arrays as the caches read them before: np.load, no checksum (the trailer cut off first, in memory)."""
    with np.load(io.BytesIO(path.read_bytes()[:-TRAILER])) as stored:
        return {name: stored[name] for name in stored.files}


def checked_load(path: Path) -> object:
    return read_whole(path, "a key none has")  # the whole check; the key comparison is the last, cheapest step


def per_file_s(reader, files: list[Path]) -> float:
    start = time.perf_counter()
    for path in files:
        reader(path)
    return (time.perf_counter() - start) / len(files)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--features", type=Path, default=Path("data/features"))
    parser.add_argument("--files", type=int, default=200, help="files per kind, spread over the folder")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    extra_per_frame = 0.0
    print(f"{'kind':<16} {'files':>5} {'np.load ms':>10} {'checked ms':>10} {'ratio':>6}")
    for kind, suffix in KINDS.items():
        found = sorted(p for p in args.features.rglob(f"*{suffix}") if "model" not in p.parts)
        files = found[:: max(1, len(found) // args.files)][: args.files]
        for path in files:  # into the page cache
            path.read_bytes()
        plain, checked = [], []
        for _ in range(args.rounds):
            plain.append(per_file_s(plain_load, files))
            checked.append(per_file_s(checked_load, files))
        p, c = float(np.median(plain)), float(np.median(checked))
        extra_per_frame += c - p
        print(f"{kind:<16} {len(files):>5} {p * 1e3:>10.3f} {c * 1e3:>10.3f} {c / p:>6.2f}")
    image = sorted((args.features.parent / "datasets").glob("*/images/*.png"))[0]
    gray = read_gray(image)
    detect_features(gray)
    start = time.process_time()
    for _ in range(args.rounds):
        detect_features(gray)
    sift = (time.process_time() - start) / args.rounds
    print(f"the check adds {extra_per_frame * 1e3:.2f} ms per frame (its four files) against {sift * 1e3:.0f} ms of "
          f"CLAHE + SIFT on {image.name}: {extra_per_frame / sift:.2%}")


if __name__ == "__main__":
    main()
