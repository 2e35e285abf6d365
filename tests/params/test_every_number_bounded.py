"""The params schema as a whole: every number params.yaml can hold is strict (YAML's ``true`` or the text "3" is
not a number, 2.0 is not a count) and bounded on both sides, its reason beside the bound.

The walker below visits every model reachable from :class:`poseintegrity.config.Params` (through nested models,
lists, tuples, dicts, unions and ``Annotated``) and lists each place a number can stand (a field, or an entry of a
tuple, list or dict), with the bounds pydantic enforces there (``Field(ge/gt/le/lt)`` or ``annotated_types``
metadata). It knows every type the schema uses and fails on one it does not, so that it cannot pass by not looking.
"""

from __future__ import annotations

import inspect
import math
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal, Optional, Union

import annotated_types
import pytest
from pydantic import BaseModel, Field
from pydantic.fields import FieldInfo

from poseintegrity.config import Params, ParamsError, load_params, parse_params
from poseintegrity.schema import FromList, Section

ROOT = Path(__file__).resolve().parents[2]

# Numeric places allowed without both bounds, each with its reason. Empty: every number of params.yaml has both
# (seeds through ``schema.Seed``: 0 <= seed < 2**63, what numpy's SeedSequence takes). Add a place here only with
# the reason no bound can be meant.
ALLOWED_UNBOUNDED: dict[str, str] = {}


@dataclass
class Place:
    """One place a number can stand: ``module.Model.field`` plus ``[i]`` for a tuple entry, ``[]`` for a list or
    dict entry (e.g. ``tracking.params.TrackParams.markers_body[][0]``)."""

    path: str
    type: type
    lower: float | None = None
    upper: float | None = None
    lax: bool = False  # Strict(False) on the number itself: bools and text would be accepted
    metadata: list = field(default_factory=list, repr=False)


def _flatten(metadata: list) -> list:
    """Pydantic keeps a ``Field(...)`` inside ``Annotated`` as a FieldInfo whose ``metadata`` holds the
    annotated_types constraints; spread those out."""
    flat = []
    for item in metadata:
        flat.extend(_flatten(item.metadata) if isinstance(item, FieldInfo) else [item])
    return flat


def _bounds(metadata: list) -> tuple[float | None, float | None, bool]:
    lower = upper = None
    lax = False
    for item in _flatten(metadata):
        if isinstance(item, (annotated_types.Ge, annotated_types.Gt)):
            lower = item.ge if isinstance(item, annotated_types.Ge) else item.gt
        elif isinstance(item, (annotated_types.Le, annotated_types.Lt)):
            upper = item.le if isinstance(item, annotated_types.Le) else item.lt
        elif isinstance(item, annotated_types.Interval):
            lower = next((b for b in (item.ge, item.gt) if b is not None), lower)
            upper = next((b for b in (item.le, item.lt) if b is not None), upper)
        elif getattr(item, "strict", None) is False:
            lax = True
    return lower, upper, lax


def _walk(path: str, annotation: Any, metadata: list, places: list[Place], models: dict[type, None]) -> None:
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        inner, *extra = typing.get_args(annotation)
        _walk(path, inner, [*metadata, *extra], places, models)
    elif annotation is bool or annotation in (str, Path, type(None)) or origin is Literal:
        return  # bool before int: a bool is an int to Python, not a number to params.yaml
    elif annotation in (int, float):
        lower, upper, lax = _bounds(metadata)
        places.append(Place(path, annotation, lower, upper, lax, _flatten(metadata)))
    elif inspect.isclass(annotation) and issubclass(annotation, BaseModel):
        walk_model(annotation, places, models)
    elif origin in (Union, types.UnionType):
        for arg in typing.get_args(annotation):
            _walk(path, arg, metadata, places, models)  # Field(ge=2, le=100) on ``int | None`` bounds the int
    elif origin is tuple:
        args = typing.get_args(annotation)
        if len(args) == 2 and args[1] is Ellipsis:
            _walk(f"{path}[]", args[0], [], places, models)
        else:
            for index, arg in enumerate(args):
                _walk(f"{path}[{index}]", arg, [], places, models)
    elif origin in (list, set, frozenset) or origin is typing.get_origin(typing.Sequence[int]):
        _walk(f"{path}[]", typing.get_args(annotation)[0], [], places, models)
    elif origin is dict:
        key, value = typing.get_args(annotation)
        _walk(f"{path}{{key}}", key, [], places, models)
        _walk(f"{path}[]", value, [], places, models)
    else:
        raise AssertionError(f"{path}: the walker does not know the type {annotation!r}; teach it, so that no "
                             f"number hides behind it")


