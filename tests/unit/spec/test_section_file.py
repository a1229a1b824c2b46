"""A section's problem file: ``[section]`` read, checked, dumped, and run by ``unibuckle solve``.

Expected values: the hollow square box's k = 4 (faces buckling alternately, corners as
simple supports: Timoshenko and Gere, *Theory of Elastic Stability*, 1961, 9.2) and the
plate solver's simply supported face on the same cells (an independent model: the plate's
Reissner-Mindlin element, ``[plate]`` with the same edges); the elastic core's limits
(a foundation stiffness -> infinity gives the rigid core, solved by the active-set method;
-> 0 the hollow section, solved by one eigen solve).
"""

from __future__ import annotations

import copy
import json
import math

from mpi4py import MPI

import pytest

from unibuckle_fenicsx import (
    SectionParameters,
    problem_from_dict,
    problem_to_dict,
    section_from_dict,
    solve,
    solve_section,
)
from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, EXIT_OK, main
from unibuckle_fenicsx.spec import load_problem

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial sections")

E, NU, T = 2.1e11, 0.3, 0.002
D = E * T**3 / (12.0 * (1.0 - NU**2))
#: The issue's file, with a small square box (b/t = 50, L = 2b: two half-waves of b).
BOX = """
[section]
shape = "box"
width = 0.1
depth = 0.1
thickness = 0.002
length = 0.2
ends = "simply_supported"
[material]
E = 2.1e11
nu = 0.3
[load]
axial_stress = -1.0
[mesh]
size = 0.0125
"""
#: Every key of a section file.
EVERY_KEY = {
    "name": "tube",
    "section": {
        "shape": "tube", "diameter": 0.2, "thickness": 0.001, "length": 0.1,
        "ends": "clamped",
    },
    "material": {"E": E, "nu": NU},
    "load": {"axial_stress": -1.0, "bending_stress": -0.5},
    "obstacle": {"core": True, "span": [0.0, 0.05], "foundation_stiffness": 1e9},
    "mesh": {"size": 0.01, "levels": 2},
    "solver": {"tau": 1e-9, "eps_tol": 1e-11, "max_iterations": 50},
}  # fmt: skip


def _no_mesh(*args, **kwargs):
    raise AssertionError("a mesh was built")


