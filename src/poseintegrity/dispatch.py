"""The instruction-set level of every compiled kernel a result passes through, pinned to AVX2.

OpenCV, numpy, torch (its ATen kernels, MKL and oneDNN) and numba choose their kernels by the CPU they run on.
Kernels of another width round differently (another summation order, another polynomial for exp or sin), so a CPU
with AVX-512 gave other SIFT keypoints than an AVX2 one and moved theta_a by up to 1.4 % (issue 32). Every x86-64
CPU of the last decade has AVX2; dispatching no higher gives the same numbers on all of them.

Each library reads its setting from the environment once, when it loads, so :func:`pin_dispatch` sets it in
``os.environ`` before anything is imported: ``import poseintegrity`` does so first, the stage runner's kernel and
the parallel workers inherit it. ``POSEINTEGRITY_CPU_DISPATCH=native`` leaves every library to its own choice
(faster on AVX-512, machine-dependent numbers). OpenBLAS, whose kernels numpy's matrix products use, is left to the
machine's settings (``OPENBLAS_CORETYPE``). For a process that does not start by importing poseintegrity (a Dask
worker started by hand), ``python -m poseintegrity.dispatch`` prints the settings as shell ``export`` lines.

Sources (docs/references.md, "CPU dispatch"): OpenCV's ``OPENCV_CPU_DISABLE`` (core/src/system.cpp), numpy's
``NPY_DISABLE_CPU_FEATURES`` (numpy 2.4 groups), ATen's ``ATEN_CPU_CAPABILITY``, MKL's conditional numerical
reproducibility ``MKL_CBWR``, oneDNN's ``ONEDNN_MAX_CPU_ISA`` and numba's ``NUMBA_CPU_NAME``.
"""

from __future__ import annotations

import os
import sys
import warnings
from collections.abc import Mapping, MutableMapping

CEILING = "AVX2"
SWITCH = "POSEINTEGRITY_CPU_DISPATCH"  # "pinned" (default) or "native"

# OpenCV's dispatched groups above AVX2 (cv2.getCPUFeaturesLine() of the locked build lists AVX512-SKX), each with
# the CPU flags (/proc/cpuinfo names) OpenCV requires for it. OpenCV warns on every import when asked to disable a
# group the CPU lacks, so only the groups the CPU has are named (the variable is set, empty, on a CPU without any:
# a user's own value would otherwise lower the level).
OPENCV_ABOVE_CEILING = {"AVX512-SKX": frozenset({"avx512f", "avx512cd", "avx512bw", "avx512dq", "avx512vl"})}
NUMPY_ABOVE_CEILING = ("X86_V4", "AVX512_ICL", "AVX512_SPR")  # numpy >= 2.4 feature groups
FIXED = {
    "NPY_DISABLE_CPU_FEATURES": " ".join(NUMPY_ABOVE_CEILING),
    "ATEN_CPU_CAPABILITY": "avx2",  # torch's own kernels
    "MKL_CBWR": "AVX2,STRICT",  # torch's BLAS (MKL): AVX2 code paths, run-to-run identical
    "ONEDNN_MAX_CPU_ISA": "AVX2",  # torch's oneDNN primitives
    "NUMBA_CPU_NAME": "haswell",  # numba compiles for the first AVX2 core, not for the host
}


def cpu_flags() -> frozenset[str]:
    """The CPU's feature flags (lower case, as /proc/cpuinfo names them); from llvmlite's host query where there is
    no /proc/cpuinfo."""
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as info:
            for line in info:
                if line.startswith("flags"):
                    return frozenset(line.partition(":")[2].split())
    except OSError:
        pass
    from llvmlite import binding  # numba's compiler: knows the host without /proc

    return frozenset(name.lower() for name, has in binding.get_host_cpu_features().items() if has)


def pinned_environment(flags: frozenset[str]) -> dict[str, str]:
    """The environment that caps every library at AVX2 on a CPU with ``flags``."""
    opencv = [group for group, needs in OPENCV_ABOVE_CEILING.items() if needs <= flags]
    return FIXED | {"OPENCV_CPU_DISABLE": ",".join(opencv)}


def pin_dispatch(environ: MutableMapping[str, str] = os.environ) -> dict[str, str]:
    """Set the pinned environment in ``environ`` (replacing a user's value of the same variables) unless
    ``POSEINTEGRITY_CPU_DISPATCH=native``; return what was set. Libraries imported earlier keep their own choice:
    :func:`check_dispatch` says which."""
    if environ.get(SWITCH, "pinned") == "native":
        return {}
    pinned = pinned_environment(cpu_flags())
    environ.update(pinned)
    return pinned


def dispatch_above_ceiling(modules: Mapping[str, object] = sys.modules) -> list[str]:
    """The loaded libraries whose kernels dispatch above AVX2 in this process, one line each (empty when pinned)."""
    found = []
    numpy_core = modules.get("numpy._core._multiarray_umath")
    if numpy_core is not None:
        features = getattr(numpy_core, "__cpu_features__", {})
        on = [name for name in NUMPY_ABOVE_CEILING if features.get(name)]
        if on:
            found.append(f"numpy dispatches {', '.join(on)}")
    cv2 = modules.get("cv2")
    if cv2 is not None and hasattr(cv2, "getCPUFeaturesLine"):
        enabled = {token[1:] for token in cv2.getCPUFeaturesLine().split() if token.startswith("*")
                   and not token.endswith("?")}
        on = sorted(enabled & OPENCV_ABOVE_CEILING.keys())
        if on:
            found.append(f"OpenCV dispatches {', '.join(on)}")
    torch = modules.get("torch")
    if torch is not None and hasattr(torch, "backends"):
        capability = torch.backends.cpu.get_cpu_capability()
        if capability.upper().startswith("AVX512"):
            found.append(f"torch dispatches {capability}")
    return found


def check_dispatch(modules: Mapping[str, object] = sys.modules) -> None:
    """A RuntimeWarning when a library loaded before poseintegrity dispatches above AVX2 (its results may then differ
    from another machine's in the last bits), naming it and what to do."""
    found = dispatch_above_ceiling(modules)
    if found and os.environ.get(SWITCH, "pinned") != "native":
        warnings.warn(f"{'; '.join(found)}: loaded before poseintegrity, so above the pinned {CEILING} level and "
                      f"its results may differ from other machines' in the last bits; import poseintegrity first, "
                      f"or start Python with the environment of `python -m poseintegrity.dispatch`",
                      RuntimeWarning, stacklevel=3)


def main() -> int:
    """Print the pinned environment of this machine as shell ``export`` lines (a Dask worker's environment)."""
    for name, value in sorted(pinned_environment(cpu_flags()).items()):
        print(f"export {name}='{value}'")
    return 0


if __name__ == "__main__":
    sys.exit(main())
