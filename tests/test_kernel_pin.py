"""The CPU dispatch pin (poseintegrity.kernel_pin): every library capped at AVX2 and OpenBLAS on its Haswell kernels by
the package import, whatever the user's environment asks, in this process, in the stage runner's kernel, in the
venv's Jupyter kernels and in a shell of the Dask recipe."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path
from types import SimpleNamespace

import pytest

from poseintegrity import kernel_pin
from poseintegrity.kernel_pin import openblas_cores, pin_dispatch, pinned_environment, unpinned_dispatch

AVX_CPU = frozenset({"sse4_2", "avx"})
AVX2_CPU = AVX_CPU | {"avx2", "fma"}
SKX_CPU = AVX2_CPU | {"avx512f", "avx512cd", "avx512bw", "avx512dq", "avx512vl"}

# SIFT on a fixed blurred-noise image: OpenCV's SIFT kernels are dispatched (sift.simd.hpp), so an AVX build and an
# AVX2 build give other keypoints or descriptors in their last bits
SIFT_HASH = textwrap.dedent("""
    import hashlib, poseintegrity, cv2, numpy as np
    img = cv2.GaussianBlur(np.random.default_rng(0).random((240, 320)).astype(np.float32), (0, 0), 2.0)
    img = cv2.normalize(img, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8)
    keypoints, descriptors = cv2.SIFT_create().detectAndCompute(img, None)
    points = np.array([k.pt + (k.size, k.angle, k.response) for k in keypoints])
    print(hashlib.sha256(points.tobytes() + descriptors.tobytes()).hexdigest())
""")
# A matrix product through numpy's OpenBLAS: its kernel sets sum in other orders, with or without fused multiply-adds
DGEMM_HASH = textwrap.dedent("""
    import hashlib, poseintegrity, numpy as np
    a, b = np.random.default_rng(0).standard_normal((2, 300, 300))
    print(hashlib.sha256((a @ b).tobytes()).hexdigest())