def _write(tmp_path, text=BOX, name="box.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_section_file_round_trips_through_load_and_dump(tmp_path):
    spec = section_from_dict(EVERY_KEY)
    dump = problem_to_dict(spec)
    for table, keys in EVERY_KEY.items():
        if isinstance(keys, dict):
            for key, value in keys.items():
                assert dump[table][key] == value, (table, key)
    assert section_from_dict(dump, name=spec.name) == spec
    mm = problem_to_dict(spec, units="mm-N-MPa")
    assert mm["section"]["diameter"] == pytest.approx(200.0, rel=1e-15)
    assert mm["obstacle"]["foundation_stiffness"] == pytest.approx(1e9 * 1e-3 / 1e6)
    back = section_from_dict(mm, name=spec.name)
    assert back.section.diameter == pytest.approx(0.2, rel=4e-15)
    # A TOML file is a section's when it has [section]; a result's JSON re-runs it.
    loaded = load_problem(_write(tmp_path))
    assert loaded.section.width == 0.1 and loaded.obstacle.core is False
    (tmp_path / "box.json").write_text(json.dumps({"input": problem_to_dict(loaded)}))
    assert load_problem(tmp_path / "box.json") == loaded.__class__(
        **{f: getattr(loaded, f) for f in loaded.__struct_fields__ if f != "name"}, name="box"
    )
    # A result of a file in mm-N-MPa: its input in SI, re-run in mm-N-MPa (the same SI values).
    result = {"units": "mm-N-MPa", "input": problem_to_dict(loaded)}
    (tmp_path / "mm.json").write_text(json.dumps(result))
    rerun = load_problem(tmp_path / "mm.json")
    assert rerun.units == "mm-N-MPa" and rerun.section == loaded.section


def _mapping(**changes):
    data = {
        "section": {"shape": "box", "width": 0.2, "depth": 0.1, "thickness": T, "length": 0.4},
        "material": {"E": E, "nu": NU},
        "mesh": {"size": 0.05},
    }
    data = copy.deepcopy(data)
    for dotted, value in changes.items():
        table, key = dotted.split("__")
        node = data.setdefault(table, {})
        if value is None:
            node.pop(key)
        else:
            node[key] = value
    return data


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"section__diameter": 0.2}, "section.diameter is not a key of a box"),
        ({"section__depth": None}, r"section.depth is needed by a box \(m, > 0\)"),
        ({"section__thickness": 0.05}, r"section.thickness must be < half of width and depth"),
        ({"section__width": -0.2}, r"section.width must be > 0 m, got -0.2"),
        ({"section__length": 0.0}, r"section.length must be > 0 m"),
        ({"section__thickness": -T}, r"section.thickness must be > 0 m"),
        ({"mesh__size": -0.01}, r"mesh.size must be > 0 m"),
        ({"section__shape": "tube"}, "section.width is not a key of a tube"),
        (
            {"section__shape": "tube", "section__width": None, "section__depth": None,
             "section__diameter": 0.004},
            r"section.thickness must be < half of diameter \(0.002 m\)",
        ),
        ({"obstacle__span": [0.0, 0.1]}, r"obstacle.span is the core's: it needs core = true"),
        ({"obstacle__foundation_stiffness": 1e9}, "obstacle.foundation_stiffness is the core's"),
        ({"obstacle__core": True, "obstacle__foundation_stiffness": -1.0},
         r"obstacle.foundation_stiffness must be > 0 N/m\^3"),
        ({"obstacle__core": True, "obstacle__span": [0.0, 0.5]},
         r"obstacle.span must satisfy 0 <= x0 < x1 <= section.length = 0.4 m"),
        # A span is a pair along the member, not a plate's point [x, y].
        ({"obstacle__core": True, "obstacle__span": [0.0, 0.1, 0.2]},
         r"obstacle.span must be a pair \[x0, x1\] \(from x0 to x1 along the member\)"),
        ({"solver__method": "enumerate"},
         r'solver.method must be one of "auto", "interior-point", "active-set" for a '
         r"section, got 'enumerate'"),
        ({"solver__penalty": 5.0}, "solver.penalty is a plate's option"),
        ({"section__radius": 0.1}, r"unknown key\(s\) \['radius'\] in \[section\]"),
    ],
)  # fmt: skip
def test_bad_section_input_is_refused_naming_the_key(changes, message):
    with pytest.raises(ValueError, match=message):
        section_from_dict(_mapping(**changes))


def test_a_span_off_the_member_is_refused_in_the_file_s_units():
    """A file in mm-N-MPa: the span and the length as the file writes them, not in m."""
    data = _mapping(obstacle__core=True, obstacle__span=[0.0, 500.0])
    data["units"] = "mm-N-MPa"
    data["section"] = {k: v * 1e3 for k, v in data["section"].items() if k != "shape"} | {
        "shape": "box"
    }
    data["material"], data["mesh"] = {"E": 2.1e5, "nu": NU}, {"size": 50.0}
    with pytest.raises(ValueError, match=r"section.length = 400 mm, got \[0, 500\]$"):
        section_from_dict(data)


