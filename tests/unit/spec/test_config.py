"""Problem description: validation of every parameter and the TOML loader.

Pure Python (no FEniCSx objects): every bad value must raise ``ValueError`` naming the
parameter before any mesh or matrix is built.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from unibuckle_fenicsx.spec import (
    EDGE_NAMES,
    EdgeSpec,
    Material,
    MeshSpec,
    ObstacleSpec,
    PlateSpec,
    ProblemSpec,
    SolverSpec,
    load_toml,
    problem_from_dict,
    problem_to_dict,
)
from unibuckle_fenicsx.spec.cases import CASES, paper_case

# A problem file in the README's schema ("Problem files"): the paper's case c1.
SCHEMA_TOML = """\
[plate]
corners = [[-0.1, -0.05], [0.1, 0.05]]
thickness = 0.006
[material]
E = 1.0e9
nu = 0.3
[mesh]
nx = 20
ny = 20
[obstacle]
zone = [[-0.04, 0.04], [-0.05, 0.05]]   # or "all"; no [obstacle] table = free plate
"""


# -- bad input: each message names the parameter ---------------------------------------
@pytest.mark.parametrize("thickness", [0.0, -0.006, math.nan, math.inf])
def test_non_positive_thickness(thickness):
    with pytest.raises(ValueError, match=r"plate\.thickness"):
        PlateSpec(thickness=thickness)


@pytest.mark.parametrize("nu", [0.5, 0.7, -1.0, -1.5, math.nan])
def test_poisson_ratio_outside_open_interval(nu):
    with pytest.raises(ValueError, match=r"material\.nu"):
        Material(E=1.0e9, nu=nu)


@pytest.mark.parametrize("nu", [-0.99, 0.0, 0.3, 0.499])
def test_poisson_ratio_inside_interval_accepted(nu):
    assert Material(E=1.0e9, nu=nu).nu == nu


@pytest.mark.parametrize("E", [0.0, -1.0e9])
def test_non_positive_young_modulus(E):
    with pytest.raises(ValueError, match=r"material\.E"):
        Material(E=E, nu=0.3)


@pytest.mark.parametrize(
    "corners",
    [
        ((0.0, 0.0), (0.0, 1.0)),  # zero length
        ((0.0, 0.0), (1.0, 0.0)),  # zero width
        ((0.1, 0.05), (-0.1, -0.05)),  # corners swapped
        ((0.0, 0.0), (1.0, math.nan)),
        ((0.0, 0.0),),  # not two corners
    ],
)
def test_degenerate_rectangle(corners):
    with pytest.raises(ValueError, match=r"plate\.corners"):
        PlateSpec(corners=corners)


def test_non_positive_definite_voigt_matrix():
    with pytest.raises(ValueError, match=r"material\.bending_voigt"):
        Material(E=1.0e9, nu=0.3, bending_voigt=((1.0, 2.0, 0.0), (2.0, 1.0, 0.0), (0, 0, 1.0)))
    with pytest.raises(ValueError, match=r"material\.membrane_voigt"):
        Material(E=1.0e9, nu=0.3, membrane_voigt=((1.0, 0.5), (0.5, 1.0)))


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"support": "hinged"}, r"edges\.left\.support"),
        ({"inplane": "glued"}, r"edges\.left\.inplane"),
        ({"normal_stress": math.inf}, r"edges\.left\.normal_stress"),
    ],
)
def test_bad_edge(kwargs, name):
    with pytest.raises(ValueError, match=name):
        EdgeSpec("left", **kwargs)


@pytest.mark.parametrize("n", [0, 1, -3, 2.5, True, "8"])
def test_bad_mesh(n):
    """At least two cells a side: one cell cannot carry a buckle (w = 0 on its edges)."""
    with pytest.raises(ValueError, match=r"mesh\.nx must be an integer >= 2"):
        MeshSpec(nx=n, ny=4)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"method": "newton"}, r"solver\.method"),
        ({"tau": 0.0}, r"solver\.tau"),
        ({"tau": 0.5}, r"solver\.tau"),
        ({"eps_tol": 1e-2}, r"solver\.eps_tol"),
        ({"max_candidates": 0}, r"solver\.max_candidates"),
        ({"penalty": -1.0}, r"solver\.penalty"),
        ({"prestress_degree": 0}, r"solver\.prestress_degree"),
        # Degree 30 was taken and its prestress solve did not end in 300 s (12 x 4 cells).
        ({"prestress_degree": 30}, r"solver\.prestress_degree must be an integer in \[1, 4\]"),
        ({"shear": "reduced"}, r"solver\.shear"),
        ({"complete": "false"}, r"solver\.complete must be true or false, got 'false'"),
        ({"max_candidates": "many"}, r"solver\.max_candidates must be an integer"),
        ({"tau": "1e-8"}, r"solver\.tau must be a number, got '1e-8'"),
        ({"max_iterations": 0}, r"solver\.max_iterations"),
        ({"bound_budget": -1}, r"solver\.bound_budget"),
        ({"enumeration_budget_s": 0.0}, r"solver\.enumeration_budget_s"),
        ({"certify": 1}, r"solver\.certify must be true or false"),
    ],
)
def test_bad_solver_option(kwargs, name):
    with pytest.raises(ValueError, match=name):
        SolverSpec(**kwargs)


@pytest.mark.parametrize(
    "zone",
    ["none", ((0.1, -0.1), (0.0, 0.1)), ((0.0, math.nan), (0.0, 0.1)), (1.0, 2.0)],
)
def test_bad_obstacle_zone(zone):
    with pytest.raises(ValueError, match=r"obstacle\.zone"):
        ObstacleSpec(zone=zone)


def test_duplicate_edge_names():
    with pytest.raises(ValueError, match=r"plate\.edges"):
        PlateSpec(edges=(EdgeSpec("left"), EdgeSpec("left")))


def test_specs_are_frozen():
    spec = paper_case("c1", 8, 4)
    with pytest.raises(AttributeError, match="immutable"):
        spec.plate.thickness = 1.0  # type: ignore[misc]


# -- TOML ---------------------------------------------------------------------------------
def test_schema_example_loads(tmp_path):
    path = tmp_path / "plate.toml"
    path.write_text(SCHEMA_TOML)
    spec = load_toml(path)
    assert spec.name == "plate"  # the file's stem
    assert spec.plate.corners == ((-0.1, -0.05), (0.1, 0.05))
    assert spec.plate.thickness == 0.006
    assert (spec.material.E, spec.material.nu) == (1.0e9, 0.3)
    assert spec.material.shear_correction == pytest.approx(5.0 / 6.0)
    assert (spec.mesh.nx, spec.mesh.ny) == (20, 20)
    assert spec.obstacle is not None
    assert spec.obstacle.zone == ((-0.04, 0.04), (-0.05, 0.05))
    # Missing tables take the paper's values: this is exactly the paper's case c1.
    assert spec.plate == paper_case("c1").plate
    assert spec.obstacle == CASES["c1"]
    assert spec.solver == SolverSpec()


def test_toml_all_zone_edges_and_solver(tmp_path):
    path = tmp_path / "thin.toml"
    path.write_text(
        'name = "thin"\n'
        "[plate]\nthickness = 1e-4\n"
        "[material]\nE = 2.1e11\nnu = 0.25\n"
        '[edges.left]\nsupport = "clamped"\ninplane = "clamped"\nnormal_stress = 0.0\n'
        '[edges.top]\nsupport = "free"\n'
        '[obstacle]\nzone = "all"\n'
        '[solver]\nmethod = "active-set"\ntau = 1e-6\nshear = "full"\n'
    )
    spec = load_toml(path)
    assert spec.name == "thin"
    assert spec.obstacle == ObstacleSpec(zone="all")
    left = spec.plate.edge("left")
    assert (left.support, left.inplane, left.loaded) == ("clamped", "clamped", False)
    # The file sets a load on the left edge (zero): no other edge is loaded either.
    assert spec.plate.edge("right").normal_stress == 0.0
    assert spec.plate.edge("top").support == "free"
    assert (spec.solver.method, spec.solver.tau, spec.solver.shear) == ("active-set", 1e-6, "full")


@pytest.mark.parametrize(
    ("inplane", "key", "value"),
    [
        ("roller", "normal_stress", -2.0),
        ("roller", "fixed_normal_stress", [-5.0, 5.0]),
        ("clamped", "normal_stress", -1.0),
        ("clamped", "shear_stress", 0.5),
        ("clamped", "fixed_shear_stress", 1.0),
    ],
)
def test_a_stress_on_an_edge_held_in_its_plane_is_refused(inplane, key, value):
    """The prestress solve's Dirichlet condition replaces the traction there: not applied.

    Left "roller" with normal_stress -2 and right -1 was solved as the plate under -1
    (the roller's reaction) while k and the design read the -2: k = 8.09 and sigma_cr
    twice the plate's, for the simply supported 2:1 plate whose k is 4 (Timoshenko and
    Gere, section 9.2; computed 4.05 from the right edge's -1).
    """
    edges = {"left": {"inplane": inplane, key: value}, "right": {"normal_stress": -1.0}}
    pattern = rf'edges\.left\.{key} = .* is not applied: inplane = "{inplane}" holds the edge'
    with pytest.raises(ValueError, match=pattern):
        problem_from_dict({"edges": edges})
    if inplane == "roller" and key == "normal_stress":  # a roller slides: shear applies
        edges["left"] = {"inplane": "roller", "shear_stress": 0.0}
        assert problem_from_dict({"edges": edges}).plate.edge("left").inplane == "roller"


def test_the_papers_load_leaves_an_edge_held_in_its_plane_out():
    """A file that sets no load gets the paper's -1 on left and right, but not on a held edge."""
    spec = problem_from_dict({"edges": {"left": {"inplane": "roller"}}})
    assert spec.plate.edge("left").normal_stress == 0.0
    assert spec.plate.edge("right").normal_stress == -1.0


def test_toml_without_obstacle_is_free_plate(tmp_path):
    path = tmp_path / "free.toml"
    path.write_text("[material]\nE = 1.0e9\nnu = 0.3\n")
    spec = load_toml(path)
    assert spec.obstacle is None
    assert spec.plate == paper_case("free").plate


@pytest.mark.parametrize(
    ("data", "match"),
    [
        ({"plate": {"thicknes": 0.006}}, r"unknown key\(s\) \['thicknes'\] in \[plate\]"),
        ({"plates": {}}, r"unknown key\(s\) \['plates'\] in \[top\]"),
        ({"edges": {"north": {}}}, r"unknown key\(s\) \['north'\] in \[edges\]"),
        ({"edges": {"left": {"load": -1.0}}}, r"in \[edges\.left\]"),
        ({"material": {"E": 1.0e9, "nu": 0.3, "G": 1.0}}, r"\['G'\] in \[material\]"),
        ({"solver": {"methd": "auto"}}, r"\['methd'\] in \[solver\]"),
        ({"obstacle": {"box": [[0, 1], [0, 1]]}}, r"\['box'\] in \[obstacle\]"),
        ({"material": {"E": 1.0e9}}, r"\[material\] needs 'nu'"),
        ({"plate": {"thickness": -1.0}}, r"plate\.thickness"),
        ({"material": {"E": 1.0e9, "nu": 0.5}}, r"material\.nu"),
        ({"plate": {"corners": [[0, 0], [0, 1]]}}, r"plate\.corners"),
    ],
)
def test_toml_bad_input_names_parameter(data, match):
    with pytest.raises(ValueError, match=match):
        problem_from_dict(data)


@pytest.mark.parametrize(
    ("data", "guess"),
    [
        ({"plate": {"thicknes": 0.006}}, " (did you mean 'thickness'?)"),
        ({"edges": {"lef": {}}}, " (did you mean 'left'?)"),
        ({"solver": {"methd": "auto", "tua": 1e-8}}, " (did you mean 'method' for 'methd', "),
        ({"plate": {"colour": 1}}, ""),  # nothing near: no guess
    ],
)
def test_a_misspelt_key_is_given_the_nearest_allowed_one(data, guess):
    """The guess is difflib's nearest allowed key (a cutoff of 0.6), after the allowed list.

    Expected: the keys of the tables (``PlateSpec``, the edge names, ``SolverSpec``) one
    letter off the misspelt ones; "colour" is near none of [plate]'s.
    """
    with pytest.raises(ValueError) as err:
        problem_from_dict(data)
    text = str(err.value)
    assert ("did you mean" in text) == bool(guess)
    assert guess in text


def test_toml_unknown_key_from_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(SCHEMA_TOML.replace("thickness = 0.006", "thickness = 0.006\ncolour = 1"))
    with pytest.raises(ValueError, match=r"'colour'.*\[plate\]"):
        load_toml(path)


# -- the paper's cases as data --------------------------------------------------------
def test_paper_case_names():
    """An unknown case is refused with the list of the known ones; the mesh is settable."""
    with pytest.raises(ValueError, match=r"case must be one of \['free', 'c1', 'c2', 'c3'\]"):
        paper_case("c4")
    spec = paper_case("c2", 8, 4)
    assert (spec.mesh.nx, spec.mesh.ny, spec.obstacle) == (8, 4, CASES["c2"])


def test_with_mesh_and_solver_copies():
    spec = ProblemSpec()
    finer = spec.with_mesh(40, 20).with_solver(method="enumerate")
    assert (finer.mesh.nx, finer.mesh.ny, finer.solver.method) == (40, 20, "enumerate")
    assert (spec.mesh.nx, spec.solver.method) == (20, "auto")
    with pytest.raises(ValueError, match=r"solver\.tau"):
        spec.with_solver(tau=-1.0)


def test_obstacle_box_contains_closed_zone():
    import numpy as np

    zone = ObstacleSpec(zone=((-0.04, 0.04), (-0.02, 0.02)))
    x = np.array([[-0.04, 0.04, 0.0, 0.0400001, 0.0], [0.02, -0.02, 0.0, 0.0, -0.0200001], [0] * 5])
    assert zone.contains(x, 0.2).tolist() == [True, True, True, False, False]


# -- types, units and the load rule of problem files --------------------------------------
@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('[material]\nE = "abc"\nnu = 0.3\n', r"material\.E must be a number, got 'abc'"),
        ('[plate]\nthickness = "thin"\n', r"plate\.thickness must be a number, got 'thin'"),
        ('[solver]\ncomplete = "false"\n', r"solver\.complete must be true or false"),
        ('[solver]\nmax_candidates = "many"\n', r"solver\.max_candidates must be an integer"),
        ("[mesh]\nnx = 8.0\n", r"mesh\.nx must be an integer"),
        ('[edges.left]\nnormal_stress = "-1"\n', r"edges\.left\.normal_stress must be a number"),
        ('[obstacle]\nzone = [["a", 1], [0, 1]]\n', r"obstacle\.zone\[0\]\[0\] must be a number"),
        ("[obstacle]\ntolerance = 1e-9\n", r"\[obstacle\] needs zone"),
        ("name = 3\n", r"name must be a string"),
        ('units = "inch"\n', r"units must be one of \('SI', 'mm-N-MPa'\)"),
    ],
)
def test_toml_types_are_checked_and_the_file_named(tmp_path, text, match):
    path = tmp_path / "typed.toml"
    path.write_text(text)
    with pytest.raises(ValueError, match=match) as err:
        load_toml(path)
    assert str(err.value).startswith(f"{path}: ")


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ("[plate]\nthickness = 1979-05-27\n", "plate.thickness must be a number, got 1979-05-27"),
        (
            '[obstacle]\nzone = "all"\ngap = 12:30:00\n',
            "obstacle.gap must be a number, got 12:30:00",
        ),
    ],
)
def test_a_toml_date_is_named_a_date_not_absent(tmp_path, text, said):
    """A TOML date or time where a number belongs: named so, as the file writes it.

    TOML has dates and times (TOML 1.0, "Offset Date-Time" to "Local Time"); the message
    said ``got datetime.date(1979, 5, 27) (absent)``, Python's repr and a key said absent
    that the file gives.
    """
    path = tmp_path / "dated.toml"
    path.write_text(text)
    with pytest.raises(ValueError) as err:
        load_toml(path)
    assert f"{said} (a TOML date or time)" in str(err.value), err.value
    assert "absent" not in str(err.value) and "datetime" not in str(err.value)


