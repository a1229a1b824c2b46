"""A problem file: read into a :class:`ProblemSpec`, written back, and its JSON Schema.

Reading is ``msgspec.convert(to_si(raw), ProblemSpec)``: the Structs' annotations check
every key (:mod:`~unibuckle_fenicsx.spec.base`). A file writes a few things in its own
form, turned into the Structs' form here (:func:`_to_api`) and back (:func:`_to_file`):

- the ``[edges.NAME]`` tables are the plate's ``edges``; edges not named take the
  paper's (simply supported, the short edges compressed), but once any edge table or
  ``[load]`` gives a load, the edges that give none carry none;
- an obstacle's zone is one of the keys ``zone`` ("all" or a box), ``polygon`` (its
  vertices) or ``circle`` (``{center, radius}``); a hole is ``{center, radius}`` or
  ``{outline}``;
- a laminate leaves out E and nu (its plies' in-plane constants) and the plate's
  thickness (their total); a rectangle's ``[mesh]`` gives nx and ny, or a cell size.

Numbers are converted to SI by their field's unit (``Meta(extra={"unit": ...})``).
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import msgspec

from unibuckle_fenicsx.errors import FieldError, InputError
from unibuckle_fenicsx.laminate import laminate
from unibuckle_fenicsx.spec.base import (
    CONVERTING,
    DIMENSIONS,
    FILE_UNITS,
    UNITS,
    Stress,
    as_table,
    as_tables,
    child,
    element,
    factor,
    form,
    hints,
    join,
    location,
    members,
    metadata,
    plain,
    reason,
    table_of,
    unknown_keys,
    walk,
)
from unibuckle_fenicsx.spec.material import Ply
from unibuckle_fenicsx.spec.obstacles import ObstacleSpec
from unibuckle_fenicsx.spec.plate import EdgeSpec, PlateSpec, paper_edges
from unibuckle_fenicsx.spec.problem import ProblemSpec
from unibuckle_fenicsx.spec.section import SectionProblemSpec

#: Keys of an ``[obstacle]`` or ``[[obstacles]]`` table.
OBSTACLE_KEYS = ("zone", "polygon", "circle", *ObstacleSpec.__struct_fields__[1:])
#: Keys of a ``[[material.plies]]`` table.
PLY_KEYS: tuple[str, ...] = Ply.__struct_fields__
_LOADS = ("normal_stress", "shear_stress", "fixed_normal_stress", "fixed_shear_stress")


def problem_from_dict(data: Mapping[str, object], name: str = "plate") -> ProblemSpec:
    """A :class:`ProblemSpec` from a TOML-shaped mapping (:doc:`/guide/plate`).

    Args:
        data: The file's tables; ``name`` and ``units`` at the top.
        name: The label when the file gives none.

    Raises:
        InputError: An unknown key, a value of the wrong type or out of its range, a
            rule between keys broken; the message names the key.
    """
    if not isinstance(data, Mapping):
        raise InputError(f"a problem file is a table of tables, got {data!r}")
    _not_a_section(data)
    return _convert(_to_api({"name": name, **plain(data)}), ProblemSpec)


def section_from_dict(data: Mapping[str, object], name: str = "section") -> SectionProblemSpec:
    """A :class:`~unibuckle_fenicsx.spec.section.SectionProblemSpec` from a TOML-shaped mapping.

    Raises:
        InputError: An unknown key, a value of the wrong type or out of its range, a
            rule between keys broken; the message names the key.
    """
    if not isinstance(data, Mapping):
        raise InputError(f"a problem file is a table of tables, got {data!r}")
    return _convert({"name": name, **as_table(plain(data))}, SectionProblemSpec)


def _convert[S: (ProblemSpec, SectionProblemSpec)](api: dict[str, object], root: type[S]) -> S:
    """The Structs' form ``api`` of a file as ``root``: in SI, a laminate's E and nu set."""
    written = api  # the file's numbers, for messages (in its units, as it writes them)
    units = api.get("units")
    units = units if isinstance(units, str) and units in UNITS else "SI"
    api = as_table(scaled(api, root, units, 1))
    token, in_units = CONVERTING.set(True), FILE_UNITS.set(units)
    try:
        return msgspec.convert(_laminate(api, written) if root is ProblemSpec else api, root)
    except msgspec.ValidationError as err:
        raise InputError(_message(err, api, root=root, written=written)) from None
    finally:
        CONVERTING.reset(token)
        FILE_UNITS.reset(in_units)


def is_section(data: Mapping[str, object]) -> bool:
    """Whether the TOML-shaped mapping ``data`` is a section's file (its ``[section]``)."""
    return isinstance(data, Mapping) and "section" in data


