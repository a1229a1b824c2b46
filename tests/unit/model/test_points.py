r"""Point restraints: bolts, tie bars and studs as bilateral, one-sided or spring points.

Expected values:

- bilateral ties in a row at mid-width of a simply supported a × b plate, at the
  spacing s of the nodal lines of a buckling mode :math:`\sin(m\pi x/a)\sin(\pi y/b)`
  (s = a/m): the ties do not touch the mode, so k is the Kirchhoff value
  :math:`(mb/a + a/(mb))^2` (Timoshenko and Gere, *Theory of Elastic Stability*, 1961,
  section 9.2) of that m, and the plate takes it if no other mode is lower: for a/b = 3
  and s = b/2 (m = 6), k = 6.25;
- springs: :math:`k_p \to 0` is the plate without points, :math:`k_p \to \infty` the
  bilateral point (error of first order in :math:`1/k_p`);
- one-sided points, and ties with a whole-plate obstacle: the Kirchhoff plate on bicubic
  Hermite elements with its own active-set loop (``tests/support/hermite_plate.py``).
"""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
import pytest
from msgspec.structs import replace

from support.hermite_plate import HermitePlate, isotropic
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.model.materials import bending_stiffness
from unibuckle_fenicsx.spec import (
    PointSpec,
    problem_from_dict,
    problem_to_dict,
)
from unibuckle_fenicsx.spec.cases import plate_case

THICKNESS = 1e-3  # b = 1 m: t/b = 1e-3
D = bending_stiffness(1.0e9, 0.3, THICKNESS)


def plate(n, aspect=3.0, zone=None, points=()):
    spec = plate_case(
        "points",
        length=aspect,
        width=1.0,
        thickness=THICKNESS,
        nx=round(aspect * n),
        ny=n,
        zone=zone,
    )
    return replace(spec, points=tuple(points))


def result(spec):
    with solve(spec, MPI.COMM_WORLD) as analysis:
        return analysis.result


def tie_row(spacing, **kw):
    """A row of points at mid-width y = b/2 of the a x 1 plate."""
    return PointSpec(spacing=(spacing, 1.0), region=((0.0, 3.0), (0.5, 0.5)), **kw)


# -- schema ------------------------------------------------------------------------------
def test_point_tables_are_read_converted_and_written_back():
    data = {
        "units": "mm-N-MPa",
        "plate": {"corners": [[0, 0], [3000, 1000]], "thickness": 1.0},
        "material": {"E": 1000.0, "nu": 0.3},
        "points": [
            {"spacing": 500, "region": [[0, 3000], [500, 500]]},
            {"at": [1500, 250], "kind": "spring", "stiffness": 2.0},  # N/mm
            {"spacing": [1000, 500], "offset": [250, 0], "kind": "one-sided", "side": "below"},
        ],
    }
    spec = problem_from_dict(data)
    tie, spring, studs = spec.points
    assert tie.spacing == (0.5, 0.5) and tie.region == ((0.0, 3.0), (0.5, 0.5))
    assert spring.at == (1.5, 0.25) and spring.stiffness == pytest.approx(2000.0)
    assert len(tie.locations(spec.plate)) == 7
    # x = 0.25 + k, y = 0, 0.5, 1: 3 x 3 points in the plate.
    assert sorted(map(tuple, studs.locations(spec.plate))) == [
        (x, y) for x in (0.25, 1.25, 2.25) for y in (0.0, 0.5, 1.0)
    ]
    assert problem_from_dict(problem_to_dict(spec, units="mm-N-MPa")) == spec
    written = problem_to_dict(spec, units="mm-N-MPa")["points"]
    assert written[0] == {"kind": "bilateral", "spacing": 500.0, "region": [[0, 3000], [500, 500]]}
    assert written[1]["stiffness"] == pytest.approx(2.0)


