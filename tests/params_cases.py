"""The helper behind every table of bad parameter values: set one dotted key of a params mapping, validate the
whole file as a stage would, and return the error message (which must name the key before any work)."""

from __future__ import annotations

import copy
import json
from typing import Any

import pytest

from poseintegrity.config import ParamsError, parse_params


def with_value(raw: dict, dotted_key: str, value: Any) -> dict:
    """A deep copy of ``raw`` with ``dotted_key`` (``"generate.scenes.0.targets"``: list indices as numbers) set."""
    raw = copy.deepcopy(raw)
    *parents, leaf = dotted_key.split(".")
    node: Any = raw
    for part in parents:
        node = node[int(part)] if isinstance(node, list) else node.setdefault(part, {})
    node[int(leaf) if isinstance(node, list) else leaf] = value
    return raw


VALID: set[str] = set()  # the raw mappings (as JSON) already validated in this process


def refusal(raw: dict, dotted_key: str, value: Any) -> str:
    """The :class:`ParamsError` message for ``raw`` with ``dotted_key`` set to ``value`` (fails if it is accepted)."""
    unchanged = json.dumps(raw, sort_keys=True, default=str)
    if unchanged not in VALID:  # valid before the change: the error below is the change's (once per mapping)
        parse_params(raw)
        VALID.add(unchanged)
    with pytest.raises(ParamsError) as info:
        parse_params(with_value(raw, dotted_key, value))
    return str(info.value)
