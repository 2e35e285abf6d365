"""Writing a stage's metrics file (``reports/metrics/<stage>.json``, read by ``dvc metrics`` and the summary).

One writer for every stage: numpy scalars become plain numbers, NaN and inf become JSON null (``json.dumps`` would
write the invalid tokens NaN / Infinity), and the file is replaced atomically, so an interrupted stage leaves no
metrics file that looks complete.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from poseintegrity.atomic_write import write_text_atomically


def json_ready(value: Any) -> Any:
    """Nested dicts/lists with numpy scalars and NaN/inf turned into plain JSON values (NaN -> null)."""
    if isinstance(value, dict):
        return {str(key): json_ready(item) for key, item in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [json_ready(item) for item in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if np.isfinite(value) else None
    return value


def write_metrics(path: str | Path, metrics: dict[str, Any]) -> None:
    """Write ``metrics`` (nested dicts / lists of numbers, strings, bools) as indented, key-sorted JSON, atomically
    (its folder made if missing; a full disk: :class:`~poseintegrity.atomic_write.DiskFullError` naming the file)."""
    write_text_atomically(path, json.dumps(json_ready(metrics), indent=2, sort_keys=True, allow_nan=False) + "\n")


def metrics_differences(before: Any, after: Any, skip: frozenset[str] = frozenset(), rtol: float = 0.0, path: str = "") -> list[str]:
    """Where two metrics (as :func:`json_ready` gives them, or read back from the file) differ: one line per
    differing leaf ("key/sub: before -> after"), empty if they agree.  Keys in ``skip`` (at any depth, e.g. the
    machine-dependent timings) are left out; numbers agree within the relative tolerance ``rtol`` (0: exactly),
    null (NaN) agrees with null; everything else must be equal."""
    if isinstance(before, dict) and isinstance(after, dict):
        keys = sorted((set(before) | set(after)) - skip)
        return [line for key in keys for line in metrics_differences(before.get(key, "<missing>"), after.get(key, "<missing>"),
                                                                        skip, rtol, f"{path}/{key}")]
    if isinstance(before, list) and isinstance(after, list) and len(before) == len(after):
        return [line for i, (a, b) in enumerate(zip(before, after)) for line in metrics_differences(a, b, skip, rtol, f"{path}[{i}]")]
    numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (before, after))
    if before == after or (numbers and abs(after - before) <= rtol * max(abs(before), abs(after))):
        return []
    return [f"{path or '/'}: {before!r} -> {after!r}"]