@pytest.mark.parametrize(
    "table, match",
    [
        ({}, r"\[points\[0\]\] needs at = \[x, y\].*or spacing"),
        ({"at": [1, 0.5], "spacing": 1}, r"exactly one of them"),
        ({"spacing": 0}, r"points\[0\]\.spacing must be > 0 m"),
        ({"spacing": [1, "a"]}, r"points\[0\]\.spacing\[1\] must be a number"),
        ({"at": [1, 0.5], "kind": "spring"}, r'points\[0\]\.stiffness: kind = "spring" needs'),
        ({"at": [1, 0.5], "stiffness": 5.0}, r'points\[0\]\.stiffness belongs to kind = "spring"'),
        ({"at": [1, 0.5], "side": "below"}, r'points\[0\]\.side belongs to kind = "one-sided"'),
        ({"at": [1, 0.5], "side": "above"}, r'points\[0\]\.side belongs to kind = "one-sided"'),
        # It took "above" silently.
        ({"at": [1, 0.5], "kind": "one-sided"}, r'points\[0\]\.side: kind = "one-sided" needs'),
        ({"at": [1, 0.5], "kind": "glued"}, r"points\[0\]\.kind must be one of"),
        ({"at": [1, 0.5], "offset": [0, 0]}, r"points\[0\]\.offset belongs to a grid"),
        ({"at": [4, 0.5]}, r"points\[0\]\.at \[4\.0, 0\.5\] lies outside the plate"),
        ({"spacing": 1, "region": [[5, 6], [0, 1]]}, r"points\[0\]: the grid .* holds no point"),
        ({"at": [1, 0.5], "diameter": 0.01}, r"unknown key\(s\) \['diameter'\] in \[points\[0\]\]"),
    ],
)
def test_bad_points_are_refused(table, match):
    data = {"plate": {"corners": [[0, 0], [3, 1]], "thickness": 0.01}, "points": [table]}
    with pytest.raises(ValueError, match=match):
        problem_from_dict(data)


def test_one_sided_points_with_a_tensionless_foundation_are_refused():
    data = {
        "obstacle": {"zone": "all", "foundation_stiffness": 1e6},
        "points": [{"at": [0.0, 0.0], "kind": "one-sided", "side": "above"}],
    }
    with pytest.raises(ValueError, match=r"points: one-sided points .* tensionless foundation"):
        problem_from_dict(data)


STUD = PointSpec(at=(1.0, 0.5), kind="one-sided", side="above")


@pytest.mark.parametrize(
    ("points", "index"),
    [
        ([replace(STUD, at=(0.0, 0.5))], 0),  # on the simply supported left edge
        ([PointSpec(at=(1.0, 0.5)), STUD], 1),  # held there by a bilateral point
    ],
)
def test_a_one_sided_point_on_a_held_node_is_named(points, index):
    """A one-sided point whose node is held already restrains nothing: named by its index.

    The message is about the points (it named an obstacle.zone the file does not have,
    then "points" without saying which).
    """
    from unibuckle_fenicsx.errors import EmptyZoneError

    at = f"{points[index].at[0]:g}, 0.5"
    match = rf"^points\[{index}\] \(one-sided \(above\) at \({at}\) m\): the one-sided points act"
    with pytest.raises(EmptyZoneError, match=match):
        result(plate(4, aspect=2.0, points=points))


def test_a_one_sided_point_held_from_the_other_side_is_named():
    """A stud above inside a zone below: w = 0 there, refused naming points[1]."""
    from unibuckle_fenicsx.model.contact import BilateralZoneError
    from unibuckle_fenicsx.spec import ObstacleSpec

    free = replace(STUD, at=(1.5, 0.5))
    spec = replace(
        plate(4, aspect=2.0, points=[free, STUD]),
        obstacle=ObstacleSpec(zone=((0.5, 1.25), (0.0, 1.0)), side="below"),
    )
    match = r"^points\[1\] \(one-sided \(above\) at \(1, 0\.5\) m\): a one-sided point acts"
    with pytest.raises(BilateralZoneError, match=match):
        result(spec)


