"""Named random generators: one seed from params.yaml, one generator per named piece of work.

Every stage draws its random numbers from generators keyed by the stage's seed and by what the draw is for (a scene
index, a dataset name, a fit's model and k, an experiment's name). The same key gives the same draws in every
process, in every order of work and with any number of workers, and another key never shares its stream.
"""

from __future__ import annotations

import zlib

import numpy as np


def keyed_rng(seed: int, *key: str | int) -> np.random.Generator:
    """``numpy.random.default_rng([seed, *key])`` with each string of ``key`` replaced by its CRC-32 (an int that
    is the same in every process, unlike ``hash``). seed and int keys : >= 0.

    numpy's SeedSequence pads the entropy with zero words, so trailing zeros of a key do not change the stream
    (``keyed_rng(s, "a", 0)`` draws as ``keyed_rng(s, "a")``): a stage's keys must differ elsewhere, as they do
    by having the same length within a stage."""
    return np.random.default_rng([seed, *(zlib.crc32(k.encode()) if isinstance(k, str) else k for k in key)])
