"""Timing helper shared by the benchmark scripts (run them from the repository root)."""

import time
from collections.abc import Callable

import numpy as np


def paired_medians(reference: Callable[[], object], subject: Callable[[], object], repeats: int) -> tuple[float, float]:
    """Median seconds of reference and subject, timed alternately so that both see the same machine load."""
    times = np.empty((repeats, 2))
    for i in range(repeats):
        for j, fn in enumerate((reference, subject)):
            start = time.perf_counter()
            fn()
            times[i, j] = time.perf_counter() - start
    return float(np.median(times[:, 0])), float(np.median(times[:, 1]))
