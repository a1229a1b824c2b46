"""The loader: a TOML-shaped mapping, a TOML file or a JSON result to a ProblemSpec."""

from __future__ import annotations

import json
import math
import tomllib
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.spec.material import Material, Ply
from unibuckle_fenicsx.spec.obstacles import DesignSpec, LoadSpec, ObstacleSpec, PointSpec
from unibuckle_fenicsx.spec.plate import (
    Circle,
    EdgeSpec,
    MeshSpec,
    PlateSpec,
    Polygon,
    _polygon,
    paper_edges,
)
from unibuckle_fenicsx.spec.problem import ProblemSpec, SolverSpec
from unibuckle_fenicsx.spec.schema import validate_document
from unibuckle_fenicsx.spec.units import _to_si
from unibuckle_fenicsx.spec.values import (
    EDGE_NAMES,
    HOLES,
    UNITS,
    _choice,
)


def _edge_tables(given: Mapping[str, Any], names: tuple[str, ...]) -> dict[str, Any]:
    """The ``[edges.NAME]`` tables: a name the plate has (the schema cannot know them)."""
    unknown = sorted(set(given) - set(names))
    if unknown:
        raise InputError(f"unknown key(s) {unknown} in [edges]; allowed: {list(names)}")
    return dict(given)


#: Keys of an ``[obstacle]`` or ``[[obstacles]]`` table.
OBSTACLE_KEYS = ("zone", "polygon", "circle", "side", "foundation_stiffness", "tolerance", "gap")


def _holes(tables: Any) -> tuple[Circle | Polygon, ...]:
    """``[[plate.holes]]`` tables: center and radius (a circle) or outline (a polygon)."""
    if not isinstance(tables, list):
        raise InputError(f"plate.holes must be a list of tables ([[plate.holes]]), got {tables!r}")
    holes: list[Circle | Polygon] = []
    for k, table in enumerate(tables):
        where = f"plate.holes[{k}]"
        kw = dict(table)
        if set(kw) == {"outline"}:
            holes.append(Polygon(_polygon(f"{where}.outline", kw["outline"])))
        elif set(kw) == {"center", "radius"}:
            try:
                holes.append(Circle(kw["center"], kw["radius"]))
            except ValueError as err:
                # Circle's messages name circle.center/radius; the file's keys are these.
                raise InputError(f"{where}.{str(err).removeprefix('circle.')}") from None
        else:
            raise InputError(
                f"[{where}] needs center = [x, y] and radius = r (a circle), or outline = "
                f"[[x, y], ...] (a polygon); got {sorted(kw)}"
            )
    return tuple(holes)


def _obstacle_from_table(table: Any, where: str) -> ObstacleSpec:
    """An :class:`ObstacleSpec` from its table; messages name ``where`` (e.g. obstacles[1])."""
    kw = dict(table)
    given = [key for key in ("zone", "polygon", "circle") if key in kw]
    if len(given) != 1:
        raise InputError(
            f'[{where}] needs zone = "all" (the whole plate) or [[xmin, xmax], [ymin, ymax]], '
            "or polygon = [[x, y], ...], or circle = {center = [x, y], radius = r}: exactly "
            f"one of them; got {given or 'none'}"
        )
    try:
        if "polygon" in kw:
            kw["zone"] = Polygon(_polygon(f"{where}.polygon", kw.pop("polygon")))
        elif "circle" in kw:
            circle = dict(kw.pop("circle"))
            if set(circle) != {"center", "radius"}:
                raise InputError(f"{where}.circle needs center = [x, y] and radius = r")
            kw["zone"] = Circle(**circle)
        return ObstacleSpec(**kw)
    except ValueError as err:
        message = str(err)
        if message.startswith("obstacle."):
            message = where + message[len("obstacle") :]
        elif message.startswith("circle."):
            message = f"{where}.{message}"
        raise InputError(message) from None