def test_points_on_held_nodes_are_reported():
    """A tie on the clamped bottom edge, a spring on a tie: restraining nothing, said so.

    Before, the summary said "1 points on 1 nodes" and nothing else: a mistyped coordinate
    went unnoticed. A grid over the whole plate has its edge points on the supports.
    """
    from unibuckle_fenicsx.spec import EdgeSpec

    spec = plate(4, aspect=2.0)
    edges = tuple(
        replace(e, support="clamped") if e.name == "bottom" else e for e in spec.plate.edges
    )
    assert any(e == EdgeSpec("bottom", support="clamped") for e in edges)
    points = [
        PointSpec(at=(0.5, 0.0)),  # on the clamped edge
        PointSpec(at=(1.0, 0.5)),  # a tie inside
        PointSpec(at=(1.0, 0.5), kind="spring", stiffness=1e5),  # on the tie's node
        PointSpec(spacing=(1.0, 0.5)),  # x = 0, 1, 2; y = 0, 0.5, 1: 8 of 9 on an edge
        PointSpec(at=(1.5, 0.5), kind="spring", stiffness=1e5),  # restrains
    ]
    spec = replace(spec, plate=replace(spec.plate, edges=edges), points=tuple(points))
    out = result(spec)
    reports = out.details.point_restraints
    idle = [r.restraining_nothing for r in reports]
    assert idle[0] == [[0.5, 0.0]] and idle[1] == [] and idle[2] == [[1.0, 0.5]]
    on_edges = {(x, y) for x in (0.0, 1.0, 2.0) for y in (0.0, 0.5, 1.0)} - {(1.0, 0.5)}
    assert {tuple(p) for p in idle[3]} == on_edges and idle[4] == []
    text = out.summary()
    assert (
        "bilateral at (0.5, 0) m: 1 points on 1 nodes, largest snap distance 0 m; 1 on a "
        "node held already (by an edge support or a bilateral point), restraining nothing: "
        "(0.5, 0) m" in text
    )
    assert "8 on a node held already" in text and ", ..." in text


def test_snap_distance_is_reported():
    """A point off the grid acts on the nearest node; the JSON and the summary say how far."""
    spec = plate(4, aspect=2.0, points=[PointSpec(at=(0.55, 0.5)), PointSpec(at=(1.5, 0.5))])
    out = result(spec)
    first, second = out.details.point_restraints
    assert first.points == first.nodes == 1
    assert first.max_snap_distance_m == pytest.approx(0.05, rel=1e-12)  # node at x = 0.5
    assert second.max_snap_distance_m == pytest.approx(0.0, abs=1e-15)
    assert "largest snap distance 0.05 m" in out.summary()


def test_the_summary_describes_points_in_the_file_s_units():
    """With units = "mm-N-MPa" the points line is in mm and N/mm, as the rest of it.

    A spring of 1e5 N/m at (1.5, 0.5) m is 100 N/mm at (1500, 500) mm; the JSON stays SI.
    """
    spring = PointSpec(at=(1.5, 0.5), kind="spring", stiffness=1.0e5)
    out = result(replace(plate(4, aspect=2.0, points=[spring]), units="mm-N-MPa"))
    assert "points: spring 100 N/mm at (1500, 500) mm: 1 points on 1 nodes" in out.summary()
    assert out.details.point_restraints[0].restraint == "spring 100000 N/m at (1.5, 0.5) m"


# -- bilateral ties ------------------------------------------------------------------------
@pytest.mark.parametrize("spacing, m", [(0.5, 6), (1.0, 3)])
def test_ties_on_the_nodal_lines_give_the_navier_load(spacing, m):
    """The a/b = 3 plate with ties at spacing a/m has k = (m/3 + 3/m)^2 (b/16, b/24, Richardson)."""
    k = [result(plate(n, points=[tie_row(spacing)])).buckling_coefficient_k for n in (16, 24)]
    richardson = (9 * k[1] - 4 * k[0]) / 5
    exact = (m / 3 + 3 / m) ** 2
    assert richardson == pytest.approx(exact, rel=5e-4), (k, richardson, exact)


def test_spring_limits_are_no_point_and_the_bilateral_point():
    """One tie at (1.25, 0.5), on no nodal line of the low modes, so the spring works."""
    free = result(plate(8)).critical_load_Pa
    tied = result(plate(8, points=[PointSpec(at=(1.25, 0.5))])).critical_load_Pa
    assert tied > 1.02 * free
    soft = result(plate(8, points=[PointSpec(at=(1.25, 0.5), kind="spring", stiffness=1e-9 * D)]))
    assert soft.critical_load_Pa == pytest.approx(free, rel=1e-9)
    errors = []
    for k in (1e6, 1e9):
        stiff = result(plate(8, points=[PointSpec(at=(1.25, 0.5), kind="spring", stiffness=k * D)]))
        errors.append(abs(stiff.critical_load_Pa / tied - 1))
    assert errors[0] < 1e-3 and errors[1] < 1e-6, errors
    assert 500 < errors[0] / errors[1] < 2000, errors