""")


def test_an_avx512_cpu_disables_opencvs_avx512_group_and_an_avx2_cpu_names_none():
    assert pinned_environment(SKX_CPU)["OPENCV_CPU_DISABLE"] == "AVX512-SKX"
    assert pinned_environment(AVX2_CPU)["OPENCV_CPU_DISABLE"] == ""  # set, so that a user's value cannot lower it
    for env in (pinned_environment(SKX_CPU), pinned_environment(AVX2_CPU)):
        assert env["ATEN_CPU_CAPABILITY"] == "avx2" and env["MKL_CBWR"].startswith("AVX2")
        assert env["NPY_DISABLE_CPU_FEATURES"].split() == ["X86_V4", "AVX512_ICL", "AVX512_SPR"]
        assert env["NUMBA_CPU_NAME"] == "haswell" and env["ONEDNN_MAX_CPU_ISA"] == "AVX2"
        assert env["OPENBLAS_CORETYPE"] == "Haswell"
    assert "OPENBLAS_CORETYPE" not in pinned_environment(AVX_CPU)  # Haswell's kernels need AVX2 and FMA


def test_the_pin_replaces_a_users_values_unless_switched_to_native():
    environ = {"OPENCV_CPU_DISABLE": "AVX2", "ATEN_CPU_CAPABILITY": "default", "NUMBA_CPU_NAME": "haswell",
               "OPENBLAS_CORETYPE": "Prescott"}
    replaced = pin_dispatch(environ)
    assert environ["ATEN_CPU_CAPABILITY"] == "avx2" and environ["OPENCV_CPU_DISABLE"] != "AVX2"
    assert replaced["ATEN_CPU_CAPABILITY"] == ("default", "avx2") and "NUMBA_CPU_NAME" not in replaced  # the same
    assert environ.items() >= pinned_environment(kernel_pin.cpu_flags()).items()
    if kernel_pin.OPENBLAS_NEEDS <= kernel_pin.cpu_flags():
        assert replaced["OPENBLAS_CORETYPE"] == ("Prescott", "Haswell") and environ["OPENBLAS_CORETYPE"] == "Haswell"
    native = {"POSEINTEGRITY_CPU_DISPATCH": "native", "OPENCV_CPU_DISABLE": "AVX2"}
    assert pin_dispatch(native) == {} and native["OPENCV_CPU_DISABLE"] == "AVX2"


def test_a_replaced_value_is_named_once_by_the_process_that_replaced_it():
    """The importing process warns; a child it starts inherits the pinned value and says nothing."""
    child = "import subprocess, sys; subprocess.run([sys.executable, '-c', 'import poseintegrity'], check=True)"
    script = f"import poseintegrity; {child}"
    env = os.environ | {"ATEN_CPU_CAPABILITY": "default"}
    run = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True)
    assert run.stderr.count("RuntimeWarning") == 1
    assert "ATEN_CPU_CAPABILITY='avx2' in place of your 'default'" in run.stderr


def test_libraries_loaded_above_the_ceiling_are_named():
    cv2 = SimpleNamespace(getCPUFeaturesLine=lambda: "SSE SSE2 *SSE4.1 *AVX *AVX2 *AVX512-SKX")
    numpy_core = SimpleNamespace(__cpu_features__={"X86_V3": True, "X86_V4": True, "AVX512_ICL": False})
    torch = SimpleNamespace(backends=SimpleNamespace(cpu=SimpleNamespace(get_cpu_capability=lambda: "AVX512")))
    openblas = {"libopenblas.so": "SkylakeX", "libscipy_openblas.so": "Haswell"}
    found = unpinned_dispatch({"cv2": cv2, "numpy._core._multiarray_umath": numpy_core, "torch": torch}, openblas,
                              SKX_CPU)
    assert found == ["OpenBLAS (libopenblas.so) runs its SkylakeX kernels", "numpy dispatches X86_V4",
                     "OpenCV dispatches AVX512-SKX", "torch dispatches AVX512"]
    with_ipp = SimpleNamespace(getCPUFeaturesLine=lambda: "SSE SSE2 *AVX2 *AVX512-SKX?",
                               ipp=SimpleNamespace(useIPP=lambda: True, getIppVersion=lambda: "ippIP AVX2 (l9)"))
    assert unpinned_dispatch({"cv2": with_ipp}, {}, SKX_CPU) == ["OpenCV runs Intel IPP (ippIP AVX2 (l9))"]
    capped = SimpleNamespace(getCPUFeaturesLine=lambda: "SSE SSE2 *SSE4.1 *AVX *AVX2 *AVX512-SKX?")
    assert unpinned_dispatch({"cv2": capped}, {}, SKX_CPU) == []
    assert unpinned_dispatch({}, {"libopenblas.so": "Sandybridge"}, AVX_CPU) == []  # no Haswell kernels to pin to
    with pytest.warns(RuntimeWarning, match="OpenCV dispatches AVX512-SKX.*import poseintegrity first"):
        kernel_pin.check_dispatch(modules={"cv2": cv2}, openblas={})
    with pytest.warns(RuntimeWarning, match="OPENBLAS_CORETYPE='Haswell' in place of your 'Prescott'"):
        kernel_pin.check_dispatch({"OPENBLAS_CORETYPE": ("Prescott", "Haswell")}, modules={})


def test_this_process_is_pinned():
    import cv2
    import numpy as np
    import torch

    assert unpinned_dispatch() == []
    assert os.environ["NUMBA_CPU_NAME"] == "haswell"
    if kernel_pin.OPENBLAS_NEEDS <= kernel_pin.cpu_flags():
        assert set(openblas_cores().values()) == {"Haswell"}
    assert not np._core._multiarray_umath.__cpu_features__.get("X86_V4")
    assert torch.backends.cpu.get_cpu_capability() in ("AVX2", "DEFAULT", "NO AVX")
    assert "*AVX512-SKX?" in cv2.getCPUFeaturesLine() or "AVX512-SKX" not in cv2.getCPUFeaturesLine()


def _hash(script: str, env: dict[str, str]) -> str:
    run = subprocess.run([sys.executable, "-c", script], env={**os.environ, **env}, capture_output=True, text=True,
                         check=True)
    return run.stdout.strip()


@pytest.mark.skipif("avx2" not in kernel_pin.cpu_flags(), reason="the AVX2 path needs an AVX2 CPU")
def test_sift_moves_with_the_dispatch_level_unpinned_and_not_pinned():
    native = {"POSEINTEGRITY_CPU_DISPATCH": "native"}
    avx2, avx = {"OPENCV_CPU_DISABLE": ""}, {"OPENCV_CPU_DISABLE": "AVX2"}
    assert _hash(SIFT_HASH, native | avx2) != _hash(SIFT_HASH, native | avx)
    pinned = {"POSEINTEGRITY_CPU_DISPATCH": "pinned"}
    assert _hash(SIFT_HASH, pinned | avx2) == _hash(SIFT_HASH, pinned | avx)


@pytest.mark.skipif("avx512f" not in kernel_pin.cpu_flags(), reason="IPP's AVX-512 level needs an AVX-512 CPU")
def test_sift_moves_with_opencvs_ipp_level_unpinned_and_not_pinned():
    """OpenCV's Intel IPP dispatches by itself (OPENCV_CPU_DISABLE does not reach it): its AVX2 and AVX-512 code
    give other SIFT angles and descriptors; pinned, IPP is off whatever the user asks."""
    native, pinned = {"POSEINTEGRITY_CPU_DISPATCH": "native"}, {"POSEINTEGRITY_CPU_DISPATCH": "pinned"}
    assert _hash(SIFT_HASH, native | {"OPENCV_IPP": "avx2"}) != _hash(SIFT_HASH, native | {"OPENCV_IPP": ""})
    assert _hash(SIFT_HASH, pinned | {"OPENCV_IPP": "avx2"}) == _hash(SIFT_HASH, pinned | {"OPENCV_IPP": ""})


@pytest.mark.skipif(not kernel_pin.OPENBLAS_NEEDS <= kernel_pin.cpu_flags(), reason="Haswell's kernels need AVX2 + FMA")
def test_a_matrix_product_moves_with_openblas_kernels_unpinned_and_not_pinned():
    """Sandybridge's kernels (AVX, no FMA) run on every AVX2 CPU: left to the user's OPENBLAS_CORETYPE, the product
    changes in its last bits; pinned, it is the Haswell kernels' whatever the user asks."""
    native, pinned = {"POSEINTEGRITY_CPU_DISPATCH": "native"}, {"POSEINTEGRITY_CPU_DISPATCH": "pinned"}
    haswell = _hash(DGEMM_HASH, native | {"OPENBLAS_CORETYPE": "Haswell"})
    assert _hash(DGEMM_HASH, native | {"OPENBLAS_CORETYPE": "Sandybridge"}) != haswell
    assert _hash(DGEMM_HASH, pinned | {"OPENBLAS_CORETYPE": "Sandybridge"}) == haswell