def spec_from_dict(data: Mapping[str, object], name: str) -> ProblemSpec | SectionProblemSpec:
    """A section's problem if ``data`` has a ``[section]`` table, else a plate's."""
    if is_section(data):
        return section_from_dict(data, name)
    return problem_from_dict(data, name)


def _not_a_section(data: Mapping[str, object]) -> None:
    """Refuse a section's keys in a plate's file: [section], load.axial_stress, obstacle.core."""
    if is_section(data):
        raise InputError(
            "[section]: a section's file is read by section_from_dict (or load_problem)"
        )
    for table, key in (("obstacle", "core"), ("load", "axial_stress"), ("load", "bending_stress")):
        if isinstance(found := data.get(table), Mapping) and key in found:
            raise InputError(
                f"{table}.{key} is a section's key, and this file has no [section] table "
                "(shape, thickness, length, width and depth or diameter): a plate has no core "
                "and takes its load on its edges ([edges.NAME] normal_stress)"
            )


def problem_to_dict(spec: ProblemSpec | SectionProblemSpec, units: str = "SI") -> dict[str, object]:
    """The TOML-shaped mapping of ``spec``, every key with the value used.

    ``problem_from_dict(problem_to_dict(spec)) == spec`` for a spec without a predicate
    zone (it cannot be written: it raises); for a section's,
    ``section_from_dict(problem_to_dict(spec)) == spec``.

    Args:
        spec: The problem (a plate's or a section's).
        units: Unit system of the numbers written (one of :data:`UNITS`); the mapping's
            ``units`` key says which.
    """
    if units not in UNITS:
        raise InputError(f"units must be one of {tuple(UNITS)}, got {units!r}")
    try:
        data = msgspec.json.decode(msgspec.json.encode(spec))  # lists, not tuples; exact
        data = as_table(scaled(data, type(spec), units, -1))
    except TypeError:
        raise InputError("problem_to_dict: a predicate obstacle zone cannot be written") from None
    if isinstance(spec, SectionProblemSpec):
        data.pop("units")
        return as_table(_pruned({"name": data.pop("name"), "units": units, **data}))
    return _to_file(data | {"units": units}, spec)


def stress_value(value: Stress) -> float | list[float]:
    """An edge stress as written in a file: a number or ``[start, end]``."""
    return list(value) if isinstance(value, tuple) else value


def scaled(value: object, tp: object, units: str, sign: int) -> object:
    """``value`` (the Structs' form) with each number in a unit converted.

    From the unit system ``units`` to SI (``sign`` 1) or back (-1). A value that is not
    a number is left as it is, for the Structs to refuse.
    """
    if units == "SI":
        return value
    table = table_of(tp, value)
    if isinstance(value, Mapping) and table is not None:
        fields = hints(table)
        return {
            k: scaled(v, fields[k], units, sign) if k in fields else v for k, v in value.items()
        }
    entries = next((element(m) for m in members(tp) if element(m) is not None), None)
    if isinstance(value, list) and entries is not None and table_of(entries, None) is not None:
        return [scaled(v, entries, units, sign) for v in value]
    dims = DIMENSIONS.get(metadata(tp, "unit"))
    if dims is None:
        return value
    if isinstance(dims, list):  # one unit per entry, or the first for a number
        if isinstance(value, list):  # of another length: left for the Structs to refuse
            if len(value) != len(dims):
                return value
            return [_times(v, factor(d, units, sign)) for v, d in zip(value, dims, strict=True)]
        dims = dims[0]
    return _times(value, factor(dims, units, sign))


