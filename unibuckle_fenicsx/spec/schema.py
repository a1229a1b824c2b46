r"""The schema of a problem file, on msgspec: types, ranges, choices, no unknown key.

Each table of a problem file (:doc:`/guide/plate`) is a frozen :class:`msgspec.Struct`
that forbids unknown fields; :func:`validate_document` converts a TOML-shaped mapping
with :func:`msgspec.convert` and turns msgspec's error into an
:class:`~unibuckle_fenicsx.errors.InputError` that names the key where it happened
(``obstacles[1].circle.radius``, ``plate.holes[0].outline[2]``) and the value given.
:func:`json_schema` is the published JSON Schema (``schema/unibuckle-problem.schema.json``,
``unibuckle schema``), :func:`accepted_keys` every dotted key the loader accepts.

Why msgspec. Measured for this schema's kind of models (five nested tables, a constrained
float, a choice; Python 3.13, a shared 2-core machine, best of five runs, the bare
interpreter's ``import typing, dataclasses, enum`` 59 ms included): import and model
definition took 148 ms with msgspec 0.22, 249 ms with attrs 26.1 + cattrs 26.2 and
1018 ms with pydantic 2.14 (``python -X importtime -c "import pydantic"`` alone: 93-138
ms; building the models' validators is the rest). For four typical bad inputs msgspec
gives one line with the location: ``Expected `float` > 0.0 - at
`$.obstacles[1].circle.radius``` (a negative radius), ``Expected `float`, got `str```
(a string for a number), ``Object contains unknown field `nz` - at `$.mesh```, ``Invalid
enum value 'up' - at `$.obstacles[0].side```; pydantic gives the same content over four
lines with a documentation link per error; cattrs says ``invalid value @
$.obstacles[1].circle`` for the radius (no bound) and accepted the string "5" for a float.
In the package, ``python -X importtime -c "import unibuckle_fenicsx.spec"`` gives this
module 75-138 ms cumulative, msgspec's import 59-109 ms of it (three runs, under load).

What stays by hand, and why. The schema knows types, numeric bounds, choices and keys. It
does not know the rules between values: the geometry (a simple outline, holes inside the
plate and disjoint, outline segments named once, an edge name the plate has), the
edge-load rule (edges that give no stress carry none once any edge or ``[load]`` gives
one), the unit systems (a file's numbers converted to SI), the positive definite
material matrices and symmetric laminates, and the mechanism checks
(:mod:`unibuckle_fenicsx.spec.checks`). Those live in the frozen dataclasses of the Python
API (:mod:`~unibuckle_fenicsx.spec.plate` and its siblings), which are also built
directly in code, without a file, and so check their own values too. A bound violated
in a file is reported by the dataclass's check, which gives the unit (``plate.thickness
must be > 0 m, got -1.0``); the schema's own message is the fallback.
"""

from __future__ import annotations

import re
import types
import typing
from collections.abc import Mapping
from typing import Annotated, Any, Literal, Union

import msgspec
import numpy as np
from msgspec import UNSET, Meta, Struct, UnsetType

from unibuckle_fenicsx.errors import InputError

__all__ = ["ProblemFile", "accepted_keys", "json_schema", "validate_document"]

Positive = Annotated[float, Meta(gt=0)]
NonNegative = Annotated[float, Meta(ge=0)]
Point = tuple[float, float]
Box = tuple[tuple[float, float], tuple[float, float]]
Stress = float | tuple[float, float]
Temperature = float | tuple[float, float, float]
Matrix3 = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]
Polygon = Annotated[list[Point], Meta(min_length=3)]


class _Table(Struct, frozen=True, forbid_unknown_fields=True, omit_defaults=True):
    """A table of the problem file: frozen, unknown keys forbidden."""


class HoleTable(_Table, frozen=True):
    """``[[plate.holes]]``: a circle (center, radius) or a polygon (outline)."""

    center: Point | UnsetType = UNSET
    radius: Positive | UnsetType = UNSET
    outline: Polygon | UnsetType = UNSET


