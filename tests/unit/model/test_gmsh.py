r"""Plates meshed by gmsh: outlines, holes, named boundary parts, files; MPI distribution.

Expected values: the structured rectangle's (the same plate meshed by gmsh's quad
algorithm), the Navier load, and for the square plate with a central circular hole an
independent computation with another mesh family and element (``tests/support/rm_triangles.py``:
cubic triangles, plain shear, scipy's Lanczos); for the interior point nested over gmsh
meshes of sizes 2h and h, the same route on h alone.
"""

from __future__ import annotations

import json
import sys

from mpi4py import MPI

import numpy as np
import pytest
from msgspec.structs import replace

gmsh = pytest.importorskip("gmsh")

from support.rm_triangles import holed_plate_load, navier_check  # noqa: E402
from unibuckle_fenicsx.algorithms.chain import ChainOptions, solve_interior_point  # noqa: E402
from unibuckle_fenicsx.analysis import solve  # noqa: E402
from unibuckle_fenicsx.cli import main as cli_main  # noqa: E402
from unibuckle_fenicsx.geometry import narrowest_width  # noqa: E402
from unibuckle_fenicsx.model.build import build_problem  # noqa: E402
from unibuckle_fenicsx.model.gmsh_mesh import GMSH_OPTIONS  # noqa: E402
from unibuckle_fenicsx.model.materials import navier_load_mindlin  # noqa: E402
from unibuckle_fenicsx.model.zones import zone_report  # noqa: E402
from unibuckle_fenicsx.spec import (  # noqa: E402
    Circle,
    Polygon,
    load_toml,
    problem_from_dict,
    problem_to_dict,
)
from unibuckle_fenicsx.spec.cases import paper_case  # noqa: E402
from unibuckle_fenicsx.spec.checks import coarse_mesh_note, plate_model_note  # noqa: E402

#: The paper's plate as an outline: segment 0 bottom, 1 right, 2 top, 3 left.
PAPER_OUTLINE = [[-0.1, -0.05], [0.1, -0.05], [0.1, 0.05], [-0.1, 0.05]]


def paper_outline(size, **extra):
    data = {
        "plate": {"outline": PAPER_OUTLINE, "thickness": 0.006},
        "edges": {
            "loaded": {"segments": [1, 3], "normal_stress": -1.0},
            "long": {"segments": [0, 2]},
        },
        "mesh": {"size": size},
    }
    return problem_from_dict({**data, **extra})


def holed_square(size, radius=0.15, **extra):
    """The 1 x 1 m SSSS plate, t = 0.01 m, compressed along x, with a central hole."""
    data = {
        "plate": {
            "corners": [[-0.5, -0.5], [0.5, 0.5]],
            "thickness": 0.01,
            "holes": [{"center": [0.0, 0.0], "radius": radius}],
        },
        "mesh": {"size": size},
    }
    return problem_from_dict({**data, **extra})


# -- schema ------------------------------------------------------------------------------
def test_outline_holes_and_segments_round_trip():
    spec = problem_from_dict(
        {
            "plate": {
                "outline": [[0, 0], [2, 0], [2, 1], [1, 1.5], [0, 1]],
                "holes": [
                    {"center": [0.5, 0.5], "radius": 0.2},
                    {"outline": [[1.3, 0.3], [1.7, 0.3], [1.5, 0.7]]},
                ],
            },
            "edges": {
                "left": {"segments": [4], "normal_stress": [-1, -0.5]},
                "right": {"segments": [1]},  # one straight edge alone is a mechanism
                "holes": {"support": "free"},
            },
            "mesh": {"size": 0.1},
        }
    )
    plate = spec.plate
    assert plate.meshed_by_gmsh and plate.corners == ((0.0, 0.0), (2.0, 1.5))
    assert plate.holes == (Circle((0.5, 0.5), 0.2), Polygon(((1.3, 0.3), (1.7, 0.3), (1.5, 0.7))))
    assert plate.area == pytest.approx(2.5 - np.pi * 0.04 - 0.08, rel=1e-14)
    assert problem_from_dict(problem_to_dict(spec)) == spec
    mm = problem_to_dict(spec, units="mm-N-MPa")
    assert mm["plate"]["holes"][0] == {"center": [500.0, 500.0], "radius": 200.0}
    assert problem_from_dict(mm).plate.outline[3] == pytest.approx((1.0, 1.5), rel=1e-15)