def _times(value: object, factor: float) -> object:
    """``value`` (a number, or lists of numbers) times ``factor``; anything else as is."""
    if isinstance(value, list):
        return [_times(v, factor) for v in value]
    if isinstance(value, int | float) and not isinstance(value, bool):
        return value * factor
    return value


# -- the file's form -------------------------------------------------------------------


def _to_api(raw: dict[str, object]) -> dict[str, object]:
    """The Structs' form of the file ``raw`` (see the module docstring)."""
    out = dict(raw)
    plate = out.get("plate", {})
    if isinstance(plate, Mapping):
        plate = out["plate"] = _plate(dict(plate), out.pop("edges", {}), out.get("load"))
        mesh = out.get("mesh")
        if isinstance(mesh, Mapping) and ({"nx", "ny"} & set(mesh)):
            if any(plate.get(k) for k in ("outline", "file", "holes")):
                raise InputError(
                    "[mesh]: a plate meshed by gmsh (outline, holes or file) takes size = h "
                    "(the characteristic cell size), not nx and ny"
                )
            if "size" in mesh:
                raise InputError("[mesh]: give size (a cell size) or nx and ny, not both")
    if isinstance(obstacle := out.get("obstacle"), Mapping):
        out["obstacle"] = _zone(obstacle, "obstacle")
    if isinstance(obstacles := out.get("obstacles"), list):
        out["obstacles"] = [
            _zone(t, f"obstacles[{k}]") if isinstance(t, Mapping) else t
            for k, t in enumerate(obstacles)
        ]
    return out


def _plate(plate: dict[str, object], edges: object, load: object) -> dict[str, object]:
    """``[plate]`` with the holes in the Structs' form and the ``[edges.*]`` tables."""
    _unknown(plate, PlateSpec.file_keys(), "plate")
    gmsh = "outline" in plate or "file" in plate
    if gmsh and "corners" in plate:
        raise InputError(
            "[plate]: give corners (a rectangle), or outline (a polygon) or file (a gmsh "
            "file), not both"
        )
    if isinstance(holes := plate.get("holes"), list):
        plate["holes"] = [_hole(h, f"plate.holes[{k}]") for k, h in enumerate(holes)]
    if not isinstance(edges, Mapping):
        raise InputError(f"edges must be a table of [edges.NAME] tables, got {edges!r}")
    loaded = any(isinstance(t, Mapping) and set(_LOADS) & set(t) for t in edges.values())
    loaded |= isinstance(load, Mapping) and bool(load)
    paper = () if gmsh else paper_edges()  # their loads only for a file that gives none
    tables = {e.name: {} if loaded else {"normal_stress": e.normal_stress} for e in paper}
    for name, table in edges.items():
        if not isinstance(table, Mapping):
            raise InputError(reason(f"edges.{name}", table, EdgeSpec))
        _unknown(table, EdgeSpec.file_keys(), f"edges.{name}")
        held = table.get("inplane", "free") != "free"  # takes no paper's load: its reaction
        tables[name] = {**({} if held else tables.get(name, {})), **table}
    plate["edges"] = [{"name": name, **table} for name, table in tables.items()]
    return plate


def _unknown(table: Mapping[str, object], allowed: Sequence[str], where: str) -> None:
    """Refuse the keys of ``table`` not in ``allowed``."""
    if found := [key for key in table if key not in allowed]:
        raise InputError(unknown_keys(found, f"[{where}]", allowed))