def test_toml_syntax_error_and_binary_file_name_the_file(tmp_path):
    bad = tmp_path / "broken.toml"
    bad.write_text("[plate\nthickness = 0.006\n")
    with pytest.raises(ValueError, match=rf"{bad}: invalid TOML"):
        load_toml(bad)
    binary = tmp_path / "latin1.toml"
    binary.write_bytes('name = "pl\u00e4te"\n'.encode("latin-1"))
    with pytest.raises(ValueError, match=rf"{binary}: not a UTF-8 text file"):
        load_toml(binary)


def test_mm_units_convert_to_si(tmp_path):
    """The paper's c1 in mm, N and MPa reads as the same SI problem (and prints MPa)."""
    path = tmp_path / "mm.toml"
    path.write_text(
        'units = "mm-N-MPa"\n'
        "[plate]\ncorners = [[-100.0, -50.0], [100.0, 50.0]]\nthickness = 6.0\n"
        "[material]\nE = 1000.0\nnu = 0.3\n"
        "[obstacle]\nzone = [[-40.0, 40.0], [-50.0, 50.0]]\ntolerance = 1e-6\n"
    )
    spec = load_toml(path)
    si = paper_case("c1")
    assert spec.units == "mm-N-MPa" and spec.stress_unit == (1e6, "MPa")
    np.testing.assert_allclose(spec.plate.corners, si.plate.corners, rtol=1e-15)
    assert spec.plate.thickness == pytest.approx(si.plate.thickness, rel=1e-15)
    assert spec.material.E == pytest.approx(si.material.E, rel=1e-15)
    np.testing.assert_allclose(spec.obstacle.zone, si.obstacle.zone, rtol=1e-15)
    assert spec.obstacle.tolerance == pytest.approx(1e-9, rel=1e-15)


