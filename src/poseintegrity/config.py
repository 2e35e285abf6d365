"""Load and validate ``params.yaml`` before any work starts.

Every stage of ``dvc.yaml`` owns one top-level section of ``params.yaml``; the schema of a section lives
next to the code that uses it (``poseintegrity.<subpackage>.params``) and is collected here. The ``protocol``
section holds the facts several stages share (:mod:`poseintegrity.protocol`); every other section is validated
with it at hand, so that a rule across sections (a tolerance named in ``predict`` must be one of
``protocol.tolerances``) names its key too. A bad value raises :class:`ParamsError` whose message names the
offending key, e.g. ``generate.scenes.2.targets.0``.

A params file may start with ``extends: <path>``: it is then an overlay on that file (relative to the overlay),
merged key by key (mappings recursively, everything else replaced). ``tests/params_tiny.yaml`` is such an overlay
on ``params.yaml``: tests run the real configuration, shrunk. File paths inside params (:data:`ProjectPath`) are
relative to the directory of the file at the root of the ``extends`` chain (the repository for ``params.yaml``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ConfigDict, ValidationError

from poseintegrity.artifact_models.params import FitParams
from poseintegrity.errors import PoseIntegrityError
from poseintegrity.localization.params import ExtractParams
from poseintegrity.parallel import ParallelParams
from poseintegrity.prediction.params import PredictParams
from poseintegrity.protocol import ProtocolParams
from poseintegrity.scenes.params import GenerateParams
from poseintegrity.schema import KeyRule
from poseintegrity.tracking.params import TrackParams


PROTOCOL_READERS = ("protocol", "generate", "extract", "fit", "predict")  # sections checked against ``protocol``


class ParamsError(PoseIntegrityError):
    """``params.yaml`` is unreadable or one of its keys has an invalid value."""


class Params(BaseModel):
    """The whole of ``params.yaml``: one section per pipeline stage."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    protocol: ProtocolParams  # stages 01-05: the facts of Windsor et al.'s protocol they share
    generate: GenerateParams  # stage 01
    extract: ExtractParams  # stages 02 and 05
    fit: FitParams  # stage 03
    predict: PredictParams  # stage 04
    track: TrackParams  # stage 06
    parallel: ParallelParams  # every stage: where the per-frame and per-dataset tasks run


def _format_errors(error: ValidationError, prefix: tuple = ()) -> str:
    """One line per bad key: ``  <dotted key>: <why> (got <value>)``. A rule between keys (:class:`KeyRule`) names
    the key it carries; the whole section it was checked on is not repeated."""
    lines = []
    for item in error.errors():
        rule = item.get("ctx", {}).get("error")
        loc = (*prefix, *item["loc"], *(rule.key.split(".") if isinstance(rule, KeyRule) else ()))
        key = ".".join(str(part) for part in loc) or "<root>"
        value = item.get("input")
        got = "" if isinstance(value, dict) else f" (got {value!r:.80})"
        message = str(rule) if isinstance(rule, KeyRule) else item["msg"]
        lines.append(f"  {key}: {message}{got}")
    return "\n".join(lines)


def _protocol(raw: Any, source: str) -> ProtocolParams:
    """The validated ``protocol`` section, which every other section is checked against."""
    if not isinstance(raw, dict) or "protocol" not in raw:
        raise ParamsError(f"{source}: section 'protocol' is missing")
    try:
        return ProtocolParams.model_validate(raw["protocol"])
    except ValidationError as error:
        raise ParamsError(f"{source} has invalid values:\n{_format_errors(error, ('protocol',))}") from None


def parse_params(raw: dict[str, Any], source: str = "params", base_dir: Path | None = None) -> Params:
    """Validate a parsed YAML mapping; raise :class:`ParamsError` naming every bad key."""
    if not isinstance(raw, dict):
        raise ParamsError(f"{source}: expected a mapping of sections, got {type(raw).__name__}")
    context = {"base_dir": base_dir, "protocol": _protocol(raw, source)}
    try:
        return Params.model_validate(raw, context=context)
    except ValidationError as error:
        raise ParamsError(f"{source} has invalid values:\n{_format_errors(error)}") from None


def merge(base: Any, overlay: Any) -> Any:
    """``overlay`` on ``base``: mappings merged key by key, recursively; any other overlay value replaces."""
    if isinstance(base, dict) and isinstance(overlay, dict):
        return {**base, **{key: merge(base.get(key), value) for key, value in overlay.items()}}
    return overlay


def _read_yaml(path: Path) -> Any:
    try:
        return yaml.safe_load(path.read_text())
    except OSError as error:
        raise ParamsError(f"cannot read params file {path}: {error.strerror}") from None
    except yaml.YAMLError as error:
        raise ParamsError(f"{path} is not valid YAML: {error}") from None


def read_raw(path: str | Path) -> tuple[Any, Path]:
    """The parsed params file with its ``extends`` chain merged, and the directory its paths are relative to."""
    path = Path(path)
    raw = _read_yaml(path)
    if not (isinstance(raw, dict) and "extends" in raw):
        return raw, path.resolve().parent
    base, base_dir = read_raw(path.parent / str(raw.pop("extends")))
    return merge(base, raw), base_dir


def load_params(path: str | Path = "params.yaml") -> Params:
    """Read and validate a whole params file (``params.yaml`` or an overlay on it)."""
    raw, base_dir = read_raw(path)
    return parse_params(raw, source=str(path), base_dir=base_dir)


def load_section(path: str | Path, section: str) -> BaseModel:
    """Read and validate one stage's section (with ``protocol`` if the section reads it, see
    :data:`PROTOCOL_READERS`): a stage is not stopped by another stage's bad values (DVC tracks each stage's own
    sections too)."""
    if section not in Params.model_fields:
        raise ParamsError(f"unknown params section {section!r}; sections: {list(Params.model_fields)}")
    raw, base_dir = read_raw(path)
    if not isinstance(raw, dict) or section not in raw:
        raise ParamsError(f"{path}: section {section!r} is missing")
    protocol = _protocol(raw, str(path)) if section in PROTOCOL_READERS else None
    try:
        return Params.model_fields[section].annotation.model_validate(
            raw[section], context={"base_dir": base_dir, "protocol": protocol})
    except ValidationError as error:
        raise ParamsError(f"{path} has invalid values:\n{_format_errors(error, (section,))}") from None
