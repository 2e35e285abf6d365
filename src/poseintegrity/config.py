"""Load and validate ``params.yaml`` before any work starts.

Every stage of ``dvc.yaml`` owns one top-level section of ``params.yaml``; the schema of a section lives
next to the code that uses it (``poseintegrity.<subpackage>.params``) and is collected here. A bad value
raises :class:`ParamsError` whose message names the offending key, e.g. ``generate.scenes.2.targets.0``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ConfigDict, ValidationError

from poseintegrity.scenes.params import GenerateParams


class ParamsError(ValueError):
    """``params.yaml`` is unreadable or one of its keys has an invalid value."""


class Params(BaseModel):
    """The whole of ``params.yaml``: one section per pipeline stage."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    generate: GenerateParams


def _format_errors(error: ValidationError) -> str:
    lines = []
    for item in error.errors():
        key = ".".join(str(part) for part in item["loc"]) or "<root>"
        lines.append(f"  {key}: {item['msg']} (got {item.get('input')!r:.80})")
    return "\n".join(lines)


def parse_params(raw: dict[str, Any], source: str = "params") -> Params:
    """Validate a parsed YAML mapping; raise :class:`ParamsError` naming every bad key."""
    if not isinstance(raw, dict):
        raise ParamsError(f"{source}: expected a mapping of sections, got {type(raw).__name__}")
    try:
        return Params.model_validate(raw)
    except ValidationError as error:
        raise ParamsError(f"{source} has invalid values:\n{_format_errors(error)}") from None


def load_params(path: str | Path = "params.yaml") -> Params:
    """Read and validate a params file (``params.yaml`` or the tiny test variant)."""
    path = Path(path)
    try:
        raw = yaml.safe_load(path.read_text())
    except OSError as error:
        raise ParamsError(f"cannot read params file {path}: {error.strerror}") from None
    except yaml.YAMLError as error:
        raise ParamsError(f"{path} is not valid YAML: {error}") from None
    return parse_params(raw, source=str(path))
