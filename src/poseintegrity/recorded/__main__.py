"""``python -m poseintegrity.recorded``: check recorded dataset folders, export stage-01 datasets to the format.

    validate <folder> [<folder> ...] [--params params.yaml]
                                       every problem, one line each naming file and field (exit 2), or a summary
                                       line per folder and a warning line per weak model pair (exit 0)
    export <data_dir> --out <folder>   every dataset of data_dir/datasets in the recorded format (all or nothing)
    import-rosbag <bag> --image-topic T --info-topic T --stops <csv> --out <folder> --trajectory arc|line
                  [--board board.yaml] [--world NAME]
                                       a dataset folder from a ROS 1 / ROS 2 bag (poseintegrity.recorded.rosbag)

``validate`` checks the stops against the range ends of ``--params`` (``protocol.arc_span_deg``,
``protocol.line_length_mm``; default: ./params.yaml when there is one, else the published values), as stage 01
does, and measures each model pair's depth error at the target (:mod:`poseintegrity.recorded.model_pair`).
``--out`` of export and import-rosbag must be a new or empty folder, checked before any work.

Bad input: one line per problem on stderr, exit status 2, no traceback.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from poseintegrity.config import ParamsError, load_params
from poseintegrity.errors import PoseIntegrityError
from poseintegrity.recorded.reader import RecordedFormatError, range_problems, read_recorded
from poseintegrity.stage_timing import usage_error


def validate(folders: list[Path], params_path: Path | None = None) -> int:
    """Exit status of ``validate``: 0 (one summary line per folder on stdout, a warning line per weak model pair on
    stderr) or 2 (every problem on stderr). ``params_path``: whose range ends, tolerances and extract settings apply
    (None: ./params.yaml when it exists, else the published params.yaml)."""
    from poseintegrity.recorded.model_pair import pair_warnings

    if params_path is None and Path("params.yaml").is_file():
        params_path = Path("params.yaml")
    try:
        params = load_params(params_path)
    except ParamsError as error:
        return usage_error(" ".join(str(error).split()))
    name = str(params_path) if params_path is not None else "the published params.yaml"
    problems, summaries, warnings = [], [], []
    for folder in folders:
        try:
            recorded = read_recorded(folder)
        except RecordedFormatError as error:
            problems += error.problems
            continue
        if outside := range_problems(recorded, params.protocol, name):
            problems += outside
            continue
        warnings += [f"warning: {line}" for line in pair_warnings(recorded, params.extract, params.protocol)]
        stops = len({frame.stop for frame in recorded.frames})
        summaries.append(f"{folder}: ok, dataset {recorded.name} ({recorded.trajectory}, ground truth "
                         f"{recorded.ground_truth}, world {recorded.world}): {len(recorded.frames)} images at {stops} "
                         f"stops, camera {recorded.camera.width} x {recorded.camera.height} px")
    if problems:
        return usage_error("\n".join(problems))
    print("\n".join(summaries))
    print(f"range ends, tolerances and extract settings of {name}")
    if warnings:
        print("\n".join(warnings), file=sys.stderr)
    return 0


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m poseintegrity.recorded", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    check = commands.add_parser("validate", help="check recorded dataset folders before any work")
    check.add_argument("folders", type=Path, nargs="+")
    check.add_argument("--params", type=Path, help="the params file of the run (range ends, tolerances, extract); "
                       "default: ./params.yaml when there is one, else the published values")
    export = commands.add_parser("export", help="write stage-01 datasets in the recorded format")
    export.add_argument("data_dir", type=Path)
    export.add_argument("--out", type=Path, required=True)
    bag = commands.add_parser("import-rosbag", help="build a dataset folder from a ROS 1 or ROS 2 bag")
    bag.add_argument("bag", type=Path)
    bag.add_argument("--image-topic", required=True)
    bag.add_argument("--info-topic", required=True)
    bag.add_argument("--stops", type=Path, required=True, help="CSV: index (message index on the image topic), "
                     "stop (integer, model0 or model1), optional theta_deg, x_mm, T_cam_ref")
    bag.add_argument("--out", type=Path, required=True)
    bag.add_argument("--trajectory", choices=("arc", "line"), required=True)
    bag.add_argument("--board", type=Path, help="board.yaml of the ArUco board in view (board ground truth); "
                     "without it the table's poses are the ground truth")
    bag.add_argument("--world", default="recorded")
    args = parser.parse_args(argv)
    if args.command == "validate":
        sys.exit(validate(args.folders, args.params))
    try:
        if args.command == "export":
            from poseintegrity.recorded.export import export_all

            print(f"exported {len(export_all(args.data_dir, args.out))} dataset(s) to {args.out}")
        else:
            from poseintegrity.recorded.rosbag import import_rosbag

            import_rosbag(args.bag, args.image_topic, args.info_topic, args.stops, args.out,
                          trajectory=args.trajectory, board=args.board, world=args.world)
            print(f"imported {args.bag} into {args.out}; check it with: python -m poseintegrity.recorded validate "
                  f"{args.out}")
    except RecordedFormatError as error:
        sys.exit(usage_error("\n".join(error.problems)))
    except PoseIntegrityError as error:
        sys.exit(usage_error(str(error)))


if __name__ == "__main__":
    main()