@pytest.mark.parametrize(
    "data, match",
    [
        (
            {"plate": {"outline": [[0, 0], [1, 1], [1, 0], [0, 1]]}, "mesh": {"size": 0.1}},
            r"plate\.outline must be a simple polygon",
        ),
        (
            {"plate": {"outline": PAPER_OUTLINE, "corners": [[0, 0], [1, 1]]}},
            r"give corners .* or outline .* not both",
        ),
        (
            {"plate": {"outline": PAPER_OUTLINE}},
            r"mesh\.size: a plate meshed by gmsh .* needs \[mesh\] size",
        ),
        (
            {"plate": {"outline": PAPER_OUTLINE}, "mesh": {"nx": 4, "size": 0.01}},
            r"takes size = h .* not nx and ny",
        ),
        (
            {
                "plate": {"outline": PAPER_OUTLINE},
                "edges": {"a": {"segments": [4]}},
                "mesh": {"size": 0.01},
            },
            r"edges\.a\.segments: 4 is not a segment of the outline \(0 to 3",
        ),
        (
            {
                "plate": {"outline": PAPER_OUTLINE},
                "edges": {"a": {"segments": [1]}, "b": {"segments": [1, 2]}},
                "mesh": {"size": 0.01},
            },
            r"edges\.b\.segments: segment 1 is already in edges\.a",
        ),
        (
            {
                "plate": {"outline": PAPER_OUTLINE},
                "edges": {"left": {"support": "clamped"}},
                "mesh": {"size": 0.01},
            },
            r"edges\.left: a plate given by its outline names its boundary parts by segments",
        ),
        (
            {
                "plate": {"outline": PAPER_OUTLINE},
                "edges": {"a": {"segments": [0, 0]}},
                "mesh": {"size": 0.01},
            },
            r"edges\.a\.segments repeats a segment",
        ),
        (
            {"edges": {"left": {"segments": [0]}}},
            r"edges\.left\.segments names segments of plate\.outline",
        ),
        ({"edges": {"holes": {}}}, r"unknown key\(s\) \['holes'\] in \[edges\]"),
        (
            {"plate": {"outline": PAPER_OUTLINE}, "edges": {"holes": {}}, "mesh": {"size": 0.01}},
            r"edges\.holes: the plate has no holes",
        ),
        (
            {"plate": {"holes": [{"center": [0.09, 0.0], "radius": 0.02}]}, "mesh": {"size": 0.01}},
            r"plate\.holes\[0\] must lie inside the plate",
        ),
        (
            {
                "plate": {
                    "holes": [
                        {"center": [0.0, 0.0], "radius": 0.02},
                        {"center": [0.03, 0.0], "radius": 0.015},
                    ]
                },
                "mesh": {"size": 0.01},
            },
            r"plate\.holes\[0\] and plate\.holes\[1\] overlap",
        ),
        (
            {"plate": {"holes": [{"center": [0.0, 0.0]}]}, "mesh": {"size": 0.01}},
            r"\[plate\.holes\[0\]\] needs center = \[x, y\] and radius = r",
        ),
        (
            {
                "plate": {"holes": [{"center": [0.0, 0.0], "radius": 0.01}]},
                "edges": {"holes": {"normal_stress": [1, 2]}},
                "mesh": {"size": 0.01},
            },
            r"edges\.holes: a linear \[start, end\] stress needs a straight edge",
        ),
        ({"plate": {"file": "nowhere.msh"}}, r"plate\.file: no such file 'nowhere\.msh'"),
        ({"plate": {"file": "plate.stl"}}, r"plate\.file must be a gmsh \.geo or \.msh file"),
    ],
)
def test_bad_geometry_names_the_parameter(data, match):
    with pytest.raises(ValueError, match=match):
        problem_from_dict(data)


def test_nx_ny_are_refused_for_a_gmsh_plate(capsys):
    with pytest.raises(ValueError, match=r"--nx, --ny\) set the structured rectangle"):
        paper_outline(0.01).with_mesh(8, 4)