@pytest.mark.parametrize(
    ("span", "levels", "message"),
    [
        (
            [15.0, 20.0],
            0,
            "obstacle.span = [15, 20] mm: the core covers no free node: its "
            "span (obstacle.span) holds no node of the mesh on the cells of mesh.size = 12.5 mm",
        ),
        (
            [60.0, 90.0],
            2,
            "on the coarser section of mesh.levels = 2 with cells 50 mm (mesh.size "
            "doubled 2 times)",
        ),
    ],
)
def test_a_core_span_found_empty_on_the_mesh_is_refused_in_the_file_s_units(span, levels, message):
    """A file in mm-N-MPa: the span the mesh finds empty, and the coarser cells, in mm.

    The box 100 x 100 x 2 mm, L = 200 mm on cells of 12.5 mm: [15, 20] mm holds no node
    (nodes at 0, 12.5, 25 mm), [60, 90] mm the node at 62.5 mm but none of the cells of
    50 mm (mesh.size doubled twice). Both were said in m: "its span (0.015, 0.02) m",
    "cells 0.05 m". Both are refused when the file is read (they were once the solve
    had meshed the sections).
    """
    from unibuckle_fenicsx.errors import InputError

    with pytest.raises(InputError) as caught:
        section_from_dict({
            "units": "mm-N-MPa",
            "section": {"shape": "box", "width": 100.0, "depth": 100.0, "thickness": 2.0,
                        "length": 200.0, "ends": "simply_supported"},
            "material": {"E": 2.1e5, "nu": NU},
            "obstacle": {"core": True, "span": span},
            "mesh": {"size": 12.5, "levels": levels},
        })  # fmt: skip
    assert message in str(caught.value)
    assert " m " not in str(caught.value) and " m)" not in str(caught.value)


def test_a_core_on_a_plate_is_refused():
    """A plate's file has no core: ``[obstacle] core`` without a ``[section]``."""
    with pytest.raises(ValueError, match=r"^obstacle.core is a section's key, and this file"):
        problem_from_dict({"obstacle": {"core": True}})
    with pytest.raises(ValueError, match=r"^load.axial_stress is a section's key"):
        problem_from_dict({"load": {"axial_stress": -1.0}})