# -- one-sided points ----------------------------------------------------------------------
def test_one_sided_points_against_the_hermite_plate():
    """a/b = 2, SSSS, w <= 0 at the two lobe centres of the free mode (x = 0.5, 1.5).

    The free mode (m = 2) is up in one lobe and down in the other, so one point must
    hold: k rises from 4 to 4.462. Reference: the bicubic Hermite plate 32 x 16 (64 x 32
    differs by 1e-5). MITC4 at b/16 and b/32, Richardson: agreement to 1e-4.
    """
    bfs = HermitePlate(2.0, 1.0, 32, 16, isotropic(1.0e9, 0.3, THICKNESS))
    mask = np.zeros((33, 17), dtype=bool)
    mask[8, 8] = mask[24, 8] = True
    reference = bfs.unilateral_load(mask)[0] / (math.pi**2 * D)
    points = [PointSpec(at=(x, 0.5), kind="one-sided", side="above") for x in (0.5, 1.5)]
    k = []
    for n in (16, 32):
        out = result(plate(n, aspect=2.0, points=points))
        assert out.certificate.kkt and out.constrained_nodes == 2 and out.contact_nodes == 1
        k.append(out.buckling_coefficient_k)
    richardson = (4 * k[1] - k[0]) / 3
    assert richardson == pytest.approx(reference, rel=1e-4), (k, richardson, reference)


def test_the_new_keys_are_sweep_paths():
    """Every key added for restraints, points, plies and loads is a --vary path."""
    from unibuckle_fenicsx.sweep import point_problem

    ply = {"thickness": 0.001, "angle": 0.0, "E1": 1e11, "E2": 1e10, "G12": 5e9, "nu12": 0.3}
    ply |= {"G13": 5e9, "G23": 3e9}
    data = {
        "plate": {"corners": [[0, 0], [3, 1]]},
        "material": {"plies": [ply]},
        "edges": {"left": {"normal_stress": -1.0}, "top": {"fixed_shear_stress": 0.0}},
        "points": [{"spacing": 0.5, "region": [[0, 3], [0.5, 0.5]]}],
    }
    base = problem_to_dict(problem_from_dict(data))
    point = {
        "edges.top.rotational_stiffness": 7.0,
        "points.0.spacing": 0.75,
        "material.plies.0.angle": 30.0,
        "load.fixed_factor": 0.5,
        "edges.bottom.fixed_normal_stress": -2.0,
    }
    spec = point_problem(base, point)
    assert spec.plate.edge("top").rotational_stiffness == 7.0
    assert spec.points[0].spacing == (0.75, 0.75)
    assert spec.material.plies[0].angle == 30.0
    assert spec.load.fixed_factor == 0.5
    assert spec.plate.edge("bottom").fixed_normal_stress == -2.0


@pytest.mark.parametrize(
    "toml, key",
    [
        ("[edges.top]\nrotational_stiffness = -1.0\n", "edges.top.rotational_stiffness"),
        ("[edges.top]\ntranslational_stiffness = 5.0\n", "edges.top.translational_stiffness"),
        ("[[points]]\nat = [0.5, 0.0]\n", "points[0].at"),
        ('[[points]]\nspacing = 0.1\nkind = "spring"\n', "points[0].stiffness"),
        (
            "[[material.plies]]\nthickness = 0.003\nangle = 0.0\nE1 = 1e11\nE2 = 1e10\n"
            "G12 = 5e9\nnu12 = 0.3\nG13 = 5e9\nG23 = 3e9\n[[material.plies]]\n"
            "thickness = 0.003\nangle = 90.0\nE1 = 1e11\nE2 = 1e10\nG12 = 5e9\nnu12 = 0.3\n"
            "G13 = 5e9\nG23 = 3e9\n",
            "material.plies",
        ),
        ("[load]\nfixed_factor = 'x'\n", "load.fixed_factor"),
        ("[design]\nyield_stress = -355.0\n", "design.yield_stress"),
        ('[obstacle]\nzone = "all"\ngap = -0.001\n', "obstacle.gap"),
    ],
)
def test_cli_refuses_each_new_key_with_exit_2(tmp_path, capsys, toml, key):
    """Bad values are refused before any solve, the key named (exit status 2)."""
    from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, main

    path = tmp_path / "p.toml"
    path.write_text(toml)
    assert main(["solve", "--config", str(path), "-q"]) == EXIT_BAD_INPUT
    assert key in capsys.readouterr().err