def test_missing_gmsh_names_the_extra(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(sys.modules, "gmsh", None)  # import gmsh raises ImportError
    with pytest.raises(ImportError, match=r"pip install 'unibuckle_fenicsx\[gmsh\]'"):
        build_problem(paper_outline(0.02), MPI.COMM_WORLD)
    path = tmp_path / "outline.toml"
    path.write_text(
        f"[plate]\noutline = {PAPER_OUTLINE}\n[edges.loaded]\nsegments = [1, 3]\n"
        "normal_stress = -1.0\n[mesh]\nsize = 0.02\n"
    )
    assert cli_main(["solve", "--config", str(path)]) == 2
    assert "unibuckle_fenicsx[gmsh]" in capsys.readouterr().err


# -- the rectangle by gmsh --------------------------------------------------------------------
def test_gmsh_rectangle_reproduces_the_structured_mesh():
    """The paper's plate as an outline, size 0.01 m, and the structured 20x10 mesh.

    gmsh's quadrilateral algorithm meshes a rectangle whose sides the size divides with
    the structured grid, so the loads agree far inside the discretisation error (the
    structured mesh is 1.4 % above the Navier load here): within 1e-3 of that error
    (measured 1e-13 relative), with c1's obstacle too, and the same contact nodes.
    """
    navier, _ = navier_load_mindlin(1.0e9, 0.3, 0.006, 0.2, 0.1)
    obstacle = {"obstacle": {"zone": [[-0.04, 0.04], [-0.05, 0.05]]}}
    with solve(paper_outline(0.01, **obstacle)) as analysis:
        ours = analysis.result
        assert not analysis.problem.structured  # single-level active set
    with solve(paper_case("c1", 20, 10)) as analysis:
        structured = analysis.result
    error = abs(structured.free_load_Pa - navier)
    assert error / navier == pytest.approx(1.37e-2, abs=5e-4)
    assert abs(ours.free_load_Pa - structured.free_load_Pa) < 1e-3 * error
    assert abs(ours.critical_load_Pa - structured.critical_load_Pa) < 1e-3 * error
    assert ours.contact_coordinates == structured.contact_coordinates
    assert ours.certificate.kkt and ours.mesh == [200]
    assert ours.details.run.seeded_on == "fine"


def _outline_and_structured(corners, zone, size=0.01):
    """The same plate as an outline (gmsh) and as the structured rectangle, with ``zone``."""
    (x0, y0), (x1, y1) = corners
    obstacle = {"obstacle": {"zone": zone}}
    outline = problem_from_dict(
        {
            "plate": {"outline": [[x0, y0], [x1, y0], [x1, y1], [x0, y1]], "thickness": 0.006},
            "edges": {
                "loaded": {"segments": [1, 3], "normal_stress": -1.0},
                "long": {"segments": [0, 2]},
            },
            "mesh": {"size": size},
            **obstacle,
        }
    )
    structured = problem_from_dict(
        {"plate": {"corners": [[x0, y0], [x1, y1]]}, "mesh": {"size": size}, **obstacle}
    )
    return outline, structured


@pytest.mark.parametrize(
    ("corners", "zone"),
    [
        # The paper's plate moved to the origin, its c1-like zone moved with it.
        (((0.0, 0.0), (0.2, 0.1)), [[0.06, 0.14], [0.0, 0.1]]),
        # Far from the origin, a zone inside the plate.
        (((1.3, -0.7), (1.5, -0.6)), [[1.33, 1.41], [-0.68, -0.62]]),
        # A zone reaching beyond the plate, and a line zone.
        (((0.0, 0.0), (0.3, 0.1)), [[0.17, 0.5], [0.03, 0.2]]),
        (((0.0, 0.0), (0.3, 0.1)), [[0.12, 0.12], [0.02, 0.08]]),
    ],
)
def test_gmsh_rectangle_anywhere_equals_the_structured_mesh(corners, zone):
    """An outline rectangle anywhere, with any box zone on the grid's lines.

    The structured mesh has nodes on the zone's edges; gmsh's mesh has the zone's edges
    as mesh lines and structured patches, so both solve the same discrete problem: the
    loads agree to 1e-10 and the contact nodes are the same. (Without the zone's lines,
    the plate at [0, 0.2] x [0, 0.1] with the zone [0.06, 0.14] gave 1.41307e7 Pa with
    i = 72 against the structured mesh's 1.45685e7 Pa with i = 81.)
    """
    outline, structured = _outline_and_structured(corners, zone)
    results = []
    for spec in (outline, structured):
        with solve(spec, MPI.COMM_WORLD) as analysis:
            results.append(analysis.result)
    ours, grid = results
    assert ours.mesh == [grid.mesh[0] * grid.mesh[1]]
    assert ours.free_load_Pa == pytest.approx(grid.free_load_Pa, rel=1e-10)
    assert ours.critical_load_Pa == pytest.approx(grid.critical_load_Pa, rel=1e-10)
    assert ours.constrained_nodes == grid.constrained_nodes
    assert np.allclose(
        sorted(map(tuple, ours.contact_coordinates)),
        sorted(map(tuple, grid.contact_coordinates)),
        rtol=0.0,
        atol=1e-12,
    )
    for report in (ours.obstacle_zones[0], grid.obstacle_zones[0]):
        assert report.discrete_area_m2 == pytest.approx(report.area_m2, rel=1e-12)


@pytest.mark.parametrize("size", [0.05, 0.01])
def test_circular_zone_is_the_circle(size):
    """The zone's circle is a mesh line: the discrete zone is the inscribed polygon.

    At least 32 cell edges on the circle: its area is within 1 % of pi r^2 (the regular
    32-gon has 32 sin(2 pi / 32) / (2 pi) = 99.36 % of it), at a cell size of 2.5 r as
    at r; every node on the circle is in the zone.
    """
    r = 0.02
    spec = problem_from_dict(
        {
            "plate": {
                "outline": [[0.0, 0.0], [0.2, 0.0], [0.2, 0.1], [0.0, 0.1]],
                "thickness": 0.006,
            },
            "edges": {
                "loaded": {"segments": [1, 3], "normal_stress": -1.0},
                "long": {"segments": [0, 2]},
            },
            "mesh": {"size": size},
            "obstacle": {"circle": {"center": [0.1, 0.05], "radius": r}},
        }
    )
    with build_problem(spec, MPI.COMM_WORLD) as problem:
        (report,) = zone_report(problem.mesh, spec.all_obstacles, spec.plate, ["obstacle"])
        x = problem.mesh.geometry.x
        n_owned = problem.mesh.geometry.index_map().size_local
        on_circle = np.abs(np.hypot(x[:n_owned, 0] - 0.1, x[:n_owned, 1] - 0.05) - r) < 1e-12
        count = MPI.COMM_WORLD.allreduce(int(on_circle.sum()), op=MPI.SUM)
    assert report.area_m2 == pytest.approx(np.pi * r**2, rel=1e-6)
    assert 0.99 * np.pi * r**2 < report.discrete_area_m2 <= np.pi * r**2
    assert count >= 32


def test_structured_zone_off_the_grid_is_reported(tmp_path, capsys):
    """The structured mesh and a zone whose edges miss its lines: the summary says so.

    20 x 10 cells of 0.01 m, zone [0.065, 0.135] x [0, 0.1]: the cells with every node in
    it are [0.07, 0.13] x [0, 0.1], 0.006 m^2 of 0.007 m^2 (85.71 %), on 7 x 11 = 77 nodes.
    """
    path = tmp_path / "off.toml"
    path.write_text(
        "[plate]\ncorners = [[0.0, 0.0], [0.2, 0.1]]\n[mesh]\nnx = 20\nny = 10\n"
        "[obstacle]\nzone = [[0.065, 0.135], [0.0, 0.1]]\n"
    )
    out = tmp_path / "off.json"
    assert cli_main(["solve", "--config", str(path), "--json", str(out), "-q"]) == 0
    summary = capsys.readouterr().out
    assert "obstacle zone on the mesh: the cells with every node in it cover 85.71% of its " in (
        summary
    )
    (report,) = json.loads(out.read_text())["obstacle_zones"]
    assert report["area_m2"] == pytest.approx(0.007, rel=1e-12)
    assert report["discrete_area_m2"] == pytest.approx(0.006, rel=1e-12)
    assert report["nodes"] == 77


def test_unnamed_boundary_parts_are_free():
    """Boundary parts not named are free.

    Only the loaded segments named: the long edges are free, as support = "free" on the
    structured rectangle (same grid: 1e-10).
    """
    spec = problem_from_dict(
        {
            "plate": {"outline": PAPER_OUTLINE, "thickness": 0.006},
            "edges": {"loaded": {"segments": [1, 3], "normal_stress": -1.0}},
            "mesh": {"size": 0.01},
        }
    )
    free_edges = problem_from_dict(
        {
            "edges": {"bottom": {"support": "free"}, "top": {"support": "free"}},
            "mesh": {"nx": 20, "ny": 10},
        }
    )
    with solve(spec) as analysis:
        ours = analysis.result.free_load_Pa
    with solve(free_edges) as analysis:
        reference = analysis.result.free_load_Pa
    assert ours == pytest.approx(reference, rel=1e-10)


def _rotated_square(side, degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
    return [[side * (c * x - s * y), side * (s * x + c * y)] for x, y in corners]


L_SHAPE = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.1], [0.1, 0.1], [0.1, 0.2], [0.0, 0.2]]


