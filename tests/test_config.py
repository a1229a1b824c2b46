"""Problem description: validation of every parameter and the TOML loader.

Pure Python (no FEniCSx objects): every bad value must raise ``ValueError`` naming the
parameter before any mesh or matrix is built.
"""

from __future__ import annotations

import math
from dataclasses import FrozenInstanceError

import pytest

from unibuckle_fenicsx.cases import CASES, paper_case
from unibuckle_fenicsx.config import (
    EdgeSpec,
    Material,
    MeshSpec,
    ObstacleSpec,
    PlateSpec,
    ProblemSpec,
    SolverSpec,
    load_toml,
    problem_from_dict,
)

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
        Material(E=1.0, nu=0.3, bending_voigt=((1.0, 2.0, 0.0), (2.0, 1.0, 0.0), (0, 0, 1.0)))
    with pytest.raises(ValueError, match=r"material\.membrane_voigt"):
        Material(E=1.0, nu=0.3, membrane_voigt=((1.0, 0.5), (0.5, 1.0)))


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


@pytest.mark.parametrize("n", [0, -3, 2.5, True])
def test_bad_mesh(n):
    with pytest.raises(ValueError, match=r"mesh\.nx"):
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
        ({"shear": "reduced"}, r"solver\.shear"),
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
    with pytest.raises(FrozenInstanceError):
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
    assert spec.plate.edge("right").normal_stress == -1.0  # paper default kept
    assert spec.plate.edge("top").support == "free"
    assert (spec.solver.method, spec.solver.tau, spec.solver.shear) == ("active-set", 1e-6, "full")


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
