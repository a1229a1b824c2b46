"""The published schema of a problem file: the file in the repository, the CLI, the keys.

The JSON Schema in ``schema/unibuckle-problem.schema.json`` must be the package's
(:func:`~unibuckle_fenicsx.spec.json_schema`), every key of
:func:`~unibuckle_fenicsx.spec.accepted_keys` must load, and the JSON ``input`` echo
(:func:`~unibuckle_fenicsx.spec.problem_to_dict`) must pass the schema. The documents
below are problems written for this test (README, "Problem files"); the bad-input
family's three bases come from its module.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from support.paths import ROOT
from support.problem_files import BASES
from unibuckle_fenicsx.cli import EXIT_OK, main
from unibuckle_fenicsx.spec import (
    accepted_keys,
    json_schema,
    problem_from_dict,
    problem_to_dict,
    spec_from_dict,
)

SCHEMA_FILE = ROOT / "schema" / "unibuckle-problem.schema.json"

_PLY = {"E1": 140e9, "E2": 10e9, "G12": 5e9, "nu12": 0.3, "G13": 5e9, "G23": 3e9}
#: A symmetric laminate [0/90/0] with edge springs, fixed stresses and points (no design
#: data: EN 1993-1-5 is refused for a laminate; the rectangle's base has it).
LAMINATE = {
    "plate": {"corners": [[0.0, 0.0], [0.2, 0.1]]},
    "material": {
        "shear_correction": 5.0 / 6.0,
        "plies": [{"thickness": 0.002, "angle": a, **_PLY} for a in (0.0, 90.0, 0.0)],
    },
    "edges": {
        "left": {"normal_stress": -1.0, "fixed_normal_stress": -1e6, "fixed_shear_stress": 0.0},
        "right": {"normal_stress": -1.0, "rotational_stiffness": 10.0},
        "top": {"support": "free"},
    },
    "load": {"temperature": 0.0, "fixed_temperature": 0.0, "fixed_factor": 1.0},
    "points": [
        {"at": [0.1, 0.05], "kind": "spring", "stiffness": 1e5},
        {
            "spacing": 0.05,
            "offset": [0.0, 0.0],
            "region": [[0.0, 0.2], [0.0, 0.1]],
            "kind": "one-sided",
            "side": "below",
        },
    ],
    "solver": {"bracket": True},
    "obstacle": {"circle": {"center": [0.1, 0.05], "radius": 0.02}, "tolerance": 1e-9},
}
#: A heated isotropic plate against a polygon with a gap.
THERMAL = {
    "material": {"E": 2.1e11, "nu": 0.3, "thermal_expansion": 1.2e-5},
    "edges": {"left": {"inplane": "clamped"}, "right": {"inplane": "clamped"}},
    "load": {"temperature": [10.0, 0.0, 0.0]},
    "obstacle": {"polygon": [[-0.05, -0.02], [0.05, -0.02], [0.0, 0.03]], "gap": 0.001},
}
#: A bilateral foundation under the plate and a rigid obstacle with a gap above it.
TWO_OBSTACLES = {
    "obstacles": [
        {"zone": "all", "side": "both", "foundation_stiffness": 1e6},
        {"zone": [[-0.02, 0.02], [-0.02, 0.02]], "side": "above", "gap": 0.001},
    ],
}

#: A section's file (a box with an elastic core over part of its length).
SECTION = {
    "section": {
        "shape": "box", "width": 0.2, "depth": 0.1, "diameter": None, "thickness": 0.002,
        "length": 0.4, "ends": "clamped",
    },
    "material": {"E": 2.1e11, "nu": 0.3},
    "load": {"axial_stress": -1.0, "bending_stress": -0.2},
    "obstacle": {"core": True, "span": [0.1, 0.3], "foundation_stiffness": 1e9},
    "mesh": {"size": 0.02, "levels": 2},
}  # fmt: skip
SECTION["section"].pop("diameter")
#: A tube's: its diameter.
TUBE = {**SECTION, "section": {"shape": "tube", "diameter": 0.2, "thickness": 0.001, "length": 0.4}}


def _keys(data: dict[str, Any], prefix: str = "") -> set[str]:
    """The dotted keys of ``data`` in the form of :func:`accepted_keys`."""
    out = set()
    for key, value in data.items():
        name = "edges.<name>" if prefix == "edges." else prefix + key
        if isinstance(value, dict):
            out |= _keys(value, name + ".")
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for table in value:
                out |= _keys(table, name + "[].")
        else:
            out.add(name)
    return out


def _gmsh_file(tmp_path: Path) -> dict[str, Any]:
    geo = tmp_path / "plate.geo"
    geo.write_text("// read by gmsh when meshed; loading only needs the file\n")
    plate = {"file": str(geo), "thickness": 0.006}
    return {"plate": plate, "edges": {"rim": {"support": "clamped"}}, "mesh": {"size": 0.01}}


def test_the_schema_file_is_the_packages():
    assert json.loads(SCHEMA_FILE.read_text()) == json_schema()


def test_every_key_says_what_it_means():
    # Each key of the schema (and so each row of the reference page) carries the meaning
    # its Struct's docstring gives it, the file's own forms (edges, polygon, circle) too.
    schema = json_schema()
    for name, table in schema["$defs"].items():
        for key, node in table.get("properties", {}).items():
            assert node.get("description"), f"{name}.{key} has no description"
    tau = schema["$defs"]["SolverSpec"]["properties"]["tau"]["description"]
    assert tau.startswith("Relative feasibility/contact tolerance")
    assert "[edges.NAME]" in schema["$defs"]["ProblemSpec"]["properties"]["edges"]["description"]


def test_unibuckle_schema_writes_it(tmp_path, capsys):
    out = tmp_path / "schema.json"
    assert main(["schema", "--output", str(out)]) == EXIT_OK
    assert json.loads(out.read_text()) == json_schema()
    assert main(["schema", "--keys"]) == EXIT_OK
    assert capsys.readouterr().out.split() == accepted_keys()


def test_unibuckle_schema_into_a_pipe_closed_early(tmp_path):
    """``unibuckle schema | head``: a reader that stops early ends it quietly, status 141.

    The pipe is closed before the command writes (it takes a few tenths of a second to
    start), so its write meets a closed pipe for certain: no traceback, 128 + SIGPIPE, the
    status of any command a closed pipe ends (``seq 100 | head -1`` under pipefail).
    """
    script = Path(sys.executable).parent / "unibuckle"
    proc = subprocess.Popen(
        [str(script), "schema"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=tmp_path
    )
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.close()  # what head does after its lines
    err = proc.stderr.read().decode()
    assert proc.wait() == 128 + signal.SIGPIPE, err
    assert "Traceback" not in err and "BrokenPipe" not in err, err


def test_every_accepted_key_loads(tmp_path):
    """The documents hold every accepted key, and nothing else; each loads."""
    documents = [*BASES.values(), LAMINATE, THERMAL, TWO_OBSTACLES, SECTION, TUBE]
    documents.append(_gmsh_file(tmp_path))
    for data in documents:
        spec_from_dict(data, "plate")
    covered = set().union(*(_keys(data) for data in documents))
    assert covered == set(accepted_keys())


def test_the_input_echo_passes_the_schema_and_round_trips(tmp_path):
    for data in [*BASES.values(), LAMINATE, THERMAL, TWO_OBSTACLES, SECTION, TUBE]:
        spec = spec_from_dict(data, "plate")
        for units in ("SI", "mm-N-MPa"):
            echo = json.loads(json.dumps(problem_to_dict(spec, units=units)))
            spec_from_dict(echo, "plate")  # the echo is a problem file
            assert _keys(echo) <= set(accepted_keys())
        # Written in SI, the echo is the problem (in other units, up to rounding).
        assert spec_from_dict(problem_to_dict(spec), name=spec.name) == spec


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (
            {"obstacles": [{"zone": "all"}, {"circle": {"center": [0, 0], "radius": "5"}}]},
            r"^obstacles\[1\]\.circle\.radius must be a number, got '5' \(a string\)$",
        ),
        (
            {"obstacles": [{"zone": "all"}, {"circle": {"center": [0, 0], "r": 1.0}}]},
            r"^unknown key\(s\) \['r'\] in \[obstacles\[1\]\.circle\]; allowed: "
            r"\['center', 'radius'\]$",
        ),
        (
            {"obstacles": [{"zone": "all"}, {"circle": {"center": [0, 0], "radius": -1.0}}]},
            r"^obstacles\[1\]\.circle\.radius must be > 0 m, got -1\.0$",
        ),
        (
            {"edges": {"left": {}, "top": {"support": "pinned"}}},
            r"^edges\.top\.support must be one of \('simply_supported', "
            r"'simply_supported_soft', 'clamped', 'free'\), got 'pinned'$",
        ),
        (
            {"plate": {"holes": [{"center": [0, 0], "radius": 0.01}, {"outline": [[0, 0]]}]}},
            r"^plate\.holes\[1\]\.outline must be a list of at least 3 entries, got \[\[0, 0\]\]$",
        ),
    ],
)
def test_error_locations(data, match):
    """Where the schema finds the error, in the file's own terms."""
    with pytest.raises(ValueError, match=match):
        problem_from_dict(data)