class PlateTable(_Table, frozen=True):
    """``[plate]``: the rectangle's corners, or an outline, or a gmsh file; the thickness."""

    corners: Box | UnsetType = UNSET
    thickness: Positive | UnsetType = UNSET
    outline: Polygon | UnsetType = UNSET
    holes: list[HoleTable] | UnsetType = UNSET
    file: str | UnsetType = UNSET


class PlyTable(_Table, frozen=True):
    """``[[material.plies]]``: one orthotropic ply, bottom first."""

    thickness: Positive
    angle: Annotated[float, Meta(ge=-360.0, le=360.0)]
    E1: Positive
    E2: Positive
    G12: Positive
    nu12: float
    G13: Positive
    G23: Positive


class MaterialTable(_Table, frozen=True):
    """``[material]``: E and nu (and optional Voigt matrices), or plies."""

    E: Positive | UnsetType = UNSET
    nu: Annotated[float, Meta(gt=-1.0, lt=0.5)] | UnsetType = UNSET
    shear_correction: Positive | UnsetType = UNSET
    membrane_voigt: Matrix3 | UnsetType = UNSET
    bending_voigt: Matrix3 | UnsetType = UNSET
    plies: Annotated[list[PlyTable], Meta(min_length=1)] | UnsetType = UNSET
    thermal_expansion: NonNegative | UnsetType = UNSET


class EdgeTable(_Table, frozen=True):
    """``[edges.NAME]``: the supports and the stresses of one boundary part."""

    support: Literal["simply_supported", "simply_supported_soft", "clamped", "free"] | UnsetType = (
        UNSET
    )
    inplane: Literal["free", "clamped", "roller"] | UnsetType = UNSET
    normal_stress: Stress | UnsetType = UNSET
    shear_stress: Stress | UnsetType = UNSET
    segments: Annotated[list[Annotated[int, Meta(ge=0)]], Meta(min_length=1)] | UnsetType = UNSET
    rotational_stiffness: NonNegative | UnsetType = UNSET
    translational_stiffness: NonNegative | UnsetType = UNSET
    fixed_normal_stress: Stress | UnsetType = UNSET
    fixed_shear_stress: Stress | UnsetType = UNSET


class MeshTable(_Table, frozen=True):
    """``[mesh]``: cells nx and ny, or a cell size."""

    nx: Annotated[int, Meta(ge=2)] | UnsetType = UNSET
    ny: Annotated[int, Meta(ge=2)] | UnsetType = UNSET
    size: Positive | UnsetType = UNSET


class CircleTable(_Table, frozen=True):
    """An obstacle's ``circle = {center, radius}`` (both needed: checked by the loader)."""

    center: Point | UnsetType = UNSET
    radius: Positive | UnsetType = UNSET


class ObstacleTable(_Table, frozen=True):
    """``[obstacle]`` or ``[[obstacles]]``: one zone (zone, polygon or circle) and its kind."""

    zone: Literal["all"] | Box | UnsetType = UNSET
    polygon: Polygon | UnsetType = UNSET
    circle: CircleTable | UnsetType = UNSET
    side: Literal["above", "below", "both"] | UnsetType = UNSET
    foundation_stiffness: Positive | UnsetType = UNSET
    tolerance: NonNegative | UnsetType = UNSET
    gap: NonNegative | UnsetType = UNSET


class PointTable(_Table, frozen=True):
    """``[[points]]``: one point (at) or a grid (spacing, offset, region)."""

    at: Point | UnsetType = UNSET
    # msgspec 0.22 crashes (segfault) on a constrained number in a union with an array,
    # so the number is checked for > 0 by PointSpec only.
    spacing: float | tuple[Positive, Positive] | UnsetType = UNSET
    offset: Point | UnsetType = UNSET
    region: Box | UnsetType = UNSET
    kind: Literal["bilateral", "one-sided", "spring"] | UnsetType = UNSET
    stiffness: Positive | UnsetType = UNSET
    side: Literal["above", "below"] | UnsetType = UNSET


