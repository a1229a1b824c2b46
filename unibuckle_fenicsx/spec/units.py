"""Unit systems: a problem file's numbers converted to SI and back (:data:`UNITS`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from unibuckle_fenicsx.spec.values import (
    UNITS,
    _number,
)


def _scaled(value: Any, factor: float, name: str) -> Any:
    """``value`` (a number or nested lists of numbers) times ``factor``, types checked."""
    if isinstance(value, list | tuple):
        return [_scaled(v, factor, name) for v in value]
    return _number(name, value) * factor


#: Keys converted to SI by a file's ``units``: (table, key) -> powers of (length, stress).
_DIMENSIONS: dict[tuple[str, str], tuple[int, int]] = {
    ("plate", "corners"): (1, 0),
    ("plate", "thickness"): (1, 0),
    ("material", "E"): (0, 1),
    ("material", "membrane_voigt"): (1, 1),  # N/m = Pa m
    ("material", "bending_voigt"): (3, 1),  # N m = Pa m^3
    ("mesh", "size"): (1, 0),
    ("design", "yield_stress"): (0, 1),
}


def _to_si(top: dict[str, Any], units: str, inverse: bool = False) -> dict[str, Any]:
    """Convert the dimensional values of a TOML-shaped mapping between ``units`` and SI.

    From ``units`` to SI, or from SI to ``units`` with ``inverse``.
    """
    length, stress, _ = UNITS[units]
    if units == "SI":
        return top
    sign = -1 if inverse else 1
    out = {k: dict(v) if isinstance(v, Mapping) else v for k, v in top.items()}
    for (table, key), (pl, ps) in _DIMENSIONS.items():
        if isinstance(out.get(table), dict) and key in out[table]:
            factor = (length**pl * stress**ps) ** sign
            out[table][key] = _scaled(out[table][key], factor, f"{table}.{key}")
    load = out.get("load")
    if isinstance(load, dict):
        for key in ("temperature", "fixed_temperature"):
            value = load.get(key)
            if isinstance(value, list) and len(value) == 3:  # K, K/m, K/m
                load[key] = [value[0], *_scaled(value[1:], length**-sign, f"load.{key}")]
    material = out.get("material")
    if isinstance(material, dict) and isinstance(material.get("plies"), list):
        material["plies"] = [
            {
                k: _scaled(
                    v, length**sign if k == "thickness" else stress**sign, f"material.plies.{k}"
                )
                if k in ("thickness", "E1", "E2", "G12", "G13", "G23")
                else v
                for k, v in ply.items()
            }
            if isinstance(ply, Mapping)
            else ply
            for ply in material["plies"]
        ]
    edges = out.get("edges")
    if isinstance(edges, dict):
        out["edges"] = {
            name: _edge_to_si(table, f"edges.{name}", length, stress, sign)
            if isinstance(table, Mapping)
            else table
            for name, table in edges.items()
        }
    plate = out.get("plate")
    if isinstance(plate, dict):
        if "outline" in plate:
            plate["outline"] = _scaled(plate["outline"], length**sign, "plate.outline")
        if isinstance(plate.get("holes"), list):
            plate["holes"] = [
                {
                    k: _scaled(v, length**sign, f"plate.holes[{j}].{k}")
                    if k in ("center", "radius", "outline")
                    else v
                    for k, v in hole.items()
                }
                if isinstance(hole, Mapping)
                else hole
                for j, hole in enumerate(plate["holes"])
            ]
    if isinstance(out.get("obstacle"), dict):
        out["obstacle"] = _obstacle_to_si(out["obstacle"], "obstacle", length**sign, stress**sign)
    for key, convert in (("points", _point_to_si), ("obstacles", _obstacle_to_si)):
        if isinstance(out.get(key), list):
            out[key] = [
                convert(t, f"{key}[{k}]", length**sign, stress**sign)
                if isinstance(t, Mapping)
                else t
                for k, t in enumerate(out[key])
            ]
    return out


#: Keys of an ``[edges.NAME]`` table converted by a file's ``units``: key -> powers of
#: (length, stress).
_EDGE_DIMENSIONS: dict[str, tuple[int, int]] = {
    "translational_stiffness": (0, 1),  # N/m^2 = Pa; rotational_stiffness is N in both
    "fixed_normal_stress": (0, 1),  # Pa (normal_stress is per unit load: no unit)
    "fixed_shear_stress": (0, 1),
}


def _edge_to_si(
    table: Mapping[str, Any], where: str, length: float, stress: float, sign: int
) -> dict[str, Any]:
    """An edge table with its dimensional values converted (see :func:`_to_si`)."""
    out = dict(table)
    for key, (pl, ps) in _EDGE_DIMENSIONS.items():
        if key in out:
            out[key] = _scaled(out[key], (length**pl * stress**ps) ** sign, f"{where}.{key}")
    return out


def _point_to_si(
    table: Mapping[str, Any], where: str, length: float, stress: float
) -> dict[str, Any]:
    """A points table with its lengths times ``length``, its stiffness (N/m) converted."""
    out = dict(table)
    for key in ("at", "spacing", "offset", "region"):
        if key in out:
            out[key] = _scaled(out[key], length, f"{where}.{key}")
    if "stiffness" in out:  # N/m = Pa m
        out["stiffness"] = _scaled(out["stiffness"], stress * length, f"{where}.stiffness")
    return out


def _obstacle_to_si(
    table: Mapping[str, Any], where: str, length: float, stress: float
) -> dict[str, Any]:
    """An obstacle table with its lengths times ``length`` and stresses times ``stress``."""
    out = dict(table)
    for key in ("polygon", "tolerance", "gap"):
        if key in out:
            out[key] = _scaled(out[key], length, f"{where}.{key}")
    if "foundation_stiffness" in out:  # N/m^3 = Pa/m
        out["foundation_stiffness"] = _scaled(
            out["foundation_stiffness"], stress / length, f"{where}.foundation_stiffness"
        )
    if isinstance(out.get("zone"), list):
        out["zone"] = _scaled(out["zone"], length, f"{where}.zone")
    if isinstance(out.get("circle"), Mapping):
        circle = dict(out["circle"])
        for key in ("center", "radius"):
            if key in circle:
                circle[key] = _scaled(circle[key], length, f"{where}.circle.{key}")
        out["circle"] = circle
    return out
