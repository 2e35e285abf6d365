"""Load and validate ``params.yaml`` before any work starts.

Every stage of ``dvc.yaml`` owns one top-level section of ``params.yaml``; the schema of a section lives in the
package :mod:`poseintegrity.params` (``poseintegrity.params.<section>``), beside the other sections' and below the
code that uses it, and is collected here. The ``protocol``
section holds the facts several stages share (:mod:`poseintegrity.params.protocol`); every other section is validated
with it at hand, so that a rule across sections (a tolerance named in ``predict`` must be one of
``protocol.tolerances``) names its key too. A bad value raises :class:`ParamsError` whose message names the
offending key, e.g. ``generate.scenes.2.targets.0``.

A params file may start with ``extends: <path>``: it is then an overlay on that file (relative to the overlay),
merged key by key (mappings recursively, everything else replaced). ``tests/params_tiny.yaml`` is such an overlay
on ``params.yaml``: tests run the real configuration, shrunk. File paths inside params (:data:`ProjectPath`) are
relative to the directory of the file at the root of the ``extends`` chain (the repository for ``params.yaml``).

What reading refuses, each with a :class:`ParamsError` naming the file: bytes that are not UTF-8 (with their
offset and line), invalid YAML, a key written twice in one mapping (YAML would silently keep the last; the error
names the dotted key and both lines), an ``extends`` that is not a file path, names a missing file or closes a
cycle (the chain is named), and a file that is not a mapping.

The project's published values travel with the package: :func:`load_params` without a path reads the packaged copy
``poseintegrity/params.yaml`` (identical to the repository's ``params.yaml``, which a test checks), and the public
functions that take a params section use it when none is given, so ``detect_markers(ir, depth, lut)`` works in a
fresh notebook; a section passed explicitly (or ``load_params("my_params.yaml")``) overrides it. The packaged copy's
file paths (``generate.scapula.mesh``, texture files) are relative to the package directory, where no asset lies:
rendering a world (stage 01) needs the repository and its ``params.yaml``.
"""

from __future__ import annotations

import io
from functools import cache
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ConfigDict, ValidationError

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.params.extract import ExtractParams
from poseintegrity.params.fit import FitParams
from poseintegrity.params.generate import GenerateParams
from poseintegrity.params.parallel import ParallelParams
from poseintegrity.params.population import PopulationParams
from poseintegrity.params.predict import PredictParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.params.track import TrackParams
from poseintegrity.schema import KeyRule


PACKAGED_PARAMS = Path(__file__).with_name("params.yaml")  # a copy of the repository's params.yaml, shipped as package data
PROTOCOL_READERS = ("protocol", "generate", "extract", "fit", "predict")  # sections checked against ``protocol``


class ParamsError(PoseIntegrityError):
    """``params.yaml`` is unreadable or one of its keys has an invalid value."""


