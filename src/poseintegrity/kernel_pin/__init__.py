"""The instruction-set level of every compiled kernel a result passes through, pinned to AVX2.

OpenCV, numpy, OpenBLAS (numpy's and scipy's matrix kernels), torch (its ATen kernels, MKL and oneDNN) and numba
choose their kernels by the CPU they run on. Kernels of another width round differently (another summation order,
another polynomial for exp or sin, a fused multiply-add or not), so a CPU with AVX-512 gave other SIFT keypoints than
an AVX2 one and moved theta_a by up to 1.4 % (issue 32), and OpenBLAS's SkylakeX kernels gave other stage-01 data and
730 other metric values than its Haswell ones (issue 40). Every x86-64 CPU of the last decade has AVX2; dispatching
no higher, and running OpenBLAS's Haswell kernels (AVX2 + FMA), gives the same numbers on all of them. OpenCV's Intel
IPP dispatches by itself, and its magnitude starts from an approximate reciprocal square root that differs between
Intel and AMD CPUs: it is switched off (``OPENCV_IPP``), so SIFT runs OpenCV's own pinned kernels.

Each library reads its setting from the environment once, when it loads, so :func:`pin_dispatch` sets it in
``os.environ`` before anything is imported: ``import poseintegrity`` does so first, the stage runner's kernel and
the parallel workers inherit it, and ``make install`` has the venv's Jupyter kernels import poseintegrity before
any cell runs. Only this process and its children see it, never the machine's settings; where it replaces a value
of the caller's environment, :func:`check_dispatch` says so, once (the children inherit the pinned value).
``POSEINTEGRITY_CPU_DISPATCH=native`` leaves every library to its own choice (faster on AVX-512, machine-dependent
numbers). For a process that does not start by importing poseintegrity (a Dask worker started by hand),
``python -m poseintegrity.kernel_pin`` prints the settings as shell ``export`` lines (``__main__.py``: a module of its
own, so that running it does not run again what ``import poseintegrity`` has imported).

Sources (docs/references.md, "CPU dispatch"): OpenCV's ``OPENCV_CPU_DISABLE`` (core/src/system.cpp), numpy's
``NPY_DISABLE_CPU_FEATURES`` (numpy 2.4 groups), OpenCV's ``OPENCV_IPP`` (its Intel IPP, which dispatches on its own),
OpenBLAS's ``OPENBLAS_CORETYPE`` (DYNAMIC_ARCH builds), ATen's
``ATEN_CPU_CAPABILITY``, MKL's conditional numerical reproducibility ``MKL_CBWR``, oneDNN's ``ONEDNN_MAX_CPU_ISA``
and numba's ``NUMBA_CPU_NAME`` with ``NUMBA_CPU_FEATURES``.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import sys
import warnings
from collections.abc import Mapping, MutableMapping
from pathlib import Path

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
    # ... with that core's features: without this numba adds the host's own (AVX-512 on an AVX-512 CPU: zmm code in
    # every fastmath kernel, another summation width), whatever NUMBA_CPU_NAME says (numba/core/codegen.py,
    # _get_host_cpu_features; "" is the value numba's config gives the generic CPU for the same purpose)
    "NUMBA_CPU_FEATURES": "",
    # Intel IPP inside OpenCV: OPENCV_CPU_DISABLE does not reach it, so it ran its AVX-512 code (k0) on an AVX-512 CPU
    # and its AVX2 code (l9) elsewhere, and its magnitude (which SIFT's orientations and descriptors use) starts from
    # vrsqrtps, an approximate instruction whose results differ between Intel and AMD: SIFT descriptors +-1 and
    # other angles in 142 of 645 frames between the two levels on one CPU (traced under qemu, docs/references.md,
    # "CPU dispatch"). Without IPP, OpenCV runs its own kernels, pinned above, at no measurable cost
    # (benchmarks/bench_dispatch.py).
    "OPENCV_IPP": "disabled",
}
# OpenCV logs "IPP was disabled by OPENCV_IPP" at WARNING level when it loads, in every process; its log level is
# raised to ERROR unless the user set one (pin_dispatch)
OPENCV_LOG = ("OPENCV_LOG_LEVEL", "ERROR")
# numpy's and scipy's OpenBLAS (scipy-openblas, built with DYNAMIC_ARCH: one kernel set per CPU family, chosen at
# load) run the kernel set named here instead of their CPU's. Haswell's needs AVX2 and FMA (every AVX2 CPU has both);
# on a CPU without them no kernel set is pinned.
OPENBLAS_CORE = "Haswell"
OPENBLAS_NEEDS = frozenset({"avx2", "fma"})
OPENBLAS_CORENAME = ("scipy_openblas_get_corename64_", "scipy_openblas_get_corename", "openblas_get_corename64_",
                     "openblas_get_corename")  # the symbol that names the kernel set a loaded OpenBLAS runs


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
    openblas = {"OPENBLAS_CORETYPE": OPENBLAS_CORE} if OPENBLAS_NEEDS <= flags else {}
    return FIXED | {"OPENCV_CPU_DISABLE": ",".join(opencv)} | openblas


def pin_dispatch(environ: MutableMapping[str, str] = os.environ) -> dict[str, tuple[str, str]]:
    """Set the pinned environment in ``environ`` unless ``POSEINTEGRITY_CPU_DISPATCH=native``; return the values of
    ``environ`` it replaced, ``{name: (the caller's value, the pinned one)}``, for :func:`check_dispatch` to name.
    Libraries imported earlier keep their own choice: :func:`check_dispatch` says which."""
    if environ.get(SWITCH, "pinned") == "native":
        return {}
    pinned = pinned_environment(cpu_flags())
    replaced = {name: (environ[name], value) for name, value in pinned.items() if environ.get(name, value) != value}
    environ.update(pinned)
    environ.setdefault(*OPENCV_LOG)
    return replaced


def kernel_level(environ: Mapping[str, str] = os.environ) -> str:
    """The level the compiled kernels of this process dispatch to: ``"AVX2, OpenCV without IPP"`` where pinned (the
    same on every x86-64 machine), else ``"native "`` and a digest of the CPU's flags (machine-dependent). Part of every cache
    entry's key (:mod:`poseintegrity.cache_entry`): an entry computed by other kernels is computed again."""
    if environ.get(SWITCH, "pinned") != "native":
        return f"{CEILING}, OpenCV without IPP"
    return "native " + hashlib.sha1(" ".join(sorted(cpu_flags())).encode()).hexdigest()[:12]


def openblas_cores() -> dict[str, str]:
    """The kernel set each OpenBLAS loaded in this process runs (its core name, e.g. "Haswell"), by library file;
    read from the libraries themselves (the files mapped into the process, /proc/self/maps: empty without it)."""
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as maps:
            paths = {fields[5].strip() for line in maps if "openblas" in line.lower()
                     and len(fields := line.split(None, 5)) == 6 and ".so" in fields[5]}
    except OSError:
        return {}
    cores = {}
    for path in sorted(paths):
        library = ctypes.CDLL(path)  # already loaded: the same handle, nothing runs again
        getter = next((getattr(library, name) for name in OPENBLAS_CORENAME if hasattr(library, name)), None)
        if getter is not None:
            getter.restype = ctypes.c_char_p
            cores[Path(path).name] = getter().decode()
    return cores


def unpinned_dispatch(modules: Mapping[str, object] = sys.modules, openblas: Mapping[str, str] | None = None,
                      flags: frozenset[str] | None = None) -> list[str]:
    """The loaded libraries whose kernels are not the pinned ones in this process, one line each (empty when
    pinned): dispatched above AVX2, or an OpenBLAS running another kernel set than Haswell on a CPU that runs it.
    ``openblas``: :func:`openblas_cores` (read from this process when numpy is loaded); ``flags``: the CPU's."""
    found = []
    flags = cpu_flags() if flags is None else flags
    if openblas is None:
        openblas = openblas_cores() if "numpy" in modules else {}
    if OPENBLAS_NEEDS <= flags:
        found += [f"OpenBLAS ({library}) runs its {core} kernels" for library, core in openblas.items()
                  if core != OPENBLAS_CORE]
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
        if hasattr(cv2, "ipp") and cv2.ipp.useIPP():
            found.append(f"OpenCV runs Intel IPP ({cv2.ipp.getIppVersion()})")
    numba_config = modules.get("numba.core.config")
    if numba_config is not None and (getattr(numba_config, "CPU_NAME", None), getattr(numba_config, "CPU_FEATURES", None)) \
            != (FIXED["NUMBA_CPU_NAME"], FIXED["NUMBA_CPU_FEATURES"]):
        found.append("numba compiles for this machine's CPU")
    torch = modules.get("torch")
    if torch is not None and hasattr(torch, "backends"):
        capability = torch.backends.cpu.get_cpu_capability()
        if capability.upper().startswith("AVX512"):
            found.append(f"torch dispatches {capability}")
    return found


def check_dispatch(replaced: Mapping[str, tuple[str, str]] = {}, modules: Mapping[str, object] = sys.modules,
                   openblas: Mapping[str, str] | None = None) -> None:
    """A RuntimeWarning when :func:`pin_dispatch` replaced a value of the caller's environment (``replaced``), naming
    each, and one when a library loaded before poseintegrity runs other kernels than the pinned ones (its results may
    then differ from another machine's in the last bits), naming it and what to do."""
    if os.environ.get(SWITCH, "pinned") == "native":
        return
    if replaced:
        names = ", ".join(f"{name}={new!r} in place of your {old!r}" for name, (old, new) in sorted(replaced.items()))
        warnings.warn(f"poseintegrity set {names}, for this process and the ones it starts (the machine's settings "
                      f"are unchanged): the pinned kernels give the same numbers on every x86-64 machine (README, "
                      f"\"Same numbers on any x86-64 machine\"); {SWITCH}=native keeps yours", RuntimeWarning,
                      stacklevel=3)
    found = unpinned_dispatch(modules, openblas)
    if found:
        warnings.warn(f"{'; '.join(found)}: loaded before poseintegrity, so not at the pinned {CEILING} level and "
                      f"its results may differ from other machines' in the last bits; import poseintegrity first, "
                      f"or start Python with the environment of `python -m poseintegrity.kernel_pin`",
                      RuntimeWarning, stacklevel=3)
