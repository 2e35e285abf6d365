"""Which world heads a stage's metrics, and which one is held out.

Stages 02-05 process every world of the datasets (meta.json / index ``world``) by the same code. The first world of
:func:`world_order` is the one whose figures stand at the top of each metrics file and in the paper's tables
(Tables I-III: its operating points are chosen on it); the second, if any, is held out: those operating points are
applied to it unchanged (``reports/metrics/validation.json``); any further world is reported under ``worlds`` like
the held-out one. The rendered worlds are ``main`` and ``validation``; recorded datasets may name theirs freely
(default ``recorded``, docs/recorded-data.md).
"""

from __future__ import annotations

from collections.abc import Iterable

FIRST, SECOND = "main", "validation"  # the rendered worlds' names, first and second whenever present


def world_order(worlds: Iterable[str]) -> list[str]:
    """The distinct ``worlds``: ``main``, ``validation``, then the others in name order."""
    return sorted(set(worlds), key=lambda world: (world != FIRST, world != SECOND, world))