NUMBA_ASM = """
import poseintegrity
import numpy as np
from numba import njit

@njit(fastmath=True)
def sum_of_squares(x):
    total = 0.0
    for v in x:
        total += v * v
    return total

sum_of_squares(np.ones(3))
print(sum_of_squares.inspect_asm(sum_of_squares.signatures[0]))
"""


@pytest.mark.skipif("avx512f" not in kernel_pin.cpu_flags(), reason="needs an AVX-512 CPU to show numba's host features")
def test_numba_compiles_for_haswell_not_for_the_host(tmp_path):
    """NUMBA_CPU_NAME=haswell alone still let numba add the host's features: a fastmath loop became AVX-512 (zmm)
    code on an AVX-512 CPU and another summation width than on an AVX2 one. Pinned, it is AVX2 (ymm) code; native,
    the host's."""
    cache = {"NUMBA_CACHE_DIR": str(tmp_path)}
    pinned = _hash(NUMBA_ASM, cache | {"POSEINTEGRITY_CPU_DISPATCH": "pinned"})
    assert "ymm" in pinned and "zmm" not in pinned
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CPU")}
    native = subprocess.run([sys.executable, "-c", NUMBA_ASM], env=env | cache | {"POSEINTEGRITY_CPU_DISPATCH": "native"},
                            capture_output=True, text=True, check=True).stdout
    assert "zmm" in native


