r"""The base of every table: a frozen msgspec Struct that checks itself, and its messages.

A table's fields carry their types, ranges and choices as annotations
(``Annotated[float, Meta(gt=0, extra={"unit": "m"})]``, ``Literal``, enums). msgspec
checks them when a file is read (:func:`msgspec.convert`); :class:`Table` has msgspec
check them when a table is built in code: each rule is written once, in the annotation.
``__post_init__`` adds what no annotation says: finite numbers, and :meth:`Table.check`,
the rules between the table's fields.

A refusal names the key and what it must be. :func:`reason` words it from the field's
annotation and the value found (unknown or missing keys, the range, the type), at the
location of msgspec's error (its ``$.plate.holes[1]``, :func:`location`), never from
msgspec's own wording. A rule's ``FieldError`` names a field of its table; where that table lies
in a file (``obstacles[1]``) the loader says.
"""

from __future__ import annotations

import contextlib
import contextvars
import datetime as dt
import difflib
import enum
import functools
import math
import re
import types
import typing
from collections.abc import Iterator, Mapping, Sequence
from typing import Annotated, Any, ClassVar, Literal, Union

import msgspec
import numpy as np
from msgspec import Meta, Struct

from unibuckle_fenicsx.errors import FieldError, InputError

#: Unit systems of a problem file: name -> (metres per length unit, pascals per stress
#: unit, stress unit's name). Forces are in N in both.
UNITS: dict[str, tuple[float, float, str]] = {
    "SI": (1.0, 1.0, "Pa"),
    "mm-N-MPa": (1e-3, 1e6, "MPa"),
}
Units = Literal["SI", "mm-N-MPa"]
#: The units of fields (``Meta(extra={"unit": ...})``) that a unit system converts, as
#: powers (p, q) of its length L and stress S: a value is ``(L**p * S**q)`` SI units.
#: A list: one per entry of a list value (the first for a number).
DIMENSIONS: dict[str, tuple[int, int] | list[tuple[int, int]]] = {
    "m": (1, 0),
    "Pa": (0, 1),
    "N/m": (1, 1),  # = Pa m
    "N/m^2": (0, 1),
    "N/m^3": (-1, 1),
    "N m": (3, 1),  # = Pa m^3
    "m^2": (2, 0),  # an area, in messages
    "K, K/m": [(0, 0), (-1, 0), (-1, 0)],  # a rise, or [T0, dT/dx, dT/dy]
}


#: The unit system of the file being read (:data:`UNITS`): its messages speak it.
FILE_UNITS: contextvars.ContextVar[str] = contextvars.ContextVar("file_units", default="SI")


@contextlib.contextmanager
def file_units(units: str) -> Iterator[None]:
    """Within the block, messages speak ``units`` (:data:`FILE_UNITS`): a run's set-up.

    The file's reading sets them itself; a problem's solve (its mesh, points and
    contact set-up) refuses and warns in them too.
    """
    token = FILE_UNITS.set(units)
    try:
        yield
    finally:
        FILE_UNITS.reset(token)


def factor(dims: tuple[int, int], units: str, sign: int = 1) -> float:
    """SI units per unit of dimensions (length, stress) in ``units`` (``sign`` -1: inverse).

    A quotient for negative powers (N/m^3 = Pa/m): ``S / L``, not ``L**-1 * S``.
    """
    length, stress, _ = UNITS[units]
    p, q = dims
    up = (length ** max(p, 0) * stress ** max(q, 0)) ** sign
    return up / (length ** max(-p, 0) * stress ** max(-q, 0)) ** sign


def unit_name(name: str, units: str | None = None) -> str:
    """The SI unit ``name`` (of :data:`DIMENSIONS`) as ``units`` writes it (None: the file's).

    "m" -> "mm", "Pa" -> "MPa", "N/m^3" -> "N/mm^3" in mm-N-MPa; other names as they are.
    """
    units = FILE_UNITS.get() if units is None else units
    if units == "SI" or name not in DIMENSIONS:
        return name
    length = "m" if UNITS[units][0] == 1.0 else "mm"
    return re.sub(r"\bPa\b", UNITS[units][2], re.sub(r"\bm\b", length, name))