class LoadTable(_Table, frozen=True):
    """``[load]``: temperature rises (scaled and fixed) and the fixed part's factor."""

    temperature: Temperature | UnsetType = UNSET
    fixed_temperature: Temperature | UnsetType = UNSET
    fixed_factor: float | UnsetType = UNSET


class DesignTable(_Table, frozen=True):
    """``[design]``: the EN 1993-1-5 design data (yield_stress needed: checked by the loader)."""

    yield_stress: Positive | UnsetType = UNSET
    partial_factor: Positive | UnsetType = UNSET


class SolverTable(_Table, frozen=True):
    """``[solver]``: the method and its options."""

    method: Literal["auto", "enumerate", "interior-point", "active-set", "penalty"] | UnsetType = (
        UNSET
    )
    tau: Annotated[float, Meta(gt=0.0, le=1e-2)] | UnsetType = UNSET
    eps_tol: Annotated[float, Meta(gt=0.0, le=1e-4)] | UnsetType = UNSET
    max_candidates: Annotated[int, Meta(ge=1)] | UnsetType = UNSET
    enumeration_budget_s: Positive | UnsetType = UNSET
    complete: bool | UnsetType = UNSET
    until_proven: bool | UnsetType = UNSET
    max_iterations: Annotated[int, Meta(ge=1)] | UnsetType = UNSET
    bound_budget: Annotated[int, Meta(ge=0)] | UnsetType = UNSET
    certify: bool | UnsetType = UNSET
    bracket: bool | UnsetType = UNSET
    penalty: Positive | UnsetType = UNSET
    prestress_degree: Annotated[int, Meta(ge=1)] | UnsetType = UNSET
    shear: Literal["mitc", "full"] | UnsetType = UNSET


class ProblemFile(_Table, frozen=True):
    """A problem file (:doc:`/guide/plate`); every table optional."""

    name: str | UnsetType = UNSET
    units: Literal["SI", "mm-N-MPa"] | UnsetType = UNSET
    plate: PlateTable | UnsetType = UNSET
    material: MaterialTable | UnsetType = UNSET
    edges: dict[str, EdgeTable] | UnsetType = UNSET
    mesh: MeshTable | UnsetType = UNSET
    obstacle: ObstacleTable | UnsetType = UNSET
    obstacles: Annotated[list[ObstacleTable], Meta(min_length=1)] | UnsetType = UNSET
    points: Annotated[list[PointTable], Meta(min_length=1)] | UnsetType = UNSET
    load: LoadTable | UnsetType = UNSET
    design: DesignTable | UnsetType = UNSET
    solver: SolverTable | UnsetType = UNSET


#: JSON type names in msgspec's messages, as the messages here say them.
_TYPES = {
    "float": "a number",
    "int": "an integer",
    "bool": "true or false",
    "str": "a string",
    "array": "a list",
    "object": "a table",
    "null": "absent",
}
_WHERE = re.compile(r"^(?P<what>.*) - at `\$(?P<where>.*)`$", re.DOTALL)
_STEP = re.compile(r"\.([^.\[]+)|\[(\d+)\]")


def _value_at(data: Any, where: str) -> Any:
    """The value at ``where`` (``.obstacles[1].circle``) in ``data``, or None."""
    for key, index in _STEP.findall(where):
        try:
            data = data[key] if key else data[int(index)]
        except (KeyError, IndexError, TypeError):
            return None
    return data