@pytest.mark.parametrize(
    ("outline", "width"),
    [
        (PAPER_OUTLINE, 0.1),
        (_rotated_square(0.2, 30.0), 0.2),  # bounding box 0.273 m a side
        (L_SHAPE, 0.1),  # bounding box 0.2 m: the arms are 0.1 m wide
        ([[0.0, 0.0], [0.2, 0.0], [0.25, 0.1], [0.05, 0.1]], 0.1),  # a skew parallelogram
    ],
)
def test_plate_warnings_take_the_outline_width(outline, width):
    """Fewer than 4 cells across the plate's width: warned however the outline lies.

    The rule is the rectangle's (b/4; the simply supported square's k is +18 % at 3
    cells across, ``tests/unit/cli/test_robustness.py``). It read the outline's bounding
    box: the square of side 0.2 m turned by 30 degrees, at mesh.size = 0.2/3 m, gave the
    axis-parallel square's k = 4.7009 (Navier's k = 4) without the warning the latter
    draws; the L-shape with 0.1 m arms at 0.05 m (2 cells across an arm) gave k = 18.10
    silently against 8.56 at 0.0125 m. Expected widths: the side, the arm, the height.
    The thick-plate note (t/b above 0.2) takes the same width.
    """
    assert narrowest_width(outline) == pytest.approx(width, rel=1e-12)
    for size, warned in ((width / 3, True), (width / 4, False)):
        spec = problem_from_dict(
            {
                "plate": {"outline": outline, "thickness": 0.001},
                "edges": {"all": {"segments": list(range(len(outline)))}},
                "mesh": {"size": size},
            }
        )
        note = coarse_mesh_note(spec.plate, spec.mesh)
        assert (note is not None) == warned, note
        if warned:
            assert f"the plate's narrowest width {width:.3g} m" in note
    # the thick-plate note's t/b > 0.2 (the rectangle's rule) by the same width
    for ratio, warned in ((0.25, True), (0.15, False)):
        plate = replace(spec.plate, thickness=ratio * width)
        assert (plate_model_note(plate) is not None) == warned