def problem_from_dict(data: Mapping[str, Any], name: str = "plate") -> ProblemSpec:
    """Build a :class:`ProblemSpec` from a TOML-shaped mapping (:doc:`/guide/plate`).

    Tables: ``[plate]`` (corners, or outline, or file; thickness; ``[[plate.holes]]``
    with center and radius, or outline), ``[material]`` (E, nu, shear_correction,
    membrane_voigt, bending_voigt), ``[edges.<name>]`` (support, inplane,
    normal_stress, shear_stress, segments), ``[mesh]`` (nx, ny; or size, a cell size),
    ``[obstacle]`` (zone, polygon or circle, side, foundation_stiffness, tolerance;
    absent = free plate) or several ``[[obstacles]]``
    with the same keys, ``[solver]`` (the :class:`SolverSpec` fields);
    top-level ``name`` and ``units``. Unknown tables or keys raise ``ValueError``.

    Missing values take the paper's, with one exception for the load: if any edge table
    gives ``normal_stress``, ``shear_stress`` or a fixed stress, or the file has a
    ``[load]`` table, the edges that give no stress carry no load (the paper's unit
    compression of the short edges applies only to a file that sets no load at all).
    """
    # The schema first: types, choices and keys, named where they are; a bound it finds
    # violated is reported by the dataclasses' checks below, which give the unit.
    out_of_bounds = validate_document(data)
    top = dict(data)
    units = _choice("units", top.get("units", "SI"), tuple(UNITS))
    top = _to_si(top, units)
    plate_kw = dict(top.get("plate", {}))
    gmsh_plate = any(key in plate_kw for key in ("outline", "file"))
    if gmsh_plate and "corners" in plate_kw:
        raise InputError(
            "[plate]: give corners (a rectangle), or outline (a polygon) or file (a gmsh "
            "file), not both"
        )
    if "holes" in plate_kw:
        plate_kw["holes"] = _holes(plate_kw["holes"])
    given = top.get("edges", {})
    if gmsh_plate:  # a file's or an outline's part names are checked by PlateSpec
        names = tuple(given) if isinstance(given, Mapping) else ()
    else:
        names = (*EDGE_NAMES, HOLES) if "holes" in plate_kw else EDGE_NAMES
    edge_tables = _edge_tables(given, names)
    edges = {} if gmsh_plate else {e.name: e for e in paper_edges()}
    load_keys = ("normal_stress", "shear_stress", "fixed_normal_stress", "fixed_shear_stress")
    loads_given = any(
        key in table for table in edge_tables.values() if isinstance(table, Mapping)
        for key in load_keys
    ) or (isinstance(top.get("load"), Mapping) and bool(top["load"]))  # fmt: skip
    if loads_given:
        edges = {n: replace(e, normal_stress=0.0, shear_stress=0.0) for n, e in edges.items()}
    for edge_name, edge_table in edge_tables.items():
        kw = dict(edge_table)
        edge = edges.get(edge_name, EdgeSpec(edge_name))
        edges[edge_name] = replace(edge, **kw)
    plate = PlateSpec(**plate_kw, edges=tuple(edges.values()))
    material = _material(top.get("material", {"E": 1.0e9, "nu": 0.3}))
    if material.plies:
        total = sum(ply.thickness for ply in material.plies)
        if "thickness" not in plate_kw:
            plate = replace(plate, thickness=total)
        elif not math.isclose(plate.thickness, total, rel_tol=1e-9):
            raise InputError(
                f"plate.thickness = {plate.thickness!r} m differs from the plies' total "
                f"{total!r} m: leave plate.thickness out for a laminate (it is the plies')"
            )
    mesh_kw = dict(top.get("mesh", {}))
    if plate.meshed_by_gmsh:
        if "nx" in mesh_kw or "ny" in mesh_kw:
            raise InputError(
                "[mesh]: a plate meshed by gmsh (outline, holes or file) takes size = h (the "
                "characteristic cell size), not nx and ny"
            )
    elif "size" in mesh_kw:
        if "nx" in mesh_kw or "ny" in mesh_kw:
            raise InputError("[mesh]: give size (a cell size) or nx and ny, not both")
        mesh_kw["nx"], mesh_kw["ny"] = MeshSpec.cells_for(
            plate.length, plate.width, mesh_kw["size"]
        )
    mesh = MeshSpec(**mesh_kw)
    obstacle = None
    if "obstacle" in top:
        obstacle = _obstacle_from_table(top["obstacle"], "obstacle")
    obstacles: list[ObstacleSpec] = []
    if "obstacles" in top:
        tables = top["obstacles"]
        if not isinstance(tables, list) or not tables:
            raise InputError(
                "obstacles must be a list of tables ([[obstacles]] in TOML), at least one, "
                f"got {tables!r}"
            )
        if obstacle is not None:
            raise InputError("give one [obstacle] table or several [[obstacles]] tables, not both")
        obstacles = [_obstacle_from_table(t, f"obstacles[{k}]") for k, t in enumerate(tables)]
    points = _points(top["points"]) if "points" in top else ()
    load = LoadSpec(**dict(top.get("load", {})))
    design = None
    if "design" in top:
        design_kw = dict(top["design"])
        if "yield_stress" not in design_kw:
            raise InputError("[design] needs yield_stress (f_y)")
        design = DesignSpec(**design_kw)
    solver = SolverSpec(**dict(top.get("solver", {})))
    label = top.get("name", name)
    if not isinstance(label, str):
        raise InputError(f"name must be a string, got {label!r}")
    spec = ProblemSpec(
        name=label,
        plate=plate,
        material=material,
        mesh=mesh,
        obstacle=obstacle,
        solver=solver,
        units=units,
        obstacles=tuple(obstacles),
        points=points,
        load=load,
        design=design,
    )
    if out_of_bounds is not None:  # the schema's bound, if no check above caught it
        raise InputError(out_of_bounds)
    return spec


