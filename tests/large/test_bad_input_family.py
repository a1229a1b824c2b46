r"""The bad-input family: every key of the problem file given a bad value, and bad files.

Five base problem files hold every key of the schema (README, "Problem files"): a steel
rectangle with every edge key, three obstacles (box, polygon, circle), every solver key
and design output; a bilateral foundation on an anisotropic material; an outline with
holes, segments and a cell size; restrained edges, fixed and thermal loads, point
restraints and a gapped obstacle; a laminate. Each of their values, and each number
inside a list value, is replaced in turn by a value of the wrong type (a string, a
boolean, a list, a table), by nan, inf or -inf, and by values out of its range
(:data:`OUT_OF_RANGE`); the file is written as TOML and given to ``unibuckle solve
--config``. Each must exit with status 2, before any mesh is built, with a message that
names the file and the key (``material.E``, ``obstacles[1].polygon``,
``plate.holes[0].radius``, ...) and no traceback. Then the files themselves: missing, a
folder, not UTF-8, not TOML, a JSON result without a problem; and outputs that cannot be
written.

The default run takes every :data:`SAMPLE_STEP`-th case; ``-m stress`` runs them all.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import pytest

from support.problem_files import BASES, FEATURES, FOUNDATION, OUTLINE, RECTANGLE
from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, main
from unibuckle_fenicsx.spec import problem_from_dict

SAMPLE_STEP = 8
#: The family's size: keys (and numbers inside list values) and bad values in all.
KEYS, VALUES = 210, 1409

#: The arrays of tables ([[key]]): their entries are named key[k].
TABLE_ARRAYS = ("obstacles", "holes", "points", "plies")
#: Values out of range, by key (numbers of the right type); a pair (value, name) when the
#: message rightly names another key (a hole too large for the plate: the hole).
OUT_OF_RANGE: dict[str, list[Any]] = {
    "thickness": [0.0, -0.006, 10.0],
    "E": [0.0, -1.0e9],
    "nu": [0.5, -1.0, 0.7],
    "shear_correction": [0.0, -1.0],
    "nx": [1, 0, -3],
    "ny": [1],
    "size": [0.0, -0.01],
    "tau": [0.0, 0.5],
    "eps_tol": [0.0, 1e-3],
    "max_candidates": [0],
    "enumeration_budget_s": [0.0],
    "max_iterations": [0],
    "bound_budget": [-1],
    "penalty": [0.0],
    "prestress_degree": [0],
    "tolerance": [-1e-9],
    "foundation_stiffness": [0.0, -1.0],
    "radius": [0.0, -0.02],
    "segments": [[7], [1, 1]],
    "thermal_expansion": [-1.2e-5],
    "E1": [0.0, -1.0],
    "E2": [0.0],
    "G12": [0.0],
    "G13": [-1.0],
    "G23": [0.0],
    "nu12": [4.0],  # |nu12| < sqrt(E1/E2) = 3.74 for a positive definite ply
    "angle": [1e300, 361.0, -400.0],  # |angle| <= 360 degrees
    "rotational_stiffness": [-1.0],
    "translational_stiffness": [-1.0],
    "yield_stress": [0.0, -1.0],
    "partial_factor": [0.0, 0.9],
    "stiffness": [0.0, -1.0],
    "spacing": [[0.0, 0.05], [-0.1, 0.05]],
    "gap": [-1e-4],
}
#: Keys whose value is a choice, and values not among the choices.
CHOICES = {"support", "inplane", "side", "method", "shear", "units", "kind"}
#: Keys that are booleans.
BOOLEANS = {"complete", "until_proven", "certify", "bracket"}


def _name(path: tuple) -> str:
    """How a message names the key at ``path``: tables dotted, [[array]] entries indexed."""
    out = ""
    for k, part in enumerate(path):
        if isinstance(part, int):
            if path[k - 1] in TABLE_ARRAYS:
                out += f"[{part}]"
                continue
            break  # an entry of a list value: the key is named
        out += f".{part}" if out else part
    return out


def _leaves(node: Any, path: tuple = ()):
    """Every (path, value) of a key, and of each number inside a list value."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _leaves(value, (*path, key))
    elif isinstance(node, list) and path[-1] in TABLE_ARRAYS:
        for k, value in enumerate(node):
            yield from _leaves(value, (*path, k))
    else:
        yield path, node
        yield from _numbers(node, path)