def in_file(value: Any, name: str, units: str | None = None) -> tuple[Any, str]:
    """The SI ``value`` in the unit ``name`` as ``units`` writes it, and the unit's name.

    ``value``: a number, or lists or tuples of numbers (a unit of one entry each, as
    "K, K/m": a list of as many); ``units``: None for the file's
    being read (:data:`FILE_UNITS`). In SI the value itself (its messages unchanged);
    else rounded to 12 digits, the conversion's last-bit noise dropped (2 mm -> 0.002 m
    -> 2.0000000000000004 mm).
    """
    units, dims = FILE_UNITS.get() if units is None else units, DIMENSIONS.get(name)
    if units == "SI" or dims is None:
        return value, name

    def convert(x: Any, per: float) -> Any:
        if isinstance(x, list | tuple):
            return type(x)(convert(v, per) for v in x)
        return float(f"{x / per:.12g}") if isinstance(x, int | float) else x

    if isinstance(dims, tuple):
        return convert(value, factor(dims, units)), unit_name(name, units)
    # one unit per entry of a list ("K, K/m": [T0, dT/dx, dT/dy]), or the first for a number
    if not isinstance(value, list | tuple):
        return convert(value, factor(dims[0], units)), unit_name(name, units)
    if len(value) != len(dims):
        return value, name
    entries = (convert(v, factor(d, units)) for v, d in zip(value, dims, strict=True))
    return type(value)(entries), unit_name(name, units)


def unit(name: str, **bounds: Any) -> Meta:
    """The Meta of a field in the unit ``name`` (with its bounds)."""
    return Meta(**bounds, extra={"unit": name})


Point = tuple[float, float]
Box = tuple[tuple[float, float], tuple[float, float]]
#: An edge stress: a number, or [start, end] (linear along the edge).
Stress = float | tuple[float, float]
#: A temperature rise: a number (K), or [T0, dT/dx, dT/dy] (K, K/m), a linear field.
Temperature = float | tuple[float, float, float]
Matrix3 = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]
#: How messages write these types (a union's members hold no Meta: msgspec 0.22 crashes
#: on a bounded number beside a list in a union); a unit in braces is written in the
#: file's units (:func:`unit_name`).
FORMS: dict[Any, str] = {
    Point: "a point [x, y]",
    Box: "a box [[xmin, xmax], [ymin, ymax]]",
    Stress: "a number or a pair [start, end] (linear along the edge)",
    Temperature: "a number (K) or [T0, dT/dx, dT/dy] ({K, K/m})",
    Matrix3: "a 3x3 matrix [[a, b, c], [d, e, f], [g, h, i]]",
}


def stress_ends(value: Stress) -> tuple[float, float]:
    """(start, end) of an edge stress: the pair itself, or the number twice."""
    return (value, value) if isinstance(value, float | int) else value


def temperature_field(value: Temperature) -> tuple[float, float, float]:
    """(T0, dT/dx, dT/dy) of a temperature rise."""
    return (value, 0.0, 0.0) if isinstance(value, float | int) else value


#: Set while :func:`msgspec.convert` builds tables: their fields are checked already.
CONVERTING: contextvars.ContextVar[bool] = contextvars.ContextVar("converting", default=False)


class Table(Struct, frozen=True, forbid_unknown_fields=True):
    """A table of the problem file: frozen, unknown keys forbidden, checked when built."""

    #: The key that names this table in messages when it is built in code.
    KEY: ClassVar[str] = ""
    #: Fields that may hold a function (in code only: no file can write one).
    CALLABLE: ClassVar[tuple[str, ...]] = ()
    #: Fields of the Python API that a file's table does not have, and keys it has besides.
    CODE_ONLY: ClassVar[tuple[str, ...]] = ()
    FILE_ONLY: ClassVar[tuple[str, ...]] = ()

    def __post_init__(self) -> None:
        if not CONVERTING.get():
            for name, tp in hints(type(self)).items():
                value = getattr(self, name)
                if not (name in self.CALLABLE and callable(value)):
                    msgspec.structs.force_setattr(self, name, checked(value, tp, self.key(), name))
        for name in self.__struct_fields__:
            bad = next((v for v in _floats(getattr(self, name)) if not math.isfinite(v)), None)
            if bad is not None:
                raise self.error(name, f" must be a finite number, got {bad!r}")
        self.check()

    def check(self) -> None:
        """The rules between this table's fields (each raises :meth:`error`)."""

    def key(self) -> str:
        """This table's key in messages when it is built in code."""
        return self.KEY

    def error(self, field: str, text: str) -> FieldError:
        """The refusal of this table's ``field`` ("": the table): its key, then ``text``."""
        return FieldError(self.key(), field, text)

    @classmethod
    def file_keys(cls) -> list[str]:
        """The keys of this table in a file."""
        fields = [f for f in cls.__struct_fields__ if f not in cls.CODE_ONLY]
        return fields + list(cls.FILE_ONLY)