def _message(err: msgspec.ValidationError, data: Any) -> tuple[str, bool]:
    """The message of msgspec's ``err`` naming the key; and whether a bound was violated."""
    text = str(err)
    match = _WHERE.match(text)
    where, what = ("", text) if match is None else (match["where"], match["what"])
    if where.startswith(".edges[...]"):  # msgspec does not name a mapping's key
        where = _edge_where(data, where.removeprefix(".edges[...]"))
    key = where.removeprefix(".")
    value = _value_at(data, where)
    if unknown := re.match(r"Object contains unknown field `(.*)`", what):
        table = f"[{key}]" if key else "[top] (the file's top level)"
        allowed = [k.removeprefix(f"{_pattern(key)}.") for k in _children(key)]
        return f"unknown key(s) ['{unknown[1]}'] in {table}; allowed: {allowed}", False
    if re.match(r"Object missing required field `(.*)`", what):
        keys = [k.rsplit(".", 1)[-1] for k in _children(key)]
        struct = _tables()[_pattern(key)]
        present = value if isinstance(value, Mapping) else {}
        fields = struct.__struct_fields__
        required = fields[: len(fields) - len(struct.__struct_defaults__)]
        missing = [k for k in required if k not in present]
        return f"[{key}] needs {missing} (keys: {keys})", False
    if choice := re.match(r"Invalid enum value (.*)", what):
        field_type = _unwrap(_field_types().get(_pattern(key)))
        other = typing.get_origin(field_type) is Union  # a choice or a list (a box)
        also = " or [[xmin, xmax], [ymin, ymax]]" if other else ""
        return f"{key} must be one of {_choices(key)}{also}, got {choice[1]}", False
    if wrong := re.match(r"Expected `([^`]+)`, got `(\w+)`$", what):
        wanted = " or ".join(_TYPES.get(t, t) for t in wrong[1].split(" | "))
        if _pattern(key) + "[]" in _tables(lists=True):
            wanted = f"a list of tables ([[{key}]] in TOML)"
        got = f"{value!r} ({_TYPES.get(wrong[2], wrong[2])})"
        return f"{key or 'the file'} must be {wanted}, got {got}", False
    if shape := re.match(r"Expected `array` of (length .*?)(?:, got .*)?$", what):
        if typing.get_origin(_unwrap(_field_types().get(_pattern(key)))) is Union:
            # A number or a list (an edge stress, a temperature field, a spacing): the
            # dataclass's check says what the list means ("a pair [start, end]").
            return f"{key} must be a number or a list of {shape[1]}, got {value!r}", True
        if _pattern(key) + "[]" in _tables(lists=True):
            what = f"tables ([[{key}]] in TOML), at least one"
            return f"{key} must be a list of {what}, got {value!r}", False
        size = shape[1].replace("length >= ", "at least ").replace("length ", "exactly ")
        return f"{key} must be a list of {size} entries, got {value!r}", False
    if bound := re.match(r"Expected `(\w+)` (.*)", what):
        return f"{key} must be {_TYPES.get(bound[1], bound[1])} {bound[2]}, got {value!r}", True
    got = "" if ", got " in what else f", got {value!r}"
    return f"{key or 'the file'}: {what[0].lower()}{what[1:]}{got}", False


def _edge_where(data: Any, rest: str) -> str:
    """The location ``.edges.NAME`` + ``rest`` of the first edge table the schema refuses."""
    for name, table in data["edges"].items():
        try:
            msgspec.convert(table, EdgeTable)
        except msgspec.ValidationError:
            return f".edges.{name}{rest}"
    return f".edges{rest}"


def _pattern(key: str) -> str:
    """A location as an :func:`accepted_keys` pattern: indices ``[]``, edge names ``<name>``."""
    key = re.sub(r"\[\d+\]", "[]", key)
    return re.sub(r"^edges\.[^.\[]+", "edges.<name>", key)


def _children(key: str) -> list[str]:
    """The keys directly below the table at ``key``."""
    prefix = _pattern(key) + "." if key else ""
    below = [k.removeprefix(prefix) for k in accepted_keys() if k.startswith(prefix)]
    names = dict.fromkeys(re.split(r"[.\[]", k, maxsplit=1)[0] for k in below)
    return [prefix + n for n in names]