def test_bad_section_file_exits_2_before_any_mesh(tmp_path, monkeypatch, capsys):
    import unibuckle_fenicsx.model.shell.section as section

    def no_mesh(*args, **kwargs):
        raise AssertionError("a mesh was built")

    monkeypatch.setattr(section, "section_mesh", no_mesh)
    path = _write(tmp_path, BOX.replace("depth = 0.1", "depth = 0.1\ndiameter = 0.1"))
    assert main(["solve", "--config", str(path)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "section.diameter is not a key of a box: it has width and depth" in err
    path = _write(tmp_path, BOX, "ok.toml")
    bad = ["solve", "--config", str(path), "--set", "section.thickness=0.06"]
    assert main(bad) == EXIT_BAD_INPUT
    assert "section.thickness must be < half of width and depth (0.05 m)" in capsys.readouterr().err
    assert main(["solve", "--config", str(path), "--nx", "4"]) == EXIT_BAD_INPUT
    # A plate's flag: --candidate-parallel (an enumeration; it was ignored, the section
    # solved on its distributed mesh).
    assert main(["solve", "--config", str(path), "--candidate-parallel"]) == EXIT_BAD_INPUT
    assert "--candidate-parallel shares a plate's enumeration" in capsys.readouterr().err
    # A key of the other shape (--set adds it, the schema refuses it): the box's own keys
    # are named, not a plate's shortcuts.
    bad = ["solve", "--config", str(path), "--set", "section.diameter=0.2"]
    assert main(bad) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "section.diameter is not a key of a box: it has width and depth" in err, err
    assert "plate.length" not in err


def _plate_face_load() -> float:
    """The simply supported 0.2 x 0.1 plate on the box face's cells (16 x 8): the plate solver."""
    face = {
        "plate": {"corners": [[0.0, 0.0], [0.2, 0.1]], "thickness": T},
        "material": {"E": E, "nu": NU},
        "edges": {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}},
        "mesh": {"nx": 16, "ny": 8},
    }
    with solve(problem_from_dict(face), MPI.COMM_SELF) as analysis:
        return analysis.result.critical_load_Pa


def test_unibuckle_solve_runs_a_section_file(tmp_path, capsys):
    out = tmp_path / "box.json"
    assert main(["solve", "--config", str(_write(tmp_path)), "--json", str(out)]) == EXIT_OK
    # The file's name (its stem, box.toml giving none) heads the summary and the JSON, as
    # a plate's does: it was "section-box" whatever the file.
    assert capsys.readouterr().out.startswith("box: sigma_cr")
    r = json.loads(out.read_text())
    assert r["case"] == "box"
    load = r["critical_load_Pa"]
    # The plate solver's face (0.27 % apart on these cells: the box's faces also stretch
    # in their plane at the corners), and the long box's k = 4 (4.07 on b/8; 4.007 on
    # finer cells, docs/verification/sections.md).
    assert load == pytest.approx(_plate_face_load(), rel=5e-3)
    k = load * T * 0.1**2 / (math.pi**2 * D)
    assert r["buckling_coefficient_k"] == pytest.approx(k, rel=1e-12)
    assert k == pytest.approx(4.0, rel=0.02)
    assert [f["face"] for f in r["faces"]] == ["right", "top", "left", "bottom"]
    assert all(f["buckling_coefficient_k"] == pytest.approx(k) for f in r["faces"])
    assert r["certificate"] is None and r["input"]["section"]["width"] == 0.1
    # --set changes a key of the file: a wider box, k by its widest face (0.15 m).
    wide = tmp_path / "wide.json"
    args = ["solve", "--config", str(out), "--set", "section.width=0.15", "--json", str(wide)]
    assert main(args) == EXIT_OK
    w = json.loads(wide.read_text())
    assert w["input"]["section"]["width"] == 0.15
    assert w["buckling_coefficient_k"] == pytest.approx(
        w["critical_load_Pa"] * T * 0.15**2 / (math.pi**2 * D), rel=1e-12
    )
    widths = {f["face"]: f["width_m"] for f in w["faces"]}
    assert widths == {"right": 0.1, "top": 0.15, "left": 0.1, "bottom": 0.15}


def test_an_elastic_core_between_its_limits():
    """k_f -> 0: the hollow box; k_f -> infinity: the rigid core (another algorithm)."""
    base = {
        "width": 0.1, "depth": 0.1, "thickness": T, "length": 0.2, "E": E, "nu": NU,
        "mesh_size": 0.025, "ends": "simply_supported",
    }  # fmt: skip
    loads = {}
    for name, changes in {
        "hollow": {},
        "soft": {"core": True, "foundation_stiffness": 1e3},
        "medium": {"core": True, "foundation_stiffness": 1e9},
        "stiff": {"core": True, "foundation_stiffness": 1e15},
        "rigid": {"core": True},
        "rigid over [0, L]": {"core": True, "core_span": (0.0, 0.2)},
    }.items():
        # levels = 0 with a core (a hollow section takes no levels: its free solve)
        levels = {"levels": 0} if changes else {}
        with solve_section(SectionParameters("box", **base, **changes), **levels) as analysis:
            r = analysis.result
            loads[name] = r.critical_load_Pa
            if "foundation_stiffness" in changes:
                assert r.method == "foundation" and r.certificate is not None
                assert r.lower_bound_Pa <= r.critical_load_Pa * (1 + 1e-12)
    # The springs' energy is k_f times the pressing part of w^2: relative 1e-6 at 1e3 N/m^3
    # (9e-4 at 1e6), 6e-7 below the rigid core at 1e15 N/m^3 (the constraint's error 1/k_f).
    assert loads["soft"] == pytest.approx(loads["hollow"], rel=1e-5)
    assert loads["stiff"] == pytest.approx(loads["rigid"], rel=1e-5)
    assert loads["hollow"] < loads["medium"] < loads["stiff"] <= loads["rigid"] * (1 + 1e-9)
    assert loads["rigid over [0, L]"] == pytest.approx(loads["rigid"], rel=1e-12)


def test_cells_too_coarse_are_refused_naming_size_or_levels(tmp_path, capsys):
    """mesh.size not below the length, or levels whose coarser section cannot seed: exit 2.

    A section needs 2 cells along (ceil(L/h) >= 2, its end nodes are supported); the
    coarser sections of ``mesh.levels`` double the cells, so on L = 0.2 m, h = 0.0125 m
    (16 cells) at most 3 levels leave 2 cells; a core's span [0.06, 0.09] m holds a node
    of cells 0.0125 m (x = 0.0625) but none of cells 0.05 m (levels = 2). Each message
    names the key to change, not a plate's mesh.nx or only the span.
    """
    core = BOX.replace("[mesh]", "[obstacle]\ncore = true\n[mesh]")
    short = core.replace("core = true", "core = true\nspan = [0.06, 0.09]")
    cases = [
        (
            BOX.replace("size = 0.0125", "size = 0.2"),
            "mesh.size = 0.2 m must be below section.length = 0.2 m",
        ),
        (
            core.replace("size = 0.0125", "size = 0.0125\nlevels = 4"),
            "mesh.levels = 4: the coarsest section's cells, mesh.size x 2^4 = 0.2 m, are not "
            "below section.length = 0.2 m (at least 2 cells along): mesh.levels <= 3 here",
        ),
        (
            short.replace("size = 0.0125", "size = 0.0125\nlevels = 2"),
            "obstacle.span = [0.06, 0.09] m: the core covers no free node: its span "
            "(obstacle.span) holds no node of the mesh on the coarser section of mesh.levels "
            "= 2 with cells 0.05 m (mesh.size doubled 2 times)",
        ),
    ]
    for text, message in cases:
        assert main(["solve", "--config", str(_write(tmp_path, text)), "-q"]) == EXIT_BAD_INPUT
        err = capsys.readouterr().err
        assert message in err, err


@pytest.mark.parametrize(
    ("size", "obstacle", "refused"),
    [
        (0.05, "", True),  # ceil(0.1/0.05) = 2 cells across every face
        (0.07, "foundation_stiffness = 1e12", True),  # ceil(1.43) = 2: an elastic core too
        (0.0499, "", False),  # ceil(2.004) = 3, made even: 4 cells, the fewest allowed
    ],
)
def test_a_core_on_a_box_with_too_few_cells_across_a_face_exits_2(
    tmp_path, monkeypatch, capsys, size, obstacle, refused
):
    """A core on a box face of 2 cells: refused when the file is read, naming mesh.size.

    With the core a face's buckle must lie on one side of it between the corners; on 2
    cells it cannot (docs/guide/sections.md, "Cell size"). The count is the mesh's:
    ceil(width/mesh.size) made even, so the range is mesh.size < width/2 = 0.05 m.
    """
    import unibuckle_fenicsx.model.shell.section as section

    monkeypatch.setattr(section, "section_mesh", _no_mesh)
    text = BOX.replace("[mesh]", f"[obstacle]\ncore = true\n{obstacle}\n[mesh]")
    path = _write(tmp_path, text.replace("size = 0.0125", f"size = {size}\nlevels = 0"))
    if not refused:
        assert load_problem(path).mesh.size == size
        return
    assert main(["solve", "--config", str(path), "-q"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert (
        f"mesh.size = {size:g} m gives 2 cells across the box's narrowest face (0.1 m); with "
        "a core (obstacle.core) a face needs at least 4" in err
    ), err
    assert "mesh.size must be < 0.05 m here" in err, err
    # The hollow box on the same cells is read (a warning of coarse cells, no refusal).
    hollow = _write(tmp_path, BOX.replace("size = 0.0125", f"size = {size}"), "hollow.toml")
    assert load_problem(hollow).mesh.size == size


def test_a_core_on_a_box_with_too_few_cells_is_refused_in_the_file_s_units():
    """A file in mm-N-MPa: the narrowest face 50 mm (a box 100 x 50 mm), cells of 30 mm."""
    from unibuckle_fenicsx.errors import InputError

    data = {
        "units": "mm-N-MPa",
        "section": {"shape": "box", "width": 100.0, "depth": 50.0, "thickness": 2.0,
                    "length": 200.0, "ends": "simply_supported"},
        "material": {"E": 2.1e5, "nu": NU},
        "obstacle": {"core": True},
        "mesh": {"size": 30.0, "levels": 0},
    }  # fmt: skip
    with pytest.raises(InputError) as caught:
        section_from_dict(data)
    text = str(caught.value)
    assert "mesh.size = 30 mm gives 2 cells across the box's narrowest face (50 mm)" in text
    assert "mesh.size must be < 25 mm here" in text
    data["mesh"]["size"] = 24.0  # ceil(50/24) = 3, made even: 4 cells
    assert section_from_dict(data).mesh.size == pytest.approx(0.024)  # read into SI