@functools.cache
def hints(cls: type) -> dict[str, object]:
    """A Struct's field types (annotations), with their Meta."""
    found = typing.get_type_hints(cls, include_extras=True)
    return {name: found[name] for name in cls.__struct_fields__}  # type: ignore[attr-defined]


def plain(value: Any) -> Any:
    """``value`` with numpy scalars and arrays as Python numbers and lists."""
    if isinstance(value, np.ndarray | np.generic):
        return value.tolist()
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    if isinstance(value, Mapping):
        return {k: plain(v) for k, v in value.items()}
    return value


def checked(value: Any, tp: Any, key: str, name: str) -> Any:
    """``value`` converted to the field type ``tp`` by msgspec, or refused naming the key."""
    try:
        return msgspec.convert(plain(value), tp)
    except msgspec.ValidationError as err:
        steps = location(err)
        field_type, found = walk(tp, value, steps)
        where = join(key, name)
        for s in steps:
            where = join(where, s)
        raise InputError(reason(where, found, field_type)) from None


def _floats(value: Any) -> Iterator[float]:
    if isinstance(value, float):
        yield value
    elif isinstance(value, tuple):
        for v in value:
            yield from _floats(v)


def join(key: str, step: str | int) -> str:
    """The key ``step`` below ``key``: ``plate`` + ``holes`` -> ``plate.holes``, + 1 -> ``[1]``."""
    if isinstance(step, int):
        return f"{key}[{step}]"
    return f"{key}.{step}" if key and step else key or step


# -- types -----------------------------------------------------------------------------


def bare(tp: Any) -> Any:
    """``tp`` without its Annotated metadata."""
    while typing.get_origin(tp) is Annotated:
        tp = typing.get_args(tp)[0]
    return tp


def members(tp: Any) -> list[Any]:
    """The members of a union (each with its own Meta), or ``[tp]``."""
    if typing.get_origin(bare(tp)) in (Union, types.UnionType):
        return [m for a in typing.get_args(bare(tp)) for m in members(a)]
    return [tp]


def is_table(tp: Any) -> bool:
    """Whether ``tp`` is a table (a Struct)."""
    return isinstance(bare(tp), type) and issubclass(bare(tp), Struct)


def element(tp: Any) -> Any:
    """The entries' type of a list type ``tuple[X, ...]``, or None."""
    args = typing.get_args(bare(tp))
    return args[0] if typing.get_origin(bare(tp)) is tuple and args[-1:] == (...,) else None


def metadata(tp: Any, name: str) -> Any:
    """The ``Meta`` attribute (or ``extra`` entry) ``name`` of ``tp`` or of its union's."""
    while typing.get_origin(tp) is Annotated:
        for meta in reversed(typing.get_args(tp)[1:]):
            found = (meta.extra or {}).get(name, getattr(meta, name, None))
            if found is not None:
                return found
        tp = typing.get_args(tp)[0]
    if typing.get_origin(tp) in (Union, types.UnionType):
        return next((m for a in typing.get_args(tp) if (m := metadata(a, name)) is not None), None)
    return None