def test_numba_loaded_for_the_host_is_named():
    config = SimpleNamespace(CPU_NAME="haswell", CPU_FEATURES=None)
    assert unpinned_dispatch({"numba.core.config": config}, {}, SKX_CPU) == ["numba compiles for this machine's CPU"]
    assert unpinned_dispatch({"numba.core.config": SimpleNamespace(CPU_NAME="haswell", CPU_FEATURES="")}, {},
                             SKX_CPU) == []


@pytest.mark.pipeline  # a notebook's kernel
def test_a_jupyter_kernel_of_the_venv_is_pinned_before_its_first_cell(tmp_path):
    """make install: the venv's kernels import poseintegrity first (IPython's exec_lines), so that a notebook opened in
    JupyterLab whose first cell imports numpy runs the pinned kernels too."""
    from jupyter_client.manager import start_new_kernel

    config = Path(sys.prefix) / "etc" / "ipython" / "ipython_kernel_config.py"
    assert "import poseintegrity" in config.read_text()
    env = {k: v for k, v in os.environ.items()
           if k not in kernel_pin.FIXED and not k.startswith(("OPENCV_", "OPENBLAS_"))}
    env["JUPYTER_PATH"] = str(Path(sys.prefix) / "share" / "jupyter")
    manager, client = start_new_kernel(kernel_name="python3", env=env)
    try:
        out = []
        client.execute_interactive("import numpy\nfrom poseintegrity.kernel_pin import unpinned_dispatch\n"
                                   "print(unpinned_dispatch())", timeout=60,
                                   output_hook=lambda m: out.append(m["content"].get("text", "")))
    finally:
        client.stop_channels()
        manager.shutdown_kernel(now=True)
    assert "".join(out).strip() == "[]"


def test_the_dask_workers_recipe_pins_a_shell_that_never_imported_poseintegrity():
    """README, "Running on a Dask cluster": eval "$(.venv/bin/python -m poseintegrity.kernel_pin)" before starting a
    worker exports the pinned environment."""
    venv_python = sys.executable
    script = (f'eval "$({venv_python} -m poseintegrity.kernel_pin)" && '
              f'{venv_python} -c "import os, cv2; print(os.environ[\'ATEN_CPU_CAPABILITY\'], '
              f'os.environ[\'NUMBA_CPU_NAME\'], repr(os.environ[\'OPENCV_CPU_DISABLE\']))"')
    env = {k: v for k, v in os.environ.items() if k not in kernel_pin.FIXED and k != "OPENCV_CPU_DISABLE"}
    run = subprocess.run(["bash", "-c", script], env=env, capture_output=True, text=True, check=True)
    expected = pinned_environment(kernel_pin.cpu_flags())
    assert run.stdout.split() == ["avx2", "haswell", repr(expected["OPENCV_CPU_DISABLE"])]
    assert run.stderr == ""  # runpy's RuntimeWarning ("found in sys.modules") no more
    exports = subprocess.run([sys.executable, "-m", "poseintegrity.kernel_pin"], env=env, capture_output=True, text=True,
                             check=True).stdout
    assert all(f"export {name}='{value}'" in exports for name, value in expected.items())
