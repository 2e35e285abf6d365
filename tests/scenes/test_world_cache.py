"""The worlds a process builds for its shots (scenes/world_cache.py): a build gives its temporaries back to the
kernel."""

import os
import subprocess
import sys
import textwrap


# A world build that frees 200 MB of 1 MB temporaries (below the mmap threshold: heap memory), under the Makefile's
# malloc settings, which keep freed heap memory for reuse; the resident size before the build, after it, and after
# giving back by hand what was still resident.
BUILD_RSS = textwrap.dedent("""
    import psutil, numpy as np
    from poseintegrity.params.generate import GenerateParams
    from poseintegrity.params.protocol import ProtocolParams
    from poseintegrity.scenes import world_cache
    rss = lambda: psutil.Process().memory_info().rss / 1e6
    def build(*args):
        temporaries = [np.ones(125_000) for _ in range(200)]
        del temporaries
        return "world"
    world_cache._build_world = build
    before = rss()
    world_cache.world(GenerateParams.model_construct(), ProtocolParams.model_construct(), 0, "arc")
    after = rss()
    world_cache.give_back_freed_memory()
    print(before, after, rss())
""")


def test_building_a_world_gives_its_temporaries_back_to_the_kernel():
    """loky restarts a worker whose memory grew by 300 MB past its first task; the temporaries of a world build
    (~130 MB at paper scale) used to stay resident under the Makefile's malloc settings, and every stage-01 run lost
    both render workers that way (world_cache.give_back_freed_memory)."""
    env = os.environ | {"MALLOC_MMAP_THRESHOLD_": "33554432", "MALLOC_TRIM_THRESHOLD_": "1073741824"}
    run = subprocess.run([sys.executable, "-c", BUILD_RSS], env=env, capture_output=True, text=True, check=True)
    before, after, trimmed = map(float, run.stdout.split())
    assert after - before < 50 and after - trimmed < 20  # MB: the 200 MB are not resident after the build