def table_of(tp: Any, value: Any, field: str | None = None) -> Any:
    """The table of ``tp`` (a union: by ``value``'s tag, else having ``field``), or None."""
    tables = [bare(m) for m in members(tp) if is_table(m)]
    tag = value.get("shape") if isinstance(value, Mapping) else None
    for table in tables:
        if table.__struct_config__.tag == tag or field in table.__struct_fields__:
            return table
    return tables[0] if tables else None


def walk(tp: Any, value: Any, steps: list[str | int]) -> tuple[Any, Any]:
    """The type and value at ``steps`` (field names and indices) below ``tp``, ``value``."""
    for key in steps:
        entry = child(value, key)
        if isinstance(key, str):
            table = table_of(tp, value, key)
            tp = hints(table).get(key, Any) if table is not None else Any
        else:
            lists = [bare(m) for m in members(tp) if typing.get_origin(bare(m)) is tuple]
            args = typing.get_args(lists[0]) if lists else ()
            if lists and element(lists[0]) is not None:
                tp = element(lists[0])
            else:
                tp = args[key] if key < len(args) else Any
        value = entry
    return tp, value


def as_table(value: object) -> dict[str, object]:
    """``value``, a table of a builtins form (JSON, TOML)."""
    assert isinstance(value, dict)
    return value


def as_tables(value: object) -> list[dict[str, object]]:
    """``value``, a list of tables of a builtins form."""
    assert isinstance(value, list)
    return [as_table(v) for v in value]


def child(value: object, step: str | int) -> object:
    """The entry ``step`` (a key or an index) of a table or list ``value``, or None."""
    if isinstance(value, Mapping) and isinstance(step, str):
        return value.get(step)
    if isinstance(value, list | tuple) and isinstance(step, int) and step < len(value):
        return value[step]
    return None


def location(err: msgspec.ValidationError) -> list[str | int]:
    """The steps of msgspec's error location: ``$.obstacles[1].zone`` -> obstacles, 1, zone."""
    text = str(err)
    if " - at `$" not in text:
        return []
    steps: list[str | int] = []
    for part in text.rpartition(" - at `$")[2][:-1].replace("[", ".[").split("."):
        if part.startswith("["):
            steps.append(int(part[1:-1]) if part[1:-1].isdigit() else part)
        elif part:
            steps.append(part)
    return steps


# -- messages --------------------------------------------------------------------------


def reason(key: str, value: Any, tp: Any) -> str:
    """Why ``value`` is not a ``tp`` at ``key``: unknown or missing keys, range, or type."""
    table = table_of(tp, value)
    if table is not None and isinstance(value, Mapping):
        where = f"[{key}]" if key else "[top] (the file's top level)"
        fields = table.__struct_fields__
        tag = table.__struct_config__.tag_field
        unknown = [k for k in value if k not in fields and k != tag]
        if unknown:
            return unknown_keys(unknown, where, table.file_keys())
        missing = [
            k for k in fields[: len(fields) - len(table.__struct_defaults__)] if k not in value
        ]
        if missing:
            return f"{where} needs {', '.join(map(repr, missing))}"
    for m in members(tp):  # the right type, out of its range
        if bare(m) is not type(None) and not is_table(m) and _converts(value, bare(m)):
            text = form(m) if bare(m) is int else _range(m)
            return (
                f"{key} must {'lie' if text.startswith('in ') else 'be'} {text}, got {value!r}"
                + _si_hint(value, m)
            )
    kinds = {_kind(bare(m)) for m in members(tp)}
    got = "" if _kind(value) in kinds else f" ({_kind(value)})"
    # TOML's dates and times as the file writes them, not as Python's repr
    shown = value.isoformat() if isinstance(value, dt.date | dt.time) else repr(value)
    return f"{key or 'the file'} must be {form(tp)}, got {shown}{got}"


def unknown_keys(unknown: Sequence[str], where: str, allowed: Sequence[str]) -> str:
    """The refusal of the keys ``unknown`` in the table ``where``, with the allowed ones."""
    return f"unknown key(s) {list(unknown)} in {where}; allowed: {list(allowed)}" + did_you_mean(
        unknown, allowed
    )