def _hole(table: object, where: str) -> object:
    """A hole's table in the Structs' form: a tagged circle or polygon."""
    if not isinstance(table, Mapping):
        return table
    _unknown(table, ("center", "radius", "outline"), where)
    if set(table) == {"outline"}:
        return {"shape": "polygon", "vertices": table["outline"]}
    if set(table) == {"center", "radius"}:
        return {"shape": "circle", **table}
    raise InputError(
        f"[{where}] needs center = [x, y] and radius = r (a circle), or outline = [[x, y], "
        f"...] (a polygon); got {sorted(table)}"
    )


def _zone(table: Mapping[str, object], where: str) -> dict[str, object]:
    """An obstacle's table with its zone, polygon or circle as the Structs' ``zone``."""
    _unknown(table, OBSTACLE_KEYS, where)
    if isinstance(table.get("zone"), Mapping):  # a file's zone is "all" or a box
        zone = hints(ObstacleSpec)["zone"]
        raise InputError(f"{where}.zone must be {form(zone)}, got {table['zone']!r} (a table)")
    given = [key for key in ("zone", "polygon", "circle") if key in table]
    if len(given) != 1:
        raise InputError(
            f'[{where}] needs zone = "all" (the whole plate) or [[xmin, xmax], [ymin, ymax]], '
            "or polygon = [[x, y], ...], or circle = {center = [x, y], radius = r}: exactly "
            f"one of them; got {given or 'none'}"
        )
    out = {key: value for key, value in table.items() if key not in ("polygon", "circle")}
    if "polygon" in table:
        out = {"zone": {"shape": "polygon", "vertices": table["polygon"]}, **out}
    elif "circle" in table:
        circle = table["circle"]
        if not isinstance(circle, Mapping) or "shape" in circle:
            raise InputError(
                f"{where}.circle must be a table {{center = [x, y], radius = r}}, got {circle!r}"
            )
        out = {"zone": {"shape": "circle", **circle}, **out}
    return out


def _laminate(api: dict[str, object], written: object = None) -> dict[str, object]:
    """A laminate's E and nu, and its plate's thickness, from its plies if not given.

    ``written``: the file's numbers (before their conversion to SI), for messages.
    """
    material = api.get("material")
    if not (isinstance(material, Mapping) and isinstance(material.get("plies"), list)):
        return api
    try:
        plies = msgspec.convert(material["plies"], tuple[Ply, ...])
    except msgspec.ValidationError as err:
        raise InputError(_message(err, api, ["material", "plies"], written=written)) from None
    if not plies:
        raise InputError(
            "material.plies must be a list of tables ([[material.plies]] in TOML), at least "
            "one, got []"
        )
    E, nu = laminate(plies).engineering_constants()
    api["material"] = {"E": E, "nu": nu, **material}
    plate = api.get("plate")
    if isinstance(plate, dict) and "thickness" not in plate:
        plate["thickness"] = sum(ply.thickness for ply in plies)
    return api


def _message(
    err: msgspec.ValidationError,
    api: object,
    prefix: list[str | int] | None = None,
    root: type[ProblemSpec | SectionProblemSpec] = ProblemSpec,
    written: object = None,
) -> str:
    """The message of msgspec's ``err`` converting ``api``, naming the file's key.

    A value refused by its type or range is quoted from ``written`` (the file's numbers,
    before their conversion to SI; None: ``api``'s).
    """
    steps = [*(prefix or []), *location(err)]
    cause = err.__cause__
    if isinstance(cause, FieldError):
        where = _file_key([*steps, *([cause.field] if cause.field else [])], api)
        return (where if cause.field else f"[{where}]") + cause.text
    if isinstance(cause, InputError):
        return str(cause)
    if cause is not None:
        raise cause
    tp, value = walk(root, api if written is None else written, steps)
    return reason(_file_key(steps, api), value, tp)