def _outline_plate(outline, thickness, **extra):
    return problem_from_dict(
        {
            "plate": {"outline": outline, "thickness": thickness},
            "edges": {"all": {"segments": list(range(len(outline)))}},
            "mesh": {"size": 0.01},
            **extra,
        }
    )


@pytest.mark.parametrize(
    ("outline", "width"),
    [
        (PAPER_OUTLINE, 0.1),
        (_rotated_square(0.2, 30.0), 0.2),  # bounding box 0.273 m a side
        (L_SHAPE, 0.1),  # bounding box 0.2 m: the arms are 0.1 m wide
    ],
)
def test_the_thickness_range_takes_the_outline_width(outline, width):
    """t/b at most 0.5 (not a plate above), b the outline's narrowest width.

    The rule is the rectangle's t/b in [1e-7, 0.5] (:data:`MAX_THICKNESS_RATIO`), with b
    the width the warnings take. It read the bounding box: the L-shape with 0.1 m arms at
    t = 0.06 m (t/b = 0.6 on an arm) was accepted as t/b = 0.06/0.2 = 0.3, and the turned
    square of side 0.2 m at t = 0.12 m (0.6) as 0.12/0.273 = 0.44. Expected: refused at
    0.6 times the width, naming the key, the width and the range; accepted at 0.45.
    """
    with pytest.raises(ValueError, match=r"plate\.thickness") as err:
        _outline_plate(outline, 0.6 * width)
    message = str(err.value)
    assert f"0.6 times the plate's narrowest width {width:g} m" in message, message
    assert "must be at most 0.5 times it" in message
    assert _outline_plate(outline, 0.45 * width).plate.thickness == 0.45 * width