def test_edge_loads_default_to_zero_once_a_file_sets_one():
    """A file that loads one edge loads only the edges it names (README, "Problem files")."""
    shear = {"edges": {e: {"shear_stress": 1.0, "normal_stress": 0.0} for e in EDGE_NAMES}}
    spec = problem_from_dict({"material": {"E": 1e9, "nu": 0.3}, **shear})
    assert [e.normal_stress for e in spec.plate.edges] == [0.0] * 4
    only_left = problem_from_dict({"edges": {"left": {"shear_stress": 1.0}}})
    assert only_left.plate.edge("right").normal_stress == 0.0
    assert only_left.plate.edge("left").normal_stress == 0.0
    supports_only = problem_from_dict({"edges": {"top": {"support": "clamped"}}})
    assert [e.normal_stress for e in supports_only.plate.edges] == [-1.0, -1.0, 0.0, 0.0]


def test_problem_to_dict_round_trip():
    """problem_from_dict(problem_to_dict(spec)) gives spec back, defaults included."""
    for spec in (paper_case("c2", 12, 6), paper_case("free").with_solver(method="penalty")):
        assert problem_from_dict(problem_to_dict(spec)) == spec


# -- the methods and their options ------------------------------------------------------
def test_each_method_reads_its_options_from_the_solver_table(capsys):
    """One Method per [solver] choice, the schema's and the command line's.

    Each method's options Struct holds SolverSpec fields with their type and default.
    """
    from msgspec.structs import fields

    from unibuckle_fenicsx.algorithms.registry import entry
    from unibuckle_fenicsx.cli import main
    from unibuckle_fenicsx.spec import METHODS, OPTIONS, Method, json_schema
    from unibuckle_fenicsx.spec.base import hints
    from unibuckle_fenicsx.spec.solver import EnumerateOptions, PenaltyOptions

    assert METHODS == tuple(Method) and set(OPTIONS) == set(Method)
    assert sorted(json_schema()["$defs"]["Method"]["enum"]) == sorted(METHODS)
    with pytest.raises(SystemExit):
        main(["solve", "--help"])
    assert "{" + ",".join(METHODS) + "}" in capsys.readouterr().out  # --method's choices
    table, defaults = hints(SolverSpec), {f.name: f.default for f in fields(SolverSpec)}
    for options in OPTIONS.values():
        for f in fields(options):
            assert (hints(options)[f.name], f.default) == (table[f.name], defaults[f.name])
    spec = SolverSpec(method="enumerate", complete=True, max_candidates=7)
    assert entry(Method.ENUMERATE).options_of(spec) == EnumerateOptions(
        complete=True, max_candidates=7
    )
    assert entry(Method.PENALTY).options_of(spec) == PenaltyOptions()
    with pytest.raises(ValueError, match=r"solver\.max_candidates must be an integer >= 1"):
        EnumerateOptions(max_candidates=0)


def test_other_units_leave_a_list_of_the_wrong_length_to_be_refused():
    """Converting [T0, dT/dx, dT/dy] per entry must not cut a list of four entries."""
    data = {
        "units": "mm-N-MPa",
        "material": {"E": 1e3, "nu": 0.3, "thermal_expansion": 1e-5},
        "edges": {"left": {"inplane": "clamped"}},
        "load": {"temperature": [1.0, 2.0, 3.0, 4.0]},
    }
    with pytest.raises(ValueError, match=r"load\.temperature must be a number \(K\) or \[T0"):
        problem_from_dict(data)