def _file_key(steps: list[str | int], api: object) -> str:
    """The file's key at ``steps`` of its Structs' form ``api`` (``edges.left``, ...)."""
    key, node = "", api
    for s in steps:
        node = child(node, s)
        shape = node.get("shape") if isinstance(node, Mapping) else None
        if key == "edges" and isinstance(s, int):
            key = f"edges.{node['name']}" if isinstance(node, Mapping) else f"edges[{s}]"
        elif s == "zone" and shape is not None:
            key = join(key, shape)
        elif s == "vertices":
            key = key if key.endswith(".polygon") else join(key, "outline")
        else:
            key = "edges" if (key, s) == ("plate", "edges") else join(key, s)
    return key


def _to_file(data: dict[str, object], spec: ProblemSpec) -> dict[str, object]:
    """The file's form of ``data``, the Structs' (``spec`` as JSON)."""
    plate, mesh = as_table(data["plate"]), as_table(data["mesh"])
    edges = {}
    for edge in as_tables(plate.pop("edges")):
        del edge["tag"]
        edges[str(edge.pop("name"))] = edge
    plate["holes"] = [_shape(h, "outline") for h in as_tables(plate["holes"])]
    if spec.plate.outline is not None or spec.plate.file is not None:
        del plate["corners"]
    if spec.material.plies:
        material = as_table(data["material"])
        del material["E"], material["nu"]
    if spec.mesh.size is not None or spec.plate.meshed_by_gmsh:
        del mesh["nx"], mesh["ny"]
    for point in as_tables(data["points"]):  # a square grid's spacing: one number
        if isinstance(spacing := point["spacing"], list) and len(set(spacing)) == 1:
            point["spacing"] = spacing[0]
    data["obstacle"] = _zone_key(data["obstacle"])
    data["obstacles"] = [_zone_key(o) for o in as_tables(data["obstacles"])]
    out: dict[str, object] = {}
    for key, value in data.items():
        out[key] = value
        if key == "material":
            out["edges"] = edges
    return as_table(_pruned(out))


def _zone_key(obstacle: object) -> object:
    """An obstacle's zone under its file key: zone, polygon or circle."""
    if obstacle is None or not isinstance(zone := as_table(obstacle)["zone"], dict):
        return obstacle
    rest = {k: v for k, v in as_table(obstacle).items() if k != "zone"}
    return {zone["shape"]: _shape(zone, None), **rest}


def _shape(table: dict[str, object], vertices: str | None) -> object:
    """A circle's or polygon's file form: without its tag; a polygon's vertices."""
    if table["shape"] == "polygon":
        return {vertices: table["vertices"]} if vertices else table["vertices"]
    return {k: v for k, v in table.items() if k != "shape"}


def _pruned(value: object) -> object:
    """``value`` without absent keys (None, empty lists): a file has no null."""
    if isinstance(value, dict):
        return {k: _pruned(v) for k, v in value.items() if v is not None and v != []}
    return [_pruned(v) for v in value] if isinstance(value, list) else value


# -- files -----------------------------------------------------------------------------


def load_toml(path: str | Path) -> ProblemSpec | SectionProblemSpec:
    """Read a problem from a TOML file: a section's if it has a ``[section]`` table.

    Its keys: :func:`problem_from_dict` (a plate) or :func:`section_from_dict`.

    Raises:
        InputError: The file is not UTF-8 TOML, or describes an invalid problem; the
            message names the file.
        OSError: The file cannot be read.
    """
    path = Path(path)
    data, _ = read_problem_data(path)
    try:
        return spec_from_dict(data, name=path.stem)
    except ValueError as err:
        raise InputError(f"{path}: {err}") from None