def walk_model(model: type[BaseModel], places: list[Place], models: dict[type, None]) -> None:
    """Every numeric place of ``model`` and the models it reaches (each model once, in ``models``)."""
    if model in models:
        return
    models[model] = None
    for name, info in model.model_fields.items():
        module = model.__module__.removeprefix("poseintegrity.")  # the place names its module too
        _walk(f"{module}.{model.__name__}.{name}", info.annotation, list(info.metadata), places, models)


def numeric_places(root: type[BaseModel] = Params) -> tuple[list[Place], list[type]]:
    places: list[Place] = []
    models: dict[type, None] = {}
    walk_model(root, places, models)
    return places, list(models)


def unbounded(places: list[Place]) -> list[str]:
    return [p.path for p in places if p.lower is None or p.upper is None
            or not (math.isfinite(p.lower) and math.isfinite(p.upper))]


PLACES, MODELS = numeric_places()


def test_walker_sees_the_whole_schema():
    assert len(PLACES) > 100, f"only {len(PLACES)} numeric places found: the walker is not looking"
    assert {int, float} == {p.type for p in PLACES}
    sections = {m for m in _subclasses(Section) if m.__module__.startswith("poseintegrity.")}
    assert sections - set(MODELS) == set(), "Section models params.yaml cannot reach: the walker would miss them"
    assert all(m in sections for m in MODELS if m is not Params), "every section model derives from Section"


def _subclasses(cls: type) -> set[type]:
    return {sub for direct in cls.__subclasses__() for sub in {direct, *_subclasses(direct)}}


def test_every_number_has_both_bounds():
    missing = [path for path in unbounded(PLACES) if path not in ALLOWED_UNBOUNDED]
    assert missing == [], f"numbers without a lower and an upper bound ({len(missing)}): {missing}"
    assert set(ALLOWED_UNBOUNDED) <= {p.path for p in PLACES}, "stale entries in ALLOWED_UNBOUNDED"


def test_every_number_is_strict():
    assert all(m.model_config.get("strict") for m in MODELS), "a model without strict numbers"
    assert [p.path for p in PLACES if p.lax] == []


class _Nested(Section):
    count: int = Field(ge=0)  # no upper bound


class _Unbounded(Section):
    """A deliberately careless model: the walker must find each unbounded number, wherever it hides."""

    good: float = Field(ge=0, le=1)
    no_upper: float = Field(gt=0)
    bare: int
    inside_tuple: Annotated[tuple[Annotated[float, Field(ge=0, le=1)], float], FromList]
    inside_list: list[Annotated[float, Field(le=5)]]
    inside_dict: dict[str, int]
    optional: Optional[Annotated[float, Field(ge=0)]]
    union_model: Union[_Nested, None]
    infinite: float = Field(ge=0, le=math.inf)
    flag: bool  # not a number


def test_walker_catches_a_careless_model():
    places, models = numeric_places(_Unbounded)
    assert set(models) == {_Unbounded, _Nested}
    assert [path.removeprefix(f"{__name__}.") for path in unbounded(places)] == [
        "_Unbounded.no_upper", "_Unbounded.bare", "_Unbounded.inside_tuple[1]", "_Unbounded.inside_list[]",
        "_Unbounded.inside_dict[]", "_Unbounded.optional", "_Nested.count", "_Unbounded.infinite"]