class Params(BaseModel):
    """The whole of ``params.yaml``: one section per pipeline stage."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True)  # like every Section (schema.py)

    protocol: ProtocolParams  # stages 01-05: the facts of Windsor et al.'s protocol they share
    generate: GenerateParams  # stage 01
    extract: ExtractParams  # stages 02 and 05
    fit: FitParams  # stage 03
    predict: PredictParams  # stage 04
    track: TrackParams  # stage 06
    population: PopulationParams  # population/dvc.yaml: the worlds the predictors are judged on (issue 49)
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


class _DuplicateKey(yaml.YAMLError):
    """A mapping of a params file holds the same key twice."""


class _UniqueKeyLoader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """PyYAML's safe loader that refuses a key written twice in one mapping (PyYAML keeps the last one silently).
    The check walks the composed node tree before construction, so that the error names the dotted key and both
    lines; a merge key (``<<``) may override what it merges, as YAML intends. On libyaml (``CSafeLoader``, which
    PyYAML's wheels bundle) where there is one: params.yaml is read in 4 ms instead of 23."""

    def get_single_data(self) -> Any:
        node = self.get_single_node()
        if node is None:
            return None
        self._check_unique(node, (), set())
        return self.construct_document(node)

    def _check_unique(self, node: yaml.Node, path: tuple, seen: set[int]) -> None:
        if id(node) in seen:  # an alias: its node was checked where its anchor stands
            return
        seen.add(id(node))
        if isinstance(node, yaml.MappingNode):
            first_line: dict[Any, int] = {}
            for key_node, value_node in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    self._check_unique(value_node, path, seen)
                    continue
                key = self.construct_object(key_node) if isinstance(key_node, yaml.ScalarNode) else None
                line = key_node.start_mark.line + 1
                if key is not None:
                    try:
                        if key in first_line:
                            dotted = ".".join(map(str, (*path, key)))
                            raise _DuplicateKey(f"line {line}: key {dotted!r} is written twice (lines "
                                                f"{first_line[key]} and {line}); YAML would keep only the last")
                        first_line[key] = line
                    except TypeError:  # an unhashable key: construction names it
                        pass
                self._check_unique(value_node, (*path, key), seen)
        elif isinstance(node, yaml.SequenceNode):
            for index, item in enumerate(node.value):
                self._check_unique(item, (*path, index), seen)


def _read_yaml(path: Path) -> Any:
    """One params file parsed (UTF-8 YAML, each key once per mapping); :class:`ParamsError` naming the file."""
    try:
        data = path.read_bytes()
    except OSError as error:
        raise ParamsError(f"cannot read params file {path}: {error.strerror}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data[:error.start].count(b"\n") + 1
        raise ParamsError(f"{path} is not UTF-8 text: byte 0x{data[error.start]:02x} at offset {error.start} "
                          f"(line {line}) cannot be decoded; save the file as UTF-8") from None
    stream = io.StringIO(text)
    stream.name = str(path)  # YAML's own errors name the file, not "<unicode string>"
    loader = _UniqueKeyLoader(stream)
    try:
        return loader.get_single_data()
    except _DuplicateKey as error:
        raise ParamsError(f"{path}: {error}") from None
    except yaml.YAMLError as error:
        raise ParamsError(f"{path} is not valid YAML: {error}") from None
    finally:
        loader.dispose()


def read_raw(path: str | Path) -> tuple[Any, Path]:
    """The parsed params file with its ``extends`` chain merged, and the directory its paths are relative to.

    ``extends`` must be a path (text, relative to the file that names it) of an existing params file that is a
    mapping; a chain that comes back to a file already in it is refused, naming the chain."""
    return _read_chain(Path(path), ())


def _read_chain(path: Path, chain: tuple[Path, ...]) -> tuple[Any, Path]:
    resolved = path.resolve()
    if resolved in chain:
        names = " -> ".join(str(p) for p in (*chain, resolved))
        raise ParamsError(f"{chain[-1]}: extends makes a cycle: {names}")
    raw = _read_yaml(path)
    if not (isinstance(raw, dict) and "extends" in raw):
        return raw, resolved.parent
    target = raw.pop("extends")
    if not isinstance(target, str) or not target.strip():
        raise ParamsError(f"{path}: extends must be the path of a params file (text), got "
                          f"{type(target).__name__} {target!r:.80}")
    base_path = path.parent / target
    if not base_path.is_file():
        raise ParamsError(f"{path}: extends {target!r}: no such file {base_path}")
    base, base_dir = _read_chain(base_path, (*chain, resolved))
    if not isinstance(base, dict):
        raise ParamsError(f"{path}: extends {target!r}, which is not a mapping of sections "
                          f"(got {type(base).__name__})")
    return merge(base, raw), base_dir


def load_params(path: str | Path | None = None) -> Params:
    """Read and validate a whole params file (``params.yaml`` or an overlay on it); without a path, the project's
    published defaults (:func:`default_params`)."""
    if path is None:
        return default_params()
    raw, base_dir = read_raw(path)
    return parse_params(raw, source=str(path), base_dir=base_dir)


@cache
def default_params() -> Params:
    """The packaged copy of ``params.yaml`` (:data:`PACKAGED_PARAMS`), validated once per process: the default of
    every public function that takes a params section. Frozen, so one instance is shared safely."""
    raw, base_dir = read_raw(PACKAGED_PARAMS)
    return parse_params(raw, source=str(PACKAGED_PARAMS), base_dir=base_dir)


def published(dotted: str) -> Any:
    """The section or value of the packaged ``params.yaml`` at ``dotted`` (e.g. ``"track.detection"``): what a
    public function that takes a params section (``detect_markers(ir, depth, lut, detection=None)``) uses when none
    is given."""
    value: Any = default_params()
    for part in dotted.split("."):
        value = getattr(value, part)
    return value


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
