"""The JSON Schema of a problem file, from the Structs, and every key it accepts.

``msgspec.json.schema`` writes the Structs' form; :func:`json_schema` turns it into
the file's (the edge tables under ``edges``, an obstacle's ``polygon`` and ``circle``
keys, a hole's ``outline``: :mod:`~unibuckle_fenicsx.spec.files`) and gives each key the
description its Struct's docstring gives it (its ``Args:`` entry: msgspec reads a field's
description only from its ``Meta``, and the docstring is where the API documents it). A
section's file (:mod:`~unibuckle_fenicsx.spec.section`) is the schema's other branch.
"""

from __future__ import annotations

import inspect
import re

import msgspec

from unibuckle_fenicsx.spec.base import Table, as_table, as_tables
from unibuckle_fenicsx.spec.plate import PlateSpec
from unibuckle_fenicsx.spec.problem import ProblemSpec
from unibuckle_fenicsx.spec.section import SectionProblemSpec

__all__ = ["accepted_keys", "json_schema"]


def json_schema() -> dict[str, object]:
    """The JSON Schema (draft 2020-12) of a problem file, as a mapping.

    A plate's file or a section's (one with a ``[section]`` table): ``anyOf`` the two.
    """
    tops, defs = msgspec.json.schema_components([ProblemSpec, SectionProblemSpec])
    schema = {"anyOf": list(tops), "$defs": defs}
    for name, cls in _tables(Table).items():
        if (node := defs.get(name)) is None:
            continue
        node["description"] = inspect.cleandoc(cls.__doc__ or "").split("\n\n")[0]
        for key, text in field_docs(cls).items():
            if key in node["properties"]:
                node["properties"][key]["description"] = text
        hidden = {*cls.CODE_ONLY, cls.__struct_config__.tag_field}  # the Python API's
        node["properties"] = {k: v for k, v in node["properties"].items() if k not in hidden}
        for prop in node["properties"].values():  # absent, in a file: TOML has no null
            if "default" in prop and prop["default"] is None:
                del prop["default"]
        node["required"] = [k for k in node.get("required", []) if k not in hidden]
    vertices = defs.pop("Polygon")["properties"]["vertices"]
    top = list(defs["ProblemSpec"]["properties"].items())
    at = [k for k, _ in top].index("material") + 1
    edges = {
        "type": "object",
        "additionalProperties": {"$ref": "#/$defs/EdgeSpec"},
        "description": "The [edges.NAME] tables. " + field_docs(PlateSpec)["edges"],
    }
    defs["ProblemSpec"]["properties"] = dict([*top[:at], ("edges", edges), *top[at:]])
    plate = defs["PlateSpec"]["properties"]
    circle = {"$ref": "#/$defs/Circle"}
    outline = {"type": "object", "properties": {"outline": vertices}, "required": ["outline"]}
    plate["holes"]["items"] = {"anyOf": [circle, outline | {"additionalProperties": False}]}
    obstacle = defs["ObstacleSpec"]["properties"]
    zone = obstacle.pop("zone")
    zone["anyOf"] = [a for a in zone["anyOf"] if "discriminator" not in a]
    defs["ObstacleSpec"]["properties"] = {
        "zone": zone,
        "polygon": vertices | {"description": "The zone: a polygon [[x, y], ...] (m)."},
        "circle": circle | {"description": "The zone: a circle {center, radius} (m)."},
        **obstacle,
    }
    defs["Material"]["required"] = []  # a laminate's E and nu are its plies'
    # a file's nu is an isotropic material's (a laminate's nu_xy, which may exceed 0.5
    # as that of a +-45 stack does, comes from its plies)
    defs["Material"]["properties"]["nu"] |= {"exclusiveMinimum": -1.0, "exclusiveMaximum": 0.5}
    head = {"$schema": "https://json-schema.org/draft/2020-12/schema"}
    head["title"] = "unibuckle_fenicsx problem file"
    return as_table(msgspec.json.decode(msgspec.json.encode(head | schema)))  # lists


def field_docs(cls: type) -> dict[str, str]:
    """Each field's entry in the ``Args:`` section of ``cls``'s docstring (Google style)."""
    found: dict[str, str] = {}
    section = inspect.cleandoc(cls.__doc__ or "").partition("\nArgs:\n")[2]
    for line in section.splitlines():
        if line and not line.startswith(" "):  # the next section
            break
        if match := re.match(r"    (\w+): (.*)", line):
            name = match[1]
            found[name] = match[2]
        elif found and line.strip():
            found[name] += " " + line.strip()
    return found


def _tables(cls: type[Table]) -> dict[str, type[Table]]:
    """The tables (Structs) derived from ``cls``, by name."""
    found: dict[str, type[Table]] = {}
    for sub in cls.__subclasses__():
        found |= {sub.__name__: sub, **_tables(sub)}
    return found


def accepted_keys() -> list[str]:
    """Every dotted key a problem file may hold, in the schema's order.

    A list of tables is written ``[]`` (``plate.holes[].radius``), the name of an
    ``[edges.NAME]`` table ``<name>`` (``edges.<name>.support``).
    """
    schema = json_schema()
    defs = as_table(schema["$defs"])
    keys: list[str] = []

    def resolve(node: object) -> dict[str, object]:
        ref = as_table(node).get("$ref")
        return as_table(defs[ref.rpartition("/")[2]]) if isinstance(ref, str) else as_table(node)

    def tables(node: object) -> list[tuple[dict[str, object], str]]:
        """The tables a value may be (with the suffix ``[]`` for a list of them)."""
        node = resolve(node)
        found = [t for a in as_tables(node.get("anyOf", [])) for t in tables(a)]
        if "properties" in node or isinstance(node.get("additionalProperties"), dict):
            found.append((node, ""))
        if node.get("type") == "array" and isinstance(items := node.get("items"), dict):
            found += [(t, "[]" + s) for t, s in tables(items)]
        return found

    def visit(node: dict[str, object], prefix: str) -> None:
        for key, sub in as_table(node.get("properties", {})).items():
            found = tables(sub)
            if not found and prefix + key not in keys:
                keys.append(prefix + key)
            for table, suffix in found:
                visit(table, f"{prefix}{key}{suffix}.")
        if isinstance(extra := node.get("additionalProperties"), dict):
            visit(resolve(extra), f"{prefix}<name>.")

    for top, _ in tables(schema):  # a plate's file, a section's
        visit(top, "")
    return keys