def _numbers(value: Any, path: tuple):
    """(path, number) of each number inside a list value, at any depth."""
    if isinstance(value, list):
        for k, entry in enumerate(value):
            if isinstance(entry, list):
                yield from _numbers(entry, (*path, k))
            else:
                yield (*path, k), entry


def _bad_values(path: tuple, value: Any) -> list[tuple[Any, str]]:
    """The bad values of the key at ``path``, each with the key its message must name."""
    key = next(p for p in reversed(path) if isinstance(p, str))
    name = _name(path)
    whole = not isinstance(path[-1], int)
    if key in CHOICES and whole:
        bad: list[Any] = [1.5, True, "nonsense", [value]]
    elif key in BOOLEANS:
        bad = ["false", 1, [True]]
    elif key == "name":
        bad = [1.5, True, ["x"]]
    elif key == "zone" and value == "all":
        bad = ["everything", 1.0, True]
    else:
        bad = ["x", True, math.nan, math.inf, -math.inf]
        if whole:
            bad += [{"a": 1.0}, [[1.0, 2.0]]]
            # A list where a number goes, and a number where a list goes (a stress is
            # either).
            if not isinstance(value, list):
                bad.append([1.0])
            elif not key.endswith("_stress") and key != "spacing":  # a number is one too
                bad.append(1.0)
            # A ply 10 m thick: the stack's thickness is refused (plate.thickness), or its
            # symmetry; the ply's own range is > 0.
            bad += [v for v in OUT_OF_RANGE.get(key, []) if "plies" not in path or v != 10.0]
    cases = [(v, name) for v in bad]
    if key == "radius" and "holes" in path:
        cases.append((1.0, name.removesuffix(".radius")))  # the hole leaves the plate
    return cases


def _set(data: Any, path: tuple, value: Any) -> Any:
    data = json.loads(json.dumps(data))
    node = data
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value
    return data


def _cases() -> list[tuple[str, list[tuple[Any, dict, str]]]]:
    """Per key of each base: its label, and (bad value, problem, name to find) for each."""
    cases = []
    for base_name, base in BASES.items():
        problem_from_dict(base)  # the base itself is valid
        for path, value in _leaves(base):
            bad = [(v, _set(base, path, v), name) for v, name in _bad_values(path, value)]
            cases.append((f"{base_name}:{'.'.join(map(str, path))}", bad))
    return cases


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return "{" + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + "}"


def to_toml(data: dict, prefix: str = "") -> str:
    """A problem mapping as TOML: tables, arrays of tables, inline values."""
    lines = [f"{k} = {_toml_value(v)}" for k, v in data.items() if not _is_table(k, v)]
    out = "\n".join(lines) + ("\n" if lines else "")
    for key, value in data.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict) and _is_table(key, value):
            out += f"[{name}]\n" + to_toml(value, f"{name}.")
        elif _is_table(key, value):
            for entry in value:
                out += f"[[{name}]]\n" + to_toml(entry, f"{name}.")
    return out


def _is_table(key: str, value: Any) -> bool:
    """A table ([key]), or an array of tables ([[key]]); else an inline value."""
    if isinstance(value, dict):
        return True
    return key in TABLE_ARRAYS and isinstance(value, list) and bool(value)


CASES = _cases()


def _refused(path: Path, capsys, *extra: str) -> str:
    assert main(["solve", "--config", str(path), *extra]) == EXIT_BAD_INPUT
    captured = capsys.readouterr()
    assert captured.out == "" and "Traceback" not in captured.err, captured.err
    assert captured.err.startswith("unibuckle: error: "), captured.err
    return captured.err


