"""Obstacles on either side of the plate, several obstacles, polygon and circle zones.

``side = "above"`` (the default) imposes w <= 0 in the zone, ``"below"`` w >= 0; several
``[[obstacles]]`` unite their zones' nodes, each with its side. Expected values: the
mirror symmetry w -> -w (an obstacle below gives the load of the same obstacle above),
and the dense exhaustive minimum over all 2^i contact sets (``tests/support/exhaustive.py``,
LAPACK, nothing of the package's algorithms).
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import pytest
from msgspec.structs import replace

from support.exhaustive import RTOL, exhaustive_minimum
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.cli import main as cli_main
from unibuckle_fenicsx.errors import BilateralZoneError, InputError
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec import (
    Circle,
    ObstacleSpec,
    Polygon,
    SolverSpec,
    problem_from_dict,
    problem_to_dict,
)
from unibuckle_fenicsx.spec.cases import paper_case, plate_case


# -- schema ------------------------------------------------------------------------------
def test_side_defaults_to_above_and_is_checked():
    assert ObstacleSpec("all").side == "above" and ObstacleSpec("all").sign == 1.0
    assert ObstacleSpec("all", side="below").sign == -1.0
    with pytest.raises(
        ValueError, match=r"obstacle\.side must be one of \('above', 'below', 'both'\)"
    ):
        ObstacleSpec("all", side="up")


def test_both_sides_is_a_bilateral_support():
    with pytest.raises(ValueError, match=r"bilateral support.*support"):
        problem_from_dict({"obstacle": {"zone": "all", "side": "both"}})
    box = [[0.0, 0.05], [-0.05, 0.05]]
    data = {"obstacles": [{"zone": box}, {"zone": box, "side": "below"}]}
    with pytest.raises(ValueError, match=r"obstacles\[0\] and obstacles\[1\].*both sides.*support"):
        problem_from_dict(data)
    # The same zone twice on one side is just the zone.
    data["obstacles"][1]["side"] = "above"
    assert len(problem_from_dict(data).obstacles) == 2


def test_polygon_and_circle_tables():
    data = {
        "obstacles": [
            {"polygon": [[-0.1, -0.05], [0.0, -0.05], [-0.05, 0.05]], "side": "below"},
            {"circle": {"center": [0.05, 0.0], "radius": 0.02}},
            {"zone": "all", "tolerance": 1e-9},
        ]
    }
    spec = problem_from_dict(data)
    first, second, _ = spec.obstacles
    assert first.zone == Polygon(((-0.1, -0.05), (0.0, -0.05), (-0.05, 0.05)))
    assert first.side == "below" and second.zone == Circle((0.05, 0.0), 0.02)
    assert spec.obstacle is None and spec.all_obstacles == spec.obstacles
    assert problem_from_dict(problem_to_dict(spec)) == spec
    mm = problem_to_dict(spec, units="mm-N-MPa")
    assert mm["obstacles"][1]["circle"] == {"center": [50.0, 0.0], "radius": 20.0}
    back = problem_from_dict(mm)
    assert back.obstacles[1].zone.radius == pytest.approx(0.02, rel=1e-15)
    assert back.obstacles[0].zone.vertices[2] == pytest.approx((-0.05, 0.05), rel=1e-15)


@pytest.mark.parametrize(
    "table, match",
    [
        (
            {"zone": "all", "circle": {"center": [0, 0], "radius": 1}},
            r"exactly one of them; got \['zone', 'circle'\]",
        ),
        ({"side": "above"}, r"\[obstacles\[1\]\] needs zone = .* exactly one of them; got none"),
        ({"polygon": [[0, 0], [1, 1]]}, r"obstacles\[1\]\.polygon must be a list of at least 3"),
        (
            {"polygon": [[0, 0], [1, 1], [1, 0], [0, 1]]},
            r"obstacles\[1\]\.polygon must be a simple",
        ),
        ({"polygon": [[0, 0], [1, 1], [2, 2]]}, r"obstacles\[1\]\.polygon has no area"),
        (
            {"polygon": [[0, 0], [1, "a"], [1, 0]]},
            r"obstacles\[1\]\.polygon\[1\]\[1\] must be a number",
        ),
        ({"circle": {"center": [0, 0]}}, r"\[obstacles\[1\]\.circle\] needs 'radius'"),
        (
            {"circle": {"center": [0, 0], "radius": -1}},
            r"obstacles\[1\]\.circle\.radius must be > 0",
        ),
        ({"circle": {"center": [0], "radius": 1}}, r"obstacles\[1\]\.circle\.center must be"),
        ({"zone": "all", "side": "left"}, r"obstacles\[1\]\.side must be one of"),
        ({"zone": "all", "colour": 1}, r"unknown key\(s\) \['colour'\] in \[obstacles\[1\]\]"),
    ],
)
def test_bad_obstacle_tables_name_the_parameter(table, match):
    with pytest.raises(ValueError, match=match):
        problem_from_dict({"obstacles": [{"zone": "all"}, table]})


def test_obstacle_and_obstacles_are_exclusive():
    with pytest.raises(ValueError, match=r"one \[obstacle\] table or several \[\[obstacles\]\]"):
        problem_from_dict({"obstacle": {"zone": "all"}, "obstacles": [{"zone": "all"}]})
    with pytest.raises(ValueError, match=r"obstacles must be a list of tables"):
        problem_from_dict({"obstacles": {"zone": "all"}})


def test_polygon_and_circle_contain_their_closed_zone():
    """Nodes on the boundary are inside (the zone is closed), up to the tolerance."""
    size = 1.0
    L = ObstacleSpec(Polygon(((0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2))))
    x = np.array([[1.5, 0.5, 1.5, 1.0, 2.0, 1.0 + 1e-7], [1.5, 1.5, 0.5, 1.5, 0.0, 1.5]])
    x = np.vstack([x, np.zeros(x.shape[1])])
    assert L.contains(x, size).tolist() == [False, True, True, True, True, False]
    disc = ObstacleSpec(Circle((0.0, 0.0), 1.0))
    y = np.array([[1.0, 0.6, 0.8, 0.0], [0.0, 0.8, 0.6 + 1e-6, 0.0], [0.0] * 4])
    assert disc.contains(y, size).tolist() == [True, True, False, True]


def test_a_zone_tolerance_above_a_tenth_of_a_cell_is_refused_before_any_solve():
    """``obstacle.tolerance`` catches nodes on the zone's edge, it never widens the zone.

    The paper's plate, 20 x 20 cells of 0.01 x 0.005 m: the smallest cell side is 0.005 m,
    so tolerances up to 5e-4 m are accepted (the zone's nodes are the zone's: 8 cells of
    0.01 m across [-0.04, 0.04], 9 node columns times 21 rows, the edge rows held by the
    supports), and 0.05 m, which used to take the whole plate (21 columns), is refused
    naming the key and the allowed range.
    """
    c1 = paper_case("c1")
    with build_problem(replace(c1, obstacle=replace(c1.obstacle, tolerance=4e-4))) as problem:
        assert problem.contact.size == 9 * 19
    with pytest.raises(
        InputError, match=r"obstacle\.tolerance = 0\.05 m must lie in \[0, 0\.0005\] m"
    ):
        build_problem(replace(c1, obstacle=replace(c1.obstacle, tolerance=0.05)))


# -- solves -------------------------------------------------------------------------------
def test_obstacle_below_is_the_mirror_of_above():
    """The paper's c1 zone below the plate is the mirror of c1 above.

    w -> -w maps one problem onto the other, so the load, the contact set and the
    certificate are the same (to the eigen tolerance).
    """
    spec = paper_case("c1", 12, 6)
    results = {}
    for side in ("above", "below"):
        with solve(replace(spec, obstacle=replace(spec.obstacle, side=side))) as analysis:
            results[side] = analysis.result
            if side == "below":
                assert (analysis.problem.contact.signs == -1.0).all()
    above, below = results["above"], results["below"]
    assert below.critical_load_Pa == pytest.approx(above.critical_load_Pa, rel=1e-10)
    assert below.contact_indices == above.contact_indices and above.contact_nodes == 5
    assert below.certificate.kkt and below.certificate.global_optimum_proven


def _two_sided_square(side_right):
    """Square SSSS plate 6x6 under uniaxial compression with two zones of 6 nodes.

    One left of the centre above the plate, one right of it on ``side_right``.
    """
    spec = plate_case("two-sided", length=1.0, width=1.0, thickness=0.01, nx=6, ny=6)
    obstacles = (
        ObstacleSpec(((0.1, 0.4), (0.3, 0.7))),
        ObstacleSpec(((0.6, 0.9), (0.3, 0.7)), side=side_right),
    )
    return replace(spec, obstacles=obstacles, solver=SolverSpec(method="active-set"))


@pytest.mark.parametrize("side_right", ["above", "below"])
def test_obstacles_on_opposite_sides_against_the_exhaustive_minimum(side_right):
    """Two zones on one side or on opposite sides, against the exhaustive minimum.

    The square's first mode is one half-wave: one-signed, it clears two obstacles on one
    side (load unchanged), but obstacles on opposite sides force a sign change and raise
    the load. The active-set result equals the dense exhaustive minimum over the 2^12
    contact sets (1e-8), with one of its minimising sets.
    """
    spec = _two_sided_square(side_right)
    with solve(spec) as analysis:
        result = analysis.result
        reference, minimisers, _ = exhaustive_minimum(analysis.problem)
    assert result.constrained_nodes == 12 and result.certificate.kkt
    assert result.critical_load_Pa == pytest.approx(reference, rel=RTOL)
    assert tuple(result.contact_indices) in minimisers
    ratio = result.critical_load_Pa / result.free_load_Pa
    if side_right == "above":
        assert ratio == pytest.approx(1.0, abs=RTOL)
    else:
        assert ratio > 1.3 and result.contact_nodes > 0


def test_polygon_zone_equal_to_a_box_gives_the_box_result():
    spec = paper_case("c2", 12, 6)
    polygon = Polygon(((-0.04, -0.02), (0.04, -0.02), (0.04, 0.02), (-0.04, 0.02)))
    with solve(spec) as analysis:
        box = analysis.result
    with solve(replace(spec, obstacle=ObstacleSpec(polygon))) as analysis:
        poly = analysis.result
    assert poly.critical_load_Pa == pytest.approx(box.critical_load_Pa, rel=1e-12)
    assert poly.contact_coordinates == box.contact_coordinates


def test_circle_zone_holds_the_nodes_of_its_disc():
    spec = replace(paper_case("free", 20, 10), obstacle=ObstacleSpec(Circle((0.0, 0.0), 0.03)))
    with build_problem(spec) as problem:
        xy = problem.contact.coordinates
    # Nodes on the 0.01 m grid within 0.03 m of the centre: 29 (x, y = 0, +-0.01, ...).
    grid = np.array([(i, j) for i in range(-3, 4) for j in range(-3, 4) if i * i + j * j <= 9])
    assert len(xy) == len(grid) == 29
    assert np.all(np.hypot(xy[:, 0], xy[:, 1]) <= 0.03 + 1e-12)


def test_overlapping_zones_on_opposite_sides_are_refused_before_the_solve(capsys, tmp_path):
    """A node in zones on both sides: exit 2 naming both obstacles, before any solve."""
    path = tmp_path / "overlap.toml"
    path.write_text(
        "[mesh]\nnx = 8\nny = 4\n"
        "[[obstacles]]\nzone = [[-0.05, 0.0], [-0.05, 0.05]]\n"
        '[[obstacles]]\nzone = [[0.0, 0.05], [-0.05, 0.05]]\nside = "below"\n'
    )
    assert cli_main(["solve", "--config", str(path)]) == 2
    err = capsys.readouterr().err
    assert "both sides of the plate share mesh nodes" in err and "obstacles[1]" in err
    spec = problem_from_dict(
        {"obstacles": [{"zone": [[-0.05, 0.0], [-0.05, 0.05]]}, {"zone": "all", "side": "below"}]}
    )
    with pytest.raises(BilateralZoneError):
        build_problem(spec.with_mesh(8, 4), MPI.COMM_WORLD)
