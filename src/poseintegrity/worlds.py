"""Which world heads a stage's metrics, and which one is held out.

Stages 02-05 process every world of the datasets (meta.json / index ``world``) by the same code. The *primary*
world is the one whose figures stand at the top of each metrics file and in the paper's tables (Tables I-III: its
operating points are chosen on it); the *held-out* world is the one those operating points are applied to unchanged
(``reports/metrics/validation.json``); any further world is reported under ``worlds`` like the held-out one. The
rendered worlds are ``main`` and ``validation``; recorded datasets may name theirs freely (default ``recorded``,
docs/recorded-data.md): ``main`` comes first, then ``validation``, then the others by name.
"""

from __future__ import annotations

from collections.abc import Iterable

from poseintegrity.errors import ArgumentError

PRIMARY, HELD_OUT = "main", "validation"  # the rendered worlds' names, first and second whenever present


def world_order(worlds: Iterable[str]) -> list[str]:
    """The distinct ``worlds``: ``main``, ``validation``, then the others in name order. The first is the primary
    world, the second (if any) the held-out one."""
    return sorted(set(worlds), key=lambda world: (world != PRIMARY, world != HELD_OUT, world))


def primary_world(worlds: Iterable[str]) -> str:
    """The world whose figures head the metrics (:func:`world_order`'s first); ArgumentError when there is none."""
    order = world_order(worlds)
    if not order:
        raise ArgumentError("worlds: none given (the tables hold no rows)")
    return order[0]


def held_out_world(worlds: Iterable[str]) -> str | None:
    """The world the primary world's operating points are applied to (:func:`world_order`'s second), or None."""
    order = world_order(worlds)
    return order[1] if len(order) > 1 else None