def read_problem_data(path: str | Path) -> tuple[dict[str, Any], str | None]:
    """The mapping a problem file holds, unchecked, and the units of a result's re-run.

    A TOML file's tables (a gmsh file's path made absolute, as it is found next to the
    problem file), or a JSON result's ``input`` (in SI) with the ``units`` of the file it
    solved; ``None`` for a problem file. :func:`spec_from_dict` checks the mapping.

    Raises:
        InputError: The file is not UTF-8 TOML or a JSON result or problem.
        OSError: The file cannot be read.
    """
    path = Path(path)
    if path.suffix.lower() == ".json":
        try:
            data = json.loads(path.read_bytes().decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as err:
            raise InputError(f"{path}: not a JSON result or problem file: {err}") from None
        if not (isinstance(data, dict) and "input" in data):
            return _table(data, path), None
        units = data.get("units", "SI")
        if units not in UNITS:
            raise InputError(f"{path}: units must be one of {tuple(UNITS)}, got {units!r}")
        if data["input"] is None:
            raise InputError(f"{path}: this result's problem has no file form (a predicate zone)")
        return _table(data["input"], path), units
    try:
        data = tomllib.loads(path.read_bytes().decode("utf-8"))
    except UnicodeDecodeError as err:
        raise InputError(
            f"{path}: not a UTF-8 text file ({err.reason} at byte {err.start})"
        ) from None
    except tomllib.TOMLDecodeError as err:
        raise InputError(f"{path}: invalid TOML: {err}") from None
    _refuse_empty(data, path)
    plate = data.get("plate")
    if isinstance(plate, dict) and isinstance(plate.get("file"), str):
        # A gmsh file is found next to the problem file.
        plate["file"] = str((path.parent / plate["file"]).resolve())
    return data, None


def _table(data: object, path: Path) -> dict[str, Any]:
    """``data`` if it is a JSON object (a problem's tables), else an error naming ``path``."""
    if not isinstance(data, dict):
        raise InputError(f"{path}: a problem is a JSON object of tables, got {type(data).__name__}")
    _refuse_empty(data, path)
    return data


#: The file's top-level keys that are not tables (the schema's ``name`` and ``units``):
#: they name the problem and its units, but no plate or section.
TOP_LEVEL_SCALARS = ("name", "units")


def _refuse_empty(data: Mapping[str, object], path: Path) -> None:
    """Refuse a problem file that holds no table: empty, comments only, or only top-level keys.

    Every key has a default, so a file without a table would solve the default plate in
    silence (a file emptied by mistake, the wrong path, the tables left out): it names no
    plate or section. Unknown top-level keys, and a wrong name or units, are left to the
    schema's message.
    """
    needs = (
        "a problem file needs at least one table, e.g. [plate] (the plate's corners or "
        "outline, thickness) or [section] (a section); the keys it leaves out take their "
        "defaults"
    )
    if not data:
        raise InputError(
            f"{path}: holds no table or key (an empty file, comments only, or {{}}): {needs}"
        )
    valid = isinstance(data.get("name", ""), str) and data.get("units", "SI") in tuple(UNITS)
    if set(data) <= set(TOP_LEVEL_SCALARS) and valid:
        given = ", ".join(f"{key} = {data[key]!r}" for key in TOP_LEVEL_SCALARS if key in data)
        raise InputError(f"{path}: holds no table, only the top-level key(s) {given}: {needs}")


def load_problem(path: str | Path) -> ProblemSpec | SectionProblemSpec:
    """A problem file: TOML, or the JSON of a result (its ``input``, which re-runs it).

    A result's ``input`` is in SI; its ``units`` (the unit system of the file it solved)
    become the problem's, so that the re-run prints, and ``--set`` reads, in that system.

    Raises:
        InputError: An invalid file or problem; the message names the file.
        OSError: The file cannot be read.
    """
    path = Path(path)
    if path.suffix.lower() != ".json":
        return load_toml(path)
    data, units = read_problem_data(path)
    try:
        spec = spec_from_dict(data, name=path.stem)
    except ValueError as err:
        raise InputError(f"{path}: {err}") from None
    return spec if units is None else msgspec.structs.replace(spec, units=units)
