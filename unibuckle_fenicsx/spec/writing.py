"""The writer: a ProblemSpec to its TOML-shaped mapping (the JSON ``input`` echo)."""

from __future__ import annotations

from typing import Any

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.spec.material import Material
from unibuckle_fenicsx.spec.obstacles import ObstacleSpec, PointSpec
from unibuckle_fenicsx.spec.plate import (
    Circle,
    PlateSpec,
    Polygon,
)
from unibuckle_fenicsx.spec.problem import ProblemSpec
from unibuckle_fenicsx.spec.units import _to_si
from unibuckle_fenicsx.spec.values import (
    UNITS,
    _choice,
)


def _plate_table(plate: PlateSpec) -> dict[str, Any]:
    """The file form of the plate."""
    out: dict[str, Any] = {"thickness": plate.thickness}
    if plate.file is not None:
        out["file"] = plate.file
    elif plate.outline is not None:
        out["outline"] = [list(v) for v in plate.outline]
    else:
        out["corners"] = [list(c) for c in plate.corners]
    holes: list[dict[str, Any]] = []
    for hole in plate.holes:
        if isinstance(hole, Circle):
            holes.append({"center": list(hole.center), "radius": hole.radius})
        else:
            holes.append({"outline": [list(v) for v in hole.vertices]})
    if holes:
        out["holes"] = holes
    return out


def _obstacle_table(obstacle: ObstacleSpec) -> dict[str, Any]:
    """The file form of an obstacle (every key with the value used)."""
    zone = obstacle.zone
    out: dict[str, Any] = {}
    if isinstance(zone, Polygon):
        out["polygon"] = [list(v) for v in zone.vertices]
    elif isinstance(zone, Circle):
        out["circle"] = {"center": list(zone.center), "radius": zone.radius}
    elif callable(zone):
        raise InputError("problem_to_dict: a predicate obstacle zone cannot be written")
    else:
        out["zone"] = zone if isinstance(zone, str) else [list(z) for z in zone]
    out["side"] = obstacle.side
    if obstacle.foundation_stiffness is not None:
        out["foundation_stiffness"] = obstacle.foundation_stiffness
    if obstacle.tolerance is not None:
        out["tolerance"] = obstacle.tolerance
    out["gap"] = obstacle.gap
    return out


def _material_table(material: Material) -> dict[str, Any]:
    """The file form of the material (a laminate: its plies, not E and nu)."""
    if material.plies:
        return {
            "shear_correction": material.shear_correction,
            "plies": [dict(vars(ply)) for ply in material.plies],
            "thermal_expansion": material.thermal_expansion,
        }
    out: dict[str, Any] = {
        k: v for k, v in vars(material).items() if v is not None and k != "plies"
    }
    for key in ("membrane_voigt", "bending_voigt"):
        if key in out:
            out[key] = [list(row) for row in out[key]]
    return out


def _point_table(point: PointSpec) -> dict[str, Any]:
    """The file form of a point restraint (every key with the value used)."""
    out: dict[str, Any] = {"kind": point.kind}
    if point.at is not None:
        out["at"] = list(point.at)
    else:
        assert point.spacing is not None
        sx, sy = point.spacing
        out["spacing"] = sx if sx == sy else [sx, sy]
        if point.offset is not None:
            out["offset"] = list(point.offset)
        if point.region is not None:
            out["region"] = [list(r) for r in point.region]
    if point.stiffness is not None:
        out["stiffness"] = point.stiffness
    if point.kind == "one-sided":
        out["side"] = point.side
    return out


def problem_to_dict(spec: ProblemSpec, units: str = "SI") -> dict[str, Any]:
    """The TOML-shaped mapping of ``spec``, every key with the value used.

    ``problem_from_dict(problem_to_dict(spec)) == spec`` for a spec with a box or
    "all" zone on the rectangle (a predicate zone cannot be written; it raises).

    Args:
        spec: The problem.
        units: Unit system of the numbers written (one of :data:`UNITS`); the mapping's
            ``units`` key says which.
    """
    _choice("units", units, tuple(UNITS))
    plate = spec.plate
    mesh = spec.mesh
    out: dict[str, Any] = {
        "name": spec.name,
        "units": "SI",
        "plate": _plate_table(plate),
        "material": _material_table(spec.material),
        "edges": {
            e.name: {
                "support": e.support,
                "inplane": e.inplane,
                "normal_stress": stress_value(e.normal_stress),
                "shear_stress": stress_value(e.shear_stress),
                "rotational_stiffness": e.rotational_stiffness,
                "translational_stiffness": e.translational_stiffness,
                "fixed_normal_stress": stress_value(e.fixed_normal_stress),
                "fixed_shear_stress": stress_value(e.fixed_shear_stress),
            }
            | ({} if e.segments is None else {"segments": list(e.segments)})
            for e in plate.edges
        },
        "mesh": (
            {"size": mesh.size}
            if mesh.size is not None
            else {}
            if plate.meshed_by_gmsh
            else {"nx": mesh.nx, "ny": mesh.ny}
        ),
        "solver": dict(vars(spec.solver)),
    }
    if spec.obstacle is not None:
        out["obstacle"] = _obstacle_table(spec.obstacle)
    if spec.obstacles:
        out["obstacles"] = [_obstacle_table(o) for o in spec.obstacles]
    if spec.points:
        out["points"] = [_point_table(p) for p in spec.points]
    out["load"] = {
        key: list(value) if isinstance(value, tuple) else value
        for key, value in vars(spec.load).items()
    }
    if spec.design is not None:
        out["design"] = dict(vars(spec.design))
    if units != "SI":
        out = _to_si(out, units, inverse=True)
        out["units"] = units
    return out


def stress_value(value: float | tuple[float, float]) -> float | list[float]:
    """An edge stress as written in a file: a number or ``[start, end]``."""
    return list(value) if isinstance(value, tuple) else value
