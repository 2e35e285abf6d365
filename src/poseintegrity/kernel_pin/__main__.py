"""``python -m poseintegrity.kernel_pin``: this machine's pinned environment as shell ``export`` lines, for a process
that does not start by importing poseintegrity (README, "Running on a Dask cluster")."""

import sys

from poseintegrity.kernel_pin import OPENCV_LOG, cpu_flags, pinned_environment


def main() -> int:
    for name, value in sorted(pinned_environment(cpu_flags()).items()):
        print(f"export {name}='{value}'")
    name, value = OPENCV_LOG
    print(f'export {name}="${{{name}:-{value}}}"')  # the user's own level stays
    return 0


if __name__ == "__main__":
    sys.exit(main())
