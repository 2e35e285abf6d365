"""The CPU dispatch pin (poseintegrity.dispatch): every library capped at AVX2 by the package import, whatever the
user's environment asks, in this process, in the stage runner's kernel and in a shell of the Dask recipe."""

import os
import subprocess
import sys
import textwrap
from types import SimpleNamespace

import pytest

from poseintegrity import dispatch
from poseintegrity.dispatch import dispatch_above_ceiling, pin_dispatch, pinned_environment

AVX2_CPU = frozenset({"sse4_2", "avx", "avx2", "fma"})
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


def test_an_avx512_cpu_disables_opencvs_avx512_group_and_an_avx2_cpu_names_none():
    assert pinned_environment(SKX_CPU)["OPENCV_CPU_DISABLE"] == "AVX512-SKX"
    assert pinned_environment(AVX2_CPU)["OPENCV_CPU_DISABLE"] == ""  # set, so that a user's value cannot lower it
    for env in (pinned_environment(SKX_CPU), pinned_environment(AVX2_CPU)):
        assert env["ATEN_CPU_CAPABILITY"] == "avx2" and env["MKL_CBWR"].startswith("AVX2")
        assert env["NPY_DISABLE_CPU_FEATURES"].split() == ["X86_V4", "AVX512_ICL", "AVX512_SPR"]
        assert env["NUMBA_CPU_NAME"] == "haswell" and env["ONEDNN_MAX_CPU_ISA"] == "AVX2"


def test_the_pin_replaces_a_users_values_unless_switched_to_native():
    environ = {"OPENCV_CPU_DISABLE": "AVX2", "ATEN_CPU_CAPABILITY": "default"}
    pinned = pin_dispatch(environ)
    assert environ["ATEN_CPU_CAPABILITY"] == "avx2" and environ["OPENCV_CPU_DISABLE"] != "AVX2"
    assert pinned == {key: environ[key] for key in pinned}
    native = {"POSEINTEGRITY_CPU_DISPATCH": "native", "OPENCV_CPU_DISABLE": "AVX2"}
    assert pin_dispatch(native) == {} and native["OPENCV_CPU_DISABLE"] == "AVX2"


def test_libraries_loaded_above_the_ceiling_are_named():
    cv2 = SimpleNamespace(getCPUFeaturesLine=lambda: "SSE SSE2 *SSE4.1 *AVX *AVX2 *AVX512-SKX")
    numpy_core = SimpleNamespace(__cpu_features__={"X86_V3": True, "X86_V4": True, "AVX512_ICL": False})
    torch = SimpleNamespace(backends=SimpleNamespace(cpu=SimpleNamespace(get_cpu_capability=lambda: "AVX512")))
    found = dispatch_above_ceiling({"cv2": cv2, "numpy._core._multiarray_umath": numpy_core, "torch": torch})
    assert found == ["numpy dispatches X86_V4", "OpenCV dispatches AVX512-SKX", "torch dispatches AVX512"]
    capped = SimpleNamespace(getCPUFeaturesLine=lambda: "SSE SSE2 *SSE4.1 *AVX *AVX2 *AVX512-SKX?")
    assert dispatch_above_ceiling({"cv2": capped}) == []
    with pytest.warns(RuntimeWarning, match="OpenCV dispatches AVX512-SKX.*import poseintegrity first"):
        dispatch.check_dispatch({"cv2": cv2})


def test_this_process_is_pinned():
    import cv2
    import numpy as np
    import torch

    assert dispatch_above_ceiling() == []
    assert os.environ["NUMBA_CPU_NAME"] == "haswell"
    assert not np._core._multiarray_umath.__cpu_features__.get("X86_V4")
    assert torch.backends.cpu.get_cpu_capability() in ("AVX2", "DEFAULT", "NO AVX")
    assert "*AVX512-SKX?" in cv2.getCPUFeaturesLine() or "AVX512-SKX" not in cv2.getCPUFeaturesLine()


def _sift_hash(env: dict[str, str]) -> str:
    run = subprocess.run([sys.executable, "-c", SIFT_HASH], env={**os.environ, **env}, capture_output=True,
                         text=True, check=True)
    return run.stdout.strip()


@pytest.mark.skipif("avx2" not in dispatch.cpu_flags(), reason="the AVX2 path needs an AVX2 CPU")
def test_sift_moves_with_the_dispatch_level_unpinned_and_not_pinned():
    native = {"POSEINTEGRITY_CPU_DISPATCH": "native"}
    assert _sift_hash(native | {"OPENCV_CPU_DISABLE": ""}) != _sift_hash(native | {"OPENCV_CPU_DISABLE": "AVX2"})
    pinned = {"POSEINTEGRITY_CPU_DISPATCH": "pinned"}
    assert _sift_hash(pinned | {"OPENCV_CPU_DISABLE": ""}) == _sift_hash(pinned | {"OPENCV_CPU_DISABLE": "AVX2"})


def test_the_dask_workers_recipe_pins_a_shell_that_never_imported_poseintegrity():
    """README, "Running on a Dask cluster": eval "$(.venv/bin/python -m poseintegrity.dispatch)" before starting a
    worker exports the pinned environment."""
    venv_python = sys.executable
    script = (f'eval "$({venv_python} -m poseintegrity.dispatch)" && '
              f'{venv_python} -c "import os, cv2; print(os.environ[\'ATEN_CPU_CAPABILITY\'], '
              f'os.environ[\'NUMBA_CPU_NAME\'], repr(os.environ[\'OPENCV_CPU_DISABLE\']))"')
    env = {k: v for k, v in os.environ.items() if k not in dispatch.FIXED and k != "OPENCV_CPU_DISABLE"}
    run = subprocess.run(["bash", "-c", script], env=env, capture_output=True, text=True, check=True)
    expected = pinned_environment(dispatch.cpu_flags())
    assert run.stdout.split() == ["avx2", "haswell", repr(expected["OPENCV_CPU_DISABLE"])]