def _choices(key: str) -> tuple[str, ...]:
    """The allowed strings of the choice at ``key``."""
    field_type = _unwrap(_field_types().get(_pattern(key)))
    members = typing.get_args(field_type) if typing.get_origin(field_type) is Union else ()
    literals = [m for m in (field_type, *members) if typing.get_origin(m) is Literal]
    return tuple(a for lit in literals for a in typing.get_args(lit))


def _plain(value: Any) -> Any:
    """``value`` with numpy scalars as Python numbers (msgspec takes exact types only)."""
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value.item() if isinstance(value, np.generic) else value


def validate_document(data: Mapping[str, Any]) -> str | None:
    """Check the TOML-shaped ``data`` against :class:`ProblemFile`.

    Returns:
        None, or the schema's message for a value out of its bounds; the caller's checks
        give a more precise one (with the unit); this one is their fallback.

    Raises:
        InputError: A key that is not in the schema, a value of the wrong type or shape,
            a choice not among the allowed ones; the message names the key.
    """
    try:
        msgspec.convert(_plain(data), ProblemFile)
    except msgspec.ValidationError as err:
        message, bound = _message(err, data)
        if not bound:
            raise InputError(message) from None
        return message
    return None


def json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a problem file, as a mapping."""
    schema: dict[str, Any] = msgspec.json.schema(ProblemFile)
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "unibuckle_fenicsx problem file",
        **schema,
    }


def _unwrap(tp: Any) -> Any:
    """``tp`` without Annotated, UNSET and None."""
    while typing.get_origin(tp) is Annotated:
        tp = typing.get_args(tp)[0]
    if typing.get_origin(tp) in (Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a not in (UnsetType, type(None))]
        if len(args) == 1:
            return _unwrap(args[0])
        return Union[tuple(args)]  # noqa: UP007
    return tp


def _walk(
    struct: type[Struct],
    prefix: str,
    out: dict[str, Any],
    tables: dict[str, tuple[type[Struct], bool]] | None = None,
    listed: bool = False,
) -> None:
    """The leaves below ``struct`` into ``out``; its tables (and if a list) into ``tables``."""
    if tables is not None:
        tables[prefix.removesuffix(".")] = (struct, listed)
    hints = typing.get_type_hints(struct, include_extras=True)
    for name in struct.__struct_fields__:
        tp = _unwrap(hints[name])
        key = prefix + name
        origin, args = typing.get_origin(tp), typing.get_args(tp)
        if isinstance(tp, type) and issubclass(tp, Struct):
            _walk(tp, key + ".", out, tables)
        elif (
            origin is list
            and isinstance(_unwrap(args[0]), type)
            and issubclass(_unwrap(args[0]), Struct)
        ):
            _walk(_unwrap(args[0]), key + "[].", out, tables, listed=True)
        elif origin is dict and issubclass(_unwrap(args[1]), Struct):
            _walk(_unwrap(args[1]), key + ".<name>.", out, tables)
        else:
            out[key] = hints[name]


def _tables(lists: bool = False) -> dict[str, type[Struct]]:
    """The tables by :func:`accepted_keys` pattern (``lists``: the lists of tables only)."""
    found: dict[str, tuple[type[Struct], bool]] = {}
    _walk(ProblemFile, "", {}, found)
    return {k: t for k, (t, listed) in found.items() if listed or not lists}


def _field_types() -> dict[str, Any]:
    out: dict[str, Any] = {}
    _walk(ProblemFile, "", out)
    return out


def accepted_keys() -> list[str]:
    """Every dotted key the loader accepts, in the schema's order.

    A list of tables is written ``[]`` (``plate.holes[].radius``), the name of an
    ``[edges.NAME]`` table ``<name>`` (``edges.<name>.support``).
    """
    return list(_field_types())