def test_a_foundation_s_stiffness_limit_takes_the_outline_width():
    r"""K = k_f b^4/(pi^4 D) <= 1e12 with b the outline's width, not its bounding box's.

    The square of side b = 0.2 m turned by 45 degrees has a bounding box of side
    b sqrt(2): read there, K came out (sqrt 2)^4 = 4 times the axis-parallel square's,
    and a foundation of K = 5e11 (accepted on that square) was refused as K = 2e12.
    Expected (the formula, D = E t^3/12): K = 5e11 accepted, K = 2e12 refused naming
    the key and the limit, on both squares alike.
    """
    t, E = 0.002, 1.0e9
    D = E * t**3 / 12.0

    def foundation(K):
        kf = K * np.pi**4 * D / 0.2**4
        return {
            "material": {"E": E, "nu": 0.3},
            "obstacle": {"zone": "all", "foundation_stiffness": kf},
        }

    squares = (_rotated_square(0.2, 0.0), _rotated_square(0.2, 45.0))
    for outline in squares:
        assert _outline_plate(outline, t, **foundation(5e11)).tensionless
    for outline in squares:
        with pytest.raises(ValueError, match=r"obstacle\.foundation_stiffness") as err:
            _outline_plate(outline, t, **foundation(2e12))
        message = str(err.value)
        assert "K = k_f b^4/(pi^4 D) = 2e+12" in message, message
        assert "b the plate's narrowest width" in message and "K <= 1e+12" in message


def test_inclined_edge_needs_soft_support_or_clamping():
    """Hard simple support fixes the tangential rotation: only on axis-parallel edges."""
    outline = [[0.0, 0.0], [0.3, 0.0], [0.25, 0.1], [0.0, 0.1]]
    data = {
        "plate": {"outline": outline, "thickness": 0.003},
        "edges": {
            "left": {"segments": [3], "inplane": "clamped"},
            "slanted": {"segments": [1], "normal_stress": -1.0},
            "long": {"segments": [0, 2]},
        },
        "mesh": {"size": 0.02},
    }
    with pytest.raises(ValueError, match=r"edge 'slanted' is not parallel to a coordinate axis"):
        build_problem(problem_from_dict(data), MPI.COMM_WORLD)
    data["edges"]["slanted"]["support"] = "simply_supported_soft"
    with solve(problem_from_dict(data)) as analysis:
        assert analysis.result.free_load_Pa > 0


# -- files -------------------------------------------------------------------------------
GEO = """\
SetFactory("Built-in");
Point(1) = {0, 0, 0, 0.0125}; Point(2) = {0.2, 0, 0, 0.0125};
Point(3) = {0.2, 0.1, 0, 0.0125}; Point(4) = {0, 0.1, 0, 0.0125};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Physical Curve("ends") = {2, 4};
Physical Curve("sides") = {1, 3};
Physical Surface("plate") = {1};
"""


def test_geo_and_msh_files(tmp_path):
    """A .geo file and the .msh it gives.

    The .geo is meshed here with quadrilaterals; the edges are matched by physical name,
    the bounding box comes from the mesh; the .msh gives the .geo's load, and both the
    structured rectangle's to discretisation accuracy.
    """
    (tmp_path / "plate.geo").write_text(GEO)
    toml = tmp_path / "file.toml"
    toml.write_text(
        '[plate]\nfile = "plate.geo"\nthickness = 0.006\n'
        "[edges.ends]\nnormal_stress = -1.0\n[edges.sides]\n"
    )
    spec = load_toml(toml)
    assert spec.plate.file == str(tmp_path / "plate.geo")
    with solve(spec) as analysis:
        from_geo = analysis.result
        assert analysis.problem.spec.plate.corners == ((0.0, 0.0), (0.2, 0.1))
        assert {e.name: e.tag for e in analysis.problem.spec.plate.edges} == {"ends": 1, "sides": 2}
    assert problem_from_dict(from_geo.input) == spec  # the input written back is the file's
    navier, _ = navier_load_mindlin(1.0e9, 0.3, 0.006, 0.2, 0.1)
    with solve(paper_case("free", 16, 8)) as analysis:
        structured = analysis.result.free_load_Pa
    # The .geo's mesh (16x8-like, not the grid itself): far inside the 2 % mesh error.
    assert abs(from_geo.free_load_Pa - structured) < 1e-2 * abs(structured - navier)
    # The .msh of the same model.
    gmsh.initialize(interruptible=False)
    try:
        for key, value in GMSH_OPTIONS.items():  # the options the package meshes with
            gmsh.option.setNumber(key, value)
        gmsh.open(str(tmp_path / "plate.geo"))
        gmsh.model.mesh.generate(2)
        gmsh.write(str(tmp_path / "plate.msh"))
        gmsh.option.setNumber("Mesh.RecombineAll", 0)
        gmsh.model.mesh.clear()
        gmsh.model.mesh.generate(2)
        gmsh.write(str(tmp_path / "triangles.msh"))
    finally:
        gmsh.finalize()
    msh = replace(spec, plate=replace(spec.plate, file=str(tmp_path / "plate.msh")))
    with solve(msh) as analysis:
        assert analysis.result.free_load_Pa == pytest.approx(from_geo.free_load_Pa, rel=1e-10)
    triangles = replace(spec, plate=replace(spec.plate, file=str(tmp_path / "triangles.msh")))
    message = r"triangles\.msh: the gmsh mesh must consist of bilinear quadrilaterals .*Triangle"
    with pytest.raises(ValueError, match=message):
        build_problem(triangles, MPI.COMM_WORLD)