def _concrete(data: Any, prefix: str = "", path: tuple = ()) -> Any:
    """(key as :func:`accepted_keys` writes it, path, value) of each leaf of ``data``."""
    for key, value in data.items():
        name = "edges.<name>" if prefix == "edges." else prefix + key
        if isinstance(value, dict):
            yield from _concrete(value, name + ".", (*path, key))
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for k, table in enumerate(value):
                yield from _concrete(table, name + "[].", (*path, key, k))
        else:
            yield name, (*path, key), value


def _numbers_equal(a: Any, b: Any) -> bool:
    """Equal values, numbers to the last bit (an integer equals its float)."""
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(_numbers_equal(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b
    if isinstance(a, int | float) and isinstance(b, int | float):
        return float(a).hex() == float(b).hex()
    return bool(a == b)


def _close(a: Any, b: Any) -> bool:
    """Equal values, numbers to a relative 4e-15."""
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float | int) and not isinstance(a, bool):
        return bool(a == pytest.approx(b, rel=4e-15, abs=0.0))
    return bool(a == b)


def test_every_accepted_key_round_trips_through_load_and_dump(tmp_path):
    """Every key of the schema is written back by the dump with the value given.

    The keys are :func:`accepted_keys`' (walked from the JSON Schema), each found in one
    of the documents of :func:`test_every_accepted_key_loads`; the dump loads to the
    same problem. In another unit system it loads to the same problem up to rounding (a
    relative 4e-15: two conversions by the mm-N-MPa factors 1e-3 and 1e6, each within
    half an ulp per product).
    """
    documents = [*BASES.values(), LAMINATE, THERMAL, TWO_OBSTACLES, SECTION, TUBE]
    documents.append(_gmsh_file(tmp_path))
    checked = set()
    for data in documents:
        spec = spec_from_dict(data, "plate")
        dump = problem_to_dict(spec)
        for key, path, value in _concrete(data):
            written: Any = dump
            for part in path:
                written = written[part]
            assert _numbers_equal(written, value), (key, value, written)
            checked.add(key)
        assert spec_from_dict(dump, name=spec.name) == spec
        mm = spec_from_dict(problem_to_dict(spec, units="mm-N-MPa"), name=spec.name)
        si, back = (json.loads(json.dumps(problem_to_dict(s))) for s in (spec, mm))
        for (key, _, a), (_, _, b) in zip(_concrete(si), _concrete(back), strict=True):
            assert _close(a, b), (key, a, b)
    assert checked == set(accepted_keys())