def did_you_mean(unknown: Sequence[str], allowed: Sequence[str]) -> str:
    """The hint ``(did you mean 'thickness'?)``: the nearest allowed key, or nothing.

    ``difflib.get_close_matches`` (its default cutoff 0.6); with several keys, each
    guess names the key it is for.
    """
    near = {key: difflib.get_close_matches(key, list(allowed), n=1) for key in unknown}
    hints = [
        repr(found[0]) + (f" for {key!r}" if len(unknown) > 1 else "")
        for key, found in near.items()
        if found
    ]
    return f" (did you mean {', '.join(hints)}?)" if hints else ""


def form(tp: Any) -> str:
    """How a message writes the type ``tp``: a number, one of (...), a list of ...."""
    b = bare(tp)
    given = metadata(tp, "form") or FORMS.get(b)
    if given:
        return re.sub(r"\{([^}]*)\}", lambda unit: unit_name(unit.group(1)), str(given))
    if typing.get_origin(b) in (Union, types.UnionType):
        return " or ".join(form(m) for m in members(b) if bare(m) is not type(None))
    if b is int:
        return f"an integer {_range(tp)}".rstrip()
    if typing.get_origin(b) is Literal:
        return f"one of {typing.get_args(b)}"
    if isinstance(b, type) and issubclass(b, enum.Enum):
        return f"one of {tuple(m.value for m in b)}"
    if typing.get_origin(b) is tuple:
        entries = element(b) or typing.get_args(b)[0]
        return "a list of tables" if is_table(entries) else f"a list, each entry {form(entries)}"
    return (
        "a table" if is_table(b) else {float: "a number", bool: "true or false"}.get(b, "a string")
    )


_SIGNS = {"gt": ">", "ge": ">=", "lt": "<", "le": "<="}


def _range(tp: Any) -> str:
    """The range of ``tp``'s Meta: "> 0 m", "in (-1, 0.5)", "a list of at least 3 entries"."""
    if (size := metadata(tp, "min_length")) is not None:
        text = (
            "string of at least {} characters" if bare(tp) is str else "list of at least {} entries"
        )
        return "a " + text.format(size)
    name = metadata(tp, "unit")
    # The bounds are SI; a message speaks the file's units (1e3 Pa is 1e-3 MPa).
    bounds = {
        op: in_file(v, name)[0] if name else v
        for op in _SIGNS
        if (v := metadata(tp, op)) is not None
    }
    suffix = f" {unit_name(name)}" if name else ""
    if len(bounds) == 2:  # an interval
        (low, a), (high, b) = bounds.items()
        return f"in {'(['[low == 'ge']}{a:g}, {b:g}{')]'[high == 'le']}{suffix}"
    return "".join(f"{_SIGNS[op]} {v:g}{suffix}" for op, v in bounds.items())


def _si_hint(value: Any, tp: Any) -> str:
    """In a file not in SI, a hint when ``value`` would be in ``tp``'s range as SI.

    2.1e11 for E in a mm-N-MPa file is steel's modulus in Pa: the message then says that
    the file's units take MPa (``tp``'s bounds are SI, so the raw number is checked
    against them as it is).
    """
    units, name = FILE_UNITS.get(), metadata(tp, "unit")
    if units == "SI" or not name or not isinstance(DIMENSIONS.get(name), tuple):
        return ""
    if not _converts(value, tp):
        return ""
    return (
        f" (in range as {value:g} {name}: units = {units!r} takes "
        f"{unit_name(name, units)}, here {in_file(value, name, units)[0]:g})"
    )


def _converts(value: Any, tp: Any) -> bool:
    try:
        msgspec.convert(plain(value), tp)
    except (msgspec.ValidationError, TypeError):
        return False
    return True


def _kind(x: Any) -> str:
    """The JSON kind of a type or of a value: a number, a string, a list, a table."""
    x = str if typing.get_origin(x) is Literal else typing.get_origin(x) or x
    for cls, name in (
        (bool, "true or false"),
        (int | float, "a number"),
        (str | enum.Enum, "a string"),
        (list | tuple, "a list"),
        (Mapping | Struct, "a table"),
        (dt.date | dt.time, "a TOML date or time"),
    ):
        if isinstance(x, cls) or (isinstance(x, type) and issubclass(x, cls)):
            return name
    return "absent"