def test_file_zone_is_reported_against_its_area(tmp_path, capsys):
    """A .geo plate and zones off its nodes: the zone's area from the cells, and the note.

    The file's plate is known by its cells only: the zone's area was null and the
    summary said nothing, where the structured mesh's off-grid zone draws the note. The
    box [0.03, 0.13] x [0, 0.1] lies on the 0.2 x 0.1 m plate: 0.01 m^2; the arrowhead
    polygon 0.16 x 0.1 m less a 0.08 x 0.1 m triangle: 0.012 m^2 (a non-convex zone).
    """
    (tmp_path / "plate.geo").write_text(GEO)
    for zone, area in (
        ("zone = [[0.03, 0.13], [0.0, 0.1]]", 0.01),
        ("polygon = [[0.02, 0.0], [0.18, 0.0], [0.1, 0.05], [0.18, 0.1], [0.02, 0.1]]", 0.012),
    ):
        toml, out = tmp_path / "file.toml", tmp_path / "file.json"
        toml.write_text(
            '[plate]\nfile = "plate.geo"\nthickness = 0.006\n'
            f"[edges.ends]\nnormal_stress = -1.0\n[edges.sides]\n[obstacle]\n{zone}\n"
        )
        assert cli_main(["solve", "--config", str(toml), "--json", str(out), "-q"]) == 0
        assert "obstacle zone on the mesh: the cells with every node in it cover" in (
            capsys.readouterr().out
        )
        (report,) = json.loads(out.read_text())["obstacle_zones"]
        assert report["area_m2"] == pytest.approx(area, rel=1e-12)
        assert report["discrete_area_m2"] < area


def test_file_edge_names_must_exist(tmp_path, capsys):
    (tmp_path / "plate.geo").write_text(GEO)
    toml = tmp_path / "typo.toml"
    toml.write_text('[plate]\nfile = "plate.geo"\n[edges.end]\nnormal_stress = -1.0\n')
    assert cli_main(["solve", "--config", str(toml)]) == 2
    err = capsys.readouterr().err
    assert "edges.end:" in err and "no boundary part (physical curve) named 'end'" in err
    assert "['ends', 'sides']" in err
    (tmp_path / "nosurface.geo").write_text(GEO.replace('Physical Surface("plate") = {1};\n', ""))
    toml.write_text('[plate]\nfile = "nosurface.geo"\n[edges.ends]\nnormal_stress = -1.0\n')
    assert cli_main(["solve", "--config", str(toml)]) == 2
    assert "no physical surface" in capsys.readouterr().err


# -- a plate with a hole ------------------------------------------------------------------
def test_the_independent_triangles_reproduce_navier():
    """The reference code itself reproduces the Navier load.

    P3 triangles on the square without hole (h = b/8) give the Navier load of the hard
    simply supported Reissner-Mindlin plate within 1e-4.
    """
    load, navier = navier_check(1.0, 0.01, 1 / 8)
    assert load == pytest.approx(navier, rel=1e-4)