def _check_key(tmp_path, capsys, cases):
    for value, data, name in cases:
        path = tmp_path / "bad.toml"
        path.write_text(to_toml(data))
        err = _refused(path, capsys)
        assert str(path) in err, (value, err)
        # The key, or an entry of its value (key[i][j]), not a key below it (key[i].sub).
        pattern = rf"(?<![\w.\[]){re.escape(name)}(?!\w)(?!(\[\d+\])+\.)"
        assert re.search(pattern, err), f"{value!r}: {name!r} not in {err}"


#: Values each valid for its key alone that a rule between keys refuses: (label, base,
#: {path: value} (None: the key left out), the key the message must name). The design
#: output's element (EN 1993-1-5 4.4: internal or outstand, or not described) and a
#: one-sided point's side.
RULES: list[tuple[str, str, dict[tuple, Any], str]] = [
    (
        "design: both unloaded edges free",
        "rectangle",
        {("edges", "bottom", "support"): "free"},
        "edges.bottom.support",
    ),
    (
        "design: an unloaded edge on springs",
        "rectangle",
        {("edges", "top", "translational_stiffness"): 1e6},
        "edges.top.translational_stiffness",
    ),
    (
        "design: an unloaded edge held in its plane",
        "rectangle",
        {("edges", "bottom", "inplane"): "roller"},
        "edges.bottom.inplane",
    ),
    (
        "design: biaxial normal stress",
        "rectangle",
        {("edges", "bottom", "normal_stress"): -0.5},
        "edges.bottom.normal_stress",
    ),
    (
        "design: psi below Table 4.2's row",
        "rectangle",
        {
            ("edges", "left", "normal_stress"): [-1.0, 2.0],
            ("edges", "right", "normal_stress"): [-1.0, 2.0],
        },
        "edges.left.normal_stress",
    ),
    (
        "design: a temperature rise",
        "features",
        {("design",): {"yield_stress": 3.55e8}},
        "load.temperature",
    ),
    ("design: an outline", "outline", {("design",): {"yield_stress": 3.55e8}}, "plate.outline"),
    ("design: a laminate", "laminate", {("design",): {"yield_stress": 3.55e8}}, "material.plies"),
    ("design: aluminium", "rectangle", {("material", "E"): 7.0e10}, "material.E"),
    (
        "design: a general stiffness",
        "foundation",
        {("design",): {"yield_stress": 3.55e8}},
        "material.membrane_voigt",
    ),
    (
        "a one-sided point without its side",
        "features",
        {("points", 2, "side"): None},
        "points[2].side",
    ),
]  # fmt: skip


def _changed(base: dict, changes: dict[tuple, Any]) -> dict:
    data = json.loads(json.dumps(base))
    for path, value in changes.items():
        node = data
        for part in path[:-1]:
            node = node[part]
        if value is None:
            del node[path[-1]]
        else:
            node[path[-1]] = value
    return data


@pytest.mark.parametrize(("label", "base", "changes", "name"), RULES, ids=[r[0] for r in RULES])
def test_rules_between_keys(tmp_path, capsys, nothing_built, label, base, changes, name):
    """Each value valid alone, refused by a rule between keys: exit 2, the key named."""
    _check_key(tmp_path, capsys, [(changes, _changed(BASES[base], changes), name)])


SAMPLE = CASES[::SAMPLE_STEP]
REST = [c for k, c in enumerate(CASES) if k % SAMPLE_STEP]


@pytest.mark.parametrize(("label", "cases"), SAMPLE, ids=[c[0] for c in SAMPLE])
def test_bad_values_sample(tmp_path, capsys, nothing_built, label, cases):
    """Every bad value of every :data:`SAMPLE_STEP`-th key."""
    _check_key(tmp_path, capsys, cases)


@pytest.mark.stress
@pytest.mark.parametrize(("label", "cases"), REST, ids=[c[0] for c in REST])
def test_bad_values_family(tmp_path, capsys, nothing_built, label, cases):
    """Every bad value of the other keys (``-m stress``)."""
    _check_key(tmp_path, capsys, cases)


