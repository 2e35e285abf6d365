"""Reading one value of the metrics files (``reports/metrics/<stage>.json``, read into a dict by stage name)."""

from __future__ import annotations

MISSING = object()  # the stage has not run, or its metrics lack the key


def lookup(metrics: dict[str, dict], stage: str, key: str):
    """The value at dotted ``key`` of a stage's metrics; :data:`MISSING` when the stage or key is missing
    (None is a value: the stage ran and found nothing, e.g. no operating point with zero incursions)."""
    value = metrics.get(stage, MISSING)
    for part in key.split("."):
        if not isinstance(value, dict) or part not in value:
            return MISSING
        value = value[part]
    return value


def absent(metrics: dict[str, dict], stage: str) -> str:
    """The word for a value :func:`lookup` did not find: "not run" (the stage wrote no metrics) or "not measured"
    (it ran, and its metrics lack the key: an older stage, or nothing of the kind in this run)."""
    return "not measured" if stage in metrics else "not run"