def test_walker_refuses_a_type_it_does_not_know():
    class Odd(Section):
        value: complex

    with pytest.raises(AssertionError, match="does not know"):
        numeric_places(Odd)


# Strict numbers, on the real file: YAML's true, the text "3" and 2.0 for a count were accepted before (212,
# 290 and 86 of the tiny params' 290 numbers); an int where a float is expected stays accepted (JSON-style).
@pytest.mark.parametrize("key, value, message", [
    ("generate.camera.lens_mm", True, "generate.camera.lens_mm: Input should be a valid number"),
    ("generate.images_per_stop", True, "generate.images_per_stop: Input should be a valid integer"),
    ("generate.arcs.n_stops", "5", "generate.arcs.n_stops: Input should be a valid integer"),
    ("generate.sensor.exposure", "200.0", "generate.sensor.exposure: Input should be a valid number"),
    ("generate.camera.downscale", 4.0, "generate.camera.downscale: Input should be a valid integer"),
    ("generate.scenes.1.glenoid_tilt_deg", [True, 20], "generate.scenes.1.glenoid_tilt_deg.0: Input should be a valid number"),
    ("protocol.tolerances", [[2.0, "3"]], "protocol.tolerances.0.1: Input should be a valid number"),
    ("track.frames.phantom_radius_px", [1.5, False], "track.frames.phantom_radius_px.1: Input should be a valid number"),
    ("track.markers_body", [[0.03, 0.01, True]] * 4, "track.markers_body.0.2: Input should be a valid number"),
    ("predict.tail_n_t_shown", [4, 15.0], "predict.tail_n_t_shown.1: Input should be a valid integer"),
    ("parallel.n_jobs", True, "parallel.n_jobs: Input should be a valid integer"),
    ("fit.k_max", 5.5, "fit.k_max"),
    ("extract.usac_refine_lm", 1, "extract.usac_refine_lm: Input should be a valid boolean"),
    ("extract.features_dir", 7, "extract.features_dir: Input should be a valid string"),
])
def test_strict_numbers_name_the_key(tiny_raw, key, value, message):
    from params_cases import refusal

    assert message in refusal(tiny_raw, key, value)


def test_int_for_float_stays_accepted(tiny_raw):
    from params_cases import with_value

    params = parse_params(with_value(tiny_raw, "generate.camera.lens_mm", 12), base_dir=ROOT)
    assert params.generate.camera.lens_mm == 12.0 and type(params.generate.camera.lens_mm) is float


def test_strict_numbers_from_a_file_name_file_and_key(tmp_path):
    path = tmp_path / "params.yaml"
    path.write_text((ROOT / "params.yaml").read_text().replace("lens_mm: 12.0", "lens_mm: yes"))
    with pytest.raises(ParamsError, match=r"params\.yaml has invalid values:\n  generate\.camera\.lens_mm: "
                                          r"Input should be a valid number \(got True\)"):
        load_params(path)


def test_huge_numbers_are_refused_with_their_key(tiny_raw):
    """One number per section that had no upper bound before (a camera width of 10^9 was accepted)."""
    from params_cases import refusal

    for key, value in [("track.camera.width", 10**9), ("track.filter.sigma_r", 1e9), ("track.motion.duration_s", 1e9),
                       ("track.evaluation.success_frames", 10**9), ("extract.sift.n_features", 10**9),
                       ("predict.n_t_min", 10**9), ("parallel.n_jobs", 10**9),
                       ("generate.scapula.glenoid_centre", [1e9, 0.0, 0.0]),
                       ("track.markers_body", [[1e9, 0.0, 0.0]] * 4)]:
        assert key in refusal(tiny_raw, key, value), key
