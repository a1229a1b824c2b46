"""A section's method: chosen where a plate's is, named in its file or on the command line.

``analysis.choose_section_method`` decides it before any mesh, by the documented rule
(``docs/verification/sections.md``, "Cost"): without a core the free load, with an
elastic core the spring-set iteration, with a rigid core the ``[solver] method`` given,
"auto" taking the interior point on sections of at least ``INTERIOR_POINT_DOFS`` = 10^4
DOFs and the active set on smaller ones. The expected DOFs are worked out here by hand:
a box of square faces b on uniform cells h has 4 b/h nodes around, L/h + 1 along and six
DOFs per node (the demo's box: 6 x 32 x 25 = 4 800; the box b/16 of the Cost table:
6 x 64 x 49 = 18 816). A method given in a file runs that route: its load is the one
``solve_levels`` gives with that route.
"""

from __future__ import annotations

import json

from mpi4py import MPI

import pytest

import unibuckle_fenicsx.analysis as analysis
from unibuckle_fenicsx import SectionParameters, section_from_dict, solve_section
from unibuckle_fenicsx.algorithms.section_levels import solve_levels
from unibuckle_fenicsx.analysis import choose_section_method
from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, EXIT_OK, main
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.shell.section import section_parameters
from unibuckle_fenicsx.spec import SolverSpec

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial sections")

E, NU = 2.1e11, 0.3
REFUSED = 'solver.method must be one of "auto", "interior-point", "active-set" for a section'


def _square_box(b, length, h, **changes):
    """A square box of faces ``b`` on cells ``h``: 6 (4 b/h) (L/h + 1) DOFs."""
    base = {
        "width": b, "depth": b, "thickness": 0.002, "length": length, "E": E, "nu": NU,
        "mesh_size": h, "ends": "simply_supported", "core": True,
    }  # fmt: skip
    return SectionParameters("box", **{**base, **changes})


def _dofs(b, length, h):
    return 6 * round(4 * b / h) * (round(length / h) + 1)


def test_auto_takes_the_interior_point_from_ten_thousand_dofs():
    small, large = _square_box(0.1, 0.3, 0.0125), _square_box(0.2, 0.6, 0.0125)
    assert (_dofs(0.1, 0.3, 0.0125), _dofs(0.2, 0.6, 0.0125)) == (4800, 18816)
    auto = SolverSpec()
    assert choose_section_method(small, auto) == (
        "active-set",
        "auto: about 4800 DOFs (estimated before meshing) < INTERIOR_POINT_DOFS = 10000",
    )
    assert choose_section_method(large, auto) == (
        "interior-point",
        "auto: about 18816 DOFs (estimated before meshing) >= INTERIOR_POINT_DOFS = 10000",
    )


def test_auto_counts_a_section_of_exactly_the_threshold_as_large(monkeypatch):
    # "at least INTERIOR_POINT_DOFS": a threshold equal to the section's DOFs.
    monkeypatch.setattr(analysis, "INTERIOR_POINT_DOFS", 4800)
    method, _ = choose_section_method(_square_box(0.1, 0.3, 0.0125), SolverSpec())
    assert method == "interior-point"


def test_a_given_method_runs_whatever_the_size():
    small, large = _square_box(0.1, 0.3, 0.0125), _square_box(0.2, 0.6, 0.0125)
    given = SolverSpec(method="interior-point")
    assert choose_section_method(small, given) == ("interior-point", "given")
    assert choose_section_method(large, SolverSpec(method="active-set")) == ("active-set", "given")


def test_no_core_and_an_elastic_core_run_their_own():
    hollow = _square_box(0.1, 0.3, 0.0125, core=False)
    assert choose_section_method(hollow, SolverSpec()) == ("free", "no core")
    elastic = _square_box(0.1, 0.3, 0.0125, foundation_stiffness=1e9)
    assert choose_section_method(elastic, SolverSpec()) == (
        "foundation",
        "elastic core: spring-set iteration",
    )


@pytest.mark.parametrize("method", ["enumerate", "penalty"])
def test_a_plate_only_method_is_refused_naming_the_key(method):
    with pytest.raises(InputError, match=f"{REFUSED}, got '{method}'"):
        choose_section_method(_square_box(0.1, 0.3, 0.0125), SolverSpec(method=method))
    with pytest.raises(InputError, match=REFUSED):
        solve_section(_square_box(0.1, 0.3, 0.0125), solver=SolverSpec(method=method))


#: A small square box with a core (b = 0.1 m, 25 mm cells: 6 x 16 x 9 = 864 DOFs).
FILE = {
    "section": {"shape": "box", "width": 0.1, "depth": 0.1, "thickness": 0.002,
                "length": 0.2, "ends": "simply_supported"},
    "material": {"E": E, "nu": NU},
    "obstacle": {"core": True},
    "mesh": {"size": 0.025, "levels": 1},
}  # fmt: skip


@pytest.mark.parametrize("method", ["interior-point", "active-set"])
def test_a_files_method_runs_that_route(method):
    spec = section_from_dict({**FILE, "solver": {"method": method}})
    with solve_section(spec, MPI.COMM_SELF) as solved:
        result = solved.result
    assert result.method == f"{method} (section levels)"
    assert result.method_chosen_by == "given"
    finest, solution = solve_levels(
        section_parameters(spec), levels=1, comm=MPI.COMM_SELF, route=method
    )
    with finest:
        assert result.critical_load_Pa == pytest.approx(solution.load, rel=1e-12)


def test_the_command_lines_method_reaches_a_section(tmp_path, capsys):
    path = tmp_path / "box.json"  # a problem file in JSON
    path.write_text(json.dumps(FILE))
    out = tmp_path / "result.json"
    args = ["solve", "--config", str(path), "--json", str(out)]
    assert main(args) == EXIT_OK
    auto = json.loads(out.read_text())
    assert auto["method"] == "active-set (section levels)"
    assert auto["method_chosen_by"].startswith("auto: about 864 DOFs")
    assert main([*args, "--method", "interior-point"]) == EXIT_OK
    given = json.loads(out.read_text())
    assert given["method"] == "interior-point (section levels)"
    assert given["method_chosen_by"] == "given"
    assert given["route"][0] == "interior-point"
    capsys.readouterr()
    assert main([*args, "--method", "penalty"]) == EXIT_BAD_INPUT
    assert REFUSED in capsys.readouterr().err