def test_holed_plate_against_cubic_triangles():
    """A square plate with a central hole against the independent P3-triangle value.

    SSSS square, central hole d/b = 0.3, uniaxial compression: MITC4 on gmsh quads
    (h = b/16) within 1 % of the independent P3-triangle computation (h = b/16), both
    above their common limit (k = 3.2248, see the convergence test).
    """
    with solve(holed_square(1 / 16)) as analysis:
        ours = analysis.result.free_load_Pa
        assert analysis.problem.spec.plate.holes
    reference = holed_plate_load(1.0, 0.3, 0.01, 1 / 16)
    assert ours == pytest.approx(reference, rel=1e-2)
    assert min(ours, reference) > 291_400.0  # the extrapolated limit, 291 457 Pa


@pytest.mark.convergence
def test_holed_plate_converges_to_the_independent_value():
    """The holed plate converges at rate 2 to the independent computation's limit.

    MITC4 on gmsh quads, h = b/32, b/64, b/128: observed rate about 2 (measured 2.08),
    Richardson within 1e-4 of the P3-triangle Richardson (h = b/32, b/50; measured
    291 457.2 and 291 457.6 Pa, k = 3.2248; the plate without hole has k = 4).
    """
    loads = []
    for h in (1 / 32, 1 / 64, 1 / 128):
        with solve(holed_square(h)) as analysis:
            loads.append(analysis.result.free_load_Pa)
    d = np.diff(loads)
    rate = np.log2(d[0] / d[1])
    assert 1.7 < rate < 2.3, f"observed rate {rate:.2f}: {loads}"
    ours = loads[-1] + (loads[-1] - loads[-2]) / (2**rate - 1)
    p3 = [holed_plate_load(1.0, 0.3, 0.01, h) for h in (1 / 32, 1 / 50)]
    theirs = p3[1] + (p3[1] - p3[0]) * (1 / 50) ** 2 / ((1 / 32) ** 2 - (1 / 50) ** 2)
    assert ours == pytest.approx(theirs, rel=1e-4), (loads, p3)


def test_holed_plate_with_an_obstacle_is_certified():
    """The holed square against a rigid face below it, under compression + shear.

    A KKT point above the free load; the zone's nodes around the hole only (none in it).
    """
    spec = holed_square(
        1 / 8,
        edges={
            "left": {"normal_stress": -1.0, "shear_stress": 0.5},
            "right": {"normal_stress": -1.0, "shear_stress": 0.5},
            "bottom": {"shear_stress": -0.5},
            "top": {"shear_stress": -0.5},
        },
        obstacle={"zone": "all", "side": "below"},
    )
    with solve(spec) as analysis:
        result = analysis.result
        xy = analysis.problem.contact.coordinates
    assert result.certificate.kkt and result.ratio_to_free >= 1 - 1e-8
    assert np.hypot(xy[:, 0], xy[:, 1]).min() >= 0.15 * np.cos(np.pi / 16) - 1e-9


def test_thin_holed_plate_is_nested_over_gmsh_meshes():
    """A thin holed plate: the interior point nested over gmsh meshes at 2h and h.

    Against a whole face (the shorter side keeps 6 cells at 2h), with the load of the
    route on h alone. The meshes are not nested (the carry interpolates between any
    two); the reference is the same route from starts on the fine mesh itself (no
    coarser mesh allowed).
    """
    data = {
        "plate": {
            "corners": [[0.0, 0.0], [0.3, 0.1]],
            "thickness": 1e-4,
            "holes": [{"center": [0.15, 0.05], "radius": 0.02}],
        },
        "edges": {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}},
        "mesh": {"size": 0.1 / 16},
        "obstacle": {"zone": "all", "side": "below"},
    }
    loads, meshes = [], []
    for options in (ChainOptions(), ChainOptions(explore_min_cells=10**6)):
        with build_problem(problem_from_dict(data)) as problem:
            sol = solve_interior_point(problem, options)
            assert sol.method == "interior-point" and sol.candidate.kkt
            loads.append(sol.load)
            meshes.append([level.mesh for level in sol.details.levels])
            seeds = [link.seed for level in sol.details.levels for link in level.links]
    # On one mesh nothing is made for a finer one (central-path points to carry).
    assert not any("kept flat" in s or "lifted" in s or "after polish" in s for s in seeds)
    assert meshes == [[["h=0.0125"], ["h=0.00625"]], [["h=0.00625"]]]
    assert loads[0] == pytest.approx(loads[1], rel=1e-9)