def test_every_key_is_in_the_family():
    """The bases hold every key of the schema (a new key must join them); the counts."""
    from msgspec.structs import fields

    from unibuckle_fenicsx.spec import (
        OBSTACLE_KEYS,
        PLY_KEYS,
        DesignSpec,
        EdgeSpec,
        LoadSpec,
        Material,
        MeshSpec,
        PointSpec,
        SolverSpec,
    )

    covered = {
        tuple(p for p in path if isinstance(p, str))[-2:]
        for base in BASES.values()
        for path, _ in _leaves(base)
    }
    covered |= {(k,) for base in BASES.values() for k in base if not isinstance(base[k], dict)}
    wanted = {("name",), ("units",)}
    wanted |= {("plate", k) for k in ("corners", "thickness", "outline")}
    wanted |= {("holes", k) for k in ("center", "radius", "outline")}
    wanted |= {("material", f.name) for f in fields(Material) if f.name != "plies"}
    wanted |= {(e, k) for e in ("left", "right", "ends") for k in ("support",)}
    wanted |= {("left", k) for k in ("inplane", "normal_stress", "shear_stress")}
    wanted |= {("ends", "segments")}
    wanted |= {("mesh", f.name) for f in fields(MeshSpec)}
    wanted |= {("solver", f.name) for f in fields(SolverSpec)}
    wanted |= {("load", f.name) for f in fields(LoadSpec)}
    wanted |= {("design", f.name) for f in fields(DesignSpec)}
    wanted |= {("points", f.name) for f in fields(PointSpec)}
    wanted |= {("plies", k) for k in PLY_KEYS}
    edge_keys = {f.name for f in fields(EdgeSpec)} - {"name", "tag", "segments"}
    edge_names = {"left", "right", "bottom", "top", "ends", "sides"}
    missing_edge_keys = edge_keys - {k for e, *k in covered if e in edge_names for k in k}
    assert not missing_edge_keys, missing_edge_keys
    keys = set(OBSTACLE_KEYS) - {"circle"} | {"center", "radius"}
    obstacle_keys = {k for path, _ in _leaves(RECTANGLE) if "obstacles" in path for k in path}
    for base in (FOUNDATION, OUTLINE, FEATURES):
        obstacle_keys |= set(base["obstacle"])
    assert keys <= obstacle_keys, keys - obstacle_keys
    missing = wanted - covered
    assert not missing, missing
    labels = [label for label, _ in CASES]
    assert len(labels) == len(set(labels))
    assert (len(CASES), sum(len(cases) for _, cases in CASES)) == (KEYS, VALUES)


def test_the_toml_writer_round_trips(tmp_path):
    """The family's files say what it means: each base, written and read back, is itself."""
    import tomllib

    for base in BASES.values():
        assert tomllib.loads(to_toml(base)) == json.loads(json.dumps(base))


@pytest.mark.parametrize(
    ("kind", "message"),
    [
        ("missing", "--config {path}: cannot read it (No such file or directory)"),
        ("folder", "--config {path}: cannot read it (Is a directory)"),
        ("binary", "{path}: not a UTF-8 text file"),
        ("syntax", "{path}: invalid TOML"),
        ("empty result", "{path}: this result's problem has no file form"),
        ("foreign json", "{path}: unknown key(s) ['critical'] in [top]"),
        ("geo missing", "plate.file: no such file"),
        ("geo suffix", "plate.file must be a gmsh .geo or .msh file"),
    ],
)
def test_bad_files(tmp_path, capsys, nothing_built, kind, message):
    path = tmp_path / ("p.json" if kind in ("empty result", "foreign json") else "p.toml")
    if kind == "folder":
        path.mkdir()
    elif kind == "binary":
        path.write_bytes(b"\xff\xfe[plate]\n")
    elif kind == "syntax":
        path.write_text("[plate\nthickness = 0.006\n")
    elif kind == "empty result":
        path.write_text(json.dumps({"critical_load_Pa": 1.0, "input": None}))
    elif kind == "foreign json":
        path.write_text(json.dumps({"critical": 1.0}))
    elif kind == "geo missing":
        path.write_text('[plate]\nfile = "nowhere.geo"\n')
    elif kind == "geo suffix":
        (tmp_path / "plate.stl").write_text("")
        path.write_text('[plate]\nfile = "plate.stl"\n')
    err = _refused(path, capsys)
    assert message.format(path=path) in err, err