#: Keys of a ``[[material.plies]]`` table.
PLY_KEYS = ("thickness", "angle", "E1", "E2", "G12", "nu12", "G13", "G23")


def _material(table: Any) -> Material:
    """``[material]``: E and nu, or ``[[material.plies]]`` (a laminate)."""
    kw = dict(table)
    if "plies" not in kw:
        for key in ("E", "nu"):
            if key not in kw:
                raise InputError(f"[material] needs {key!r} (or [[material.plies]])")
        return Material(**kw)
    other = sorted(set(kw) - {"plies", "shear_correction", "thermal_expansion"})
    if other:
        raise InputError(
            f"[material] with plies takes shear_correction only besides them, not {other}: "
            "a laminate's stiffness (and its E_x, nu_xy) comes from its plies"
        )
    tables = kw.pop("plies")
    if not isinstance(tables, list) or not tables:
        raise InputError(
            "material.plies must be a list of tables ([[material.plies]] in TOML), at least "
            f"one, got {tables!r}"
        )
    plies = []
    for k, ply in enumerate(tables):
        where = f"material.plies[{k}]"
        ply_kw = dict(ply)
        missing = [key for key in PLY_KEYS if key not in ply_kw]
        if missing:
            raise InputError(f"[{where}] needs {missing} (keys: {list(PLY_KEYS)})")
        try:
            plies.append(Ply(**ply_kw))
        except ValueError as err:
            raise InputError(str(err).replace("material.plies.", f"{where}.")) from None
    if kw.pop("thermal_expansion", 0.0):
        Material(E=1.0, nu=0.0, thermal_expansion=1.0, plies=tuple(plies))  # raises
    return Material.from_plies(plies, **kw)


def _points(tables: Any) -> tuple[PointSpec, ...]:
    """``[[points]]`` tables; messages name ``points[k]``."""
    if not isinstance(tables, list) or not tables:
        raise InputError(
            f"points must be a list of tables ([[points]] in TOML), at least one, got {tables!r}"
        )
    out = []
    for k, table in enumerate(tables):
        kw = dict(table)
        try:
            out.append(PointSpec(**kw))
        except ValueError as err:
            message = str(err)
            if message.startswith("points"):
                message = f"points[{k}]" + message[len("points") :]
            raise InputError(message) from None
    return tuple(out)


def load_toml(path: str | Path) -> ProblemSpec:
    """Read a :class:`ProblemSpec` from a TOML file (schema: :func:`problem_from_dict`).

    Raises:
        ValueError: The file is not UTF-8 TOML, or describes an invalid problem; the
            message names the file.
        OSError: The file cannot be read.
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_bytes().decode("utf-8"))
    except UnicodeDecodeError as err:
        raise InputError(
            f"{path}: not a UTF-8 text file ({err.reason} at byte {err.start})"
        ) from None
    except tomllib.TOMLDecodeError as err:
        raise InputError(f"{path}: invalid TOML: {err}") from None
    plate = data.get("plate")
    if isinstance(plate, dict) and isinstance(plate.get("file"), str):
        # A gmsh file is found next to the problem file.
        plate["file"] = str((path.parent / plate["file"]).resolve())
    try:
        return problem_from_dict(data, name=path.stem)
    except ValueError as err:
        raise InputError(f"{path}: {err}") from None


def load_problem(path: str | Path) -> ProblemSpec:
    """A problem file: TOML, or the JSON of a result (its ``input``, which re-runs it).

    Raises:
        ValueError: An invalid file or problem; the message names the file.
        OSError: The file cannot be read.
    """
    path = Path(path)
    if path.suffix.lower() != ".json":
        return load_toml(path)
    try:
        data = json.loads(path.read_bytes().decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise InputError(f"{path}: not a JSON result or problem file: {err}") from None
    if isinstance(data, dict) and "input" in data:
        data = data["input"]
        if data is None:
            raise InputError(f"{path}: this result's problem has no file form (a predicate zone)")
    try:
        return problem_from_dict(data, name=path.stem)
    except ValueError as err:
        raise InputError(f"{path}: {err}") from None
