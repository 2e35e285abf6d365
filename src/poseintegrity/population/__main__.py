"""``python -m poseintegrity.population``: the population of rendered worlds (issue 49).

    draw <world> --out <file> [--params params.yaml]
                       world <world> of params.yaml's population, written as a params file of its own (an overlay
                       on params.yaml: population/draw.py); the first command of its stage in population/dvc.yaml

Bad input (a world not in ``population.worlds``, an invalid params file): one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.population.draw import write_world
from poseintegrity.stage_timing import usage_error


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m poseintegrity.population", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    draw = commands.add_parser("draw", help="write one world's params file")
    draw.add_argument("world")
    draw.add_argument("--out", type=Path, required=True)
    draw.add_argument("--params", type=Path, default=Path("params.yaml"))
    args = parser.parse_args(argv)
    try:
        print(write_world(args.params, args.world, args.out))
    except PoseIntegrityError as error:
        return usage_error(" ".join(str(error).split()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
