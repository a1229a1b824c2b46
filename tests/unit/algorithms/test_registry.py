"""The registry of methods: each method once, its options, the links of its route.

Every method a problem file may name (``spec.Method``) except "auto", which chooses among
them, runs through one entry of ``algorithms.registry.REGISTRY``; the entry's options
Struct is the one ``spec.OPTIONS`` gives (the command line's method flags come from it),
read from the problem's ``[solver]`` table; a result's ``route`` starts with its method
and takes only the links its entry lists. Two entries no file names: a tensionless
foundation's spring-set iteration and "auto"'s routes on a section, both section routes
on a small one (``section_levels.BOTH``) and the interior point checked by the active
set's seeds on a large one (``section_levels.CHECKED``), section runners only. Every
name the command line and the schema accept resolves, through the choice of a plate's or
a section's method, to an entry that runs on that kind of problem; an entry asked of the
other kind is refused naming ``solver.method``. The problems are the paper's plate C1
(section 6.1) on coarse meshes and a square plate on a tensionless foundation; the
checks are of names and options, not of loads (those are tested per method).
"""

from __future__ import annotations

import math

from mpi4py import MPI

import pytest
from msgspec import structs

from unibuckle_fenicsx.algorithms.registry import (
    FOUNDATION,
    REGISTRY,
    choose_method,
    choose_section_method,
    entry,
)
from unibuckle_fenicsx.algorithms.section_levels import BOTH, CHECKED, INTERIOR_POINT_DOFS
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.errors import FieldError, InputError
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.materials import bending_stiffness
from unibuckle_fenicsx.model.shell.section import SectionParameters
from unibuckle_fenicsx.spec import OPTIONS, Method, ObstacleSpec, SolverSpec, json_schema
from unibuckle_fenicsx.spec.cases import paper_case, plate_case
from unibuckle_fenicsx.spec.section import SECTION_METHODS
from unibuckle_fenicsx.spec.solver import PenaltyOptions


def test_every_method_but_auto_has_one_entry_with_the_specs_options():
    named = {m.value for m in Method if m is not Method.AUTO}
    assert set(REGISTRY) == named | {FOUNDATION, BOTH, CHECKED}
    for method in Method:
        if method is not Method.AUTO:
            assert REGISTRY[method].options is OPTIONS[method]
            assert REGISTRY[method].links[0] == method.value
    assert REGISTRY[FOUNDATION].links[0] == FOUNDATION
    with pytest.raises(InputError, match="unknown method 'auto'"):
        entry("auto")


def test_the_entries_that_run_on_sections_are_the_methods_a_section_names():
    # A section file may name SECTION_METHODS (spec, no PETSc); each but "auto" must run
    # through an entry with a section runner, an elastic core through the foundation's
    # and "auto" through both routes' (small) or the checked interior point's (large).
    on_sections = {name for name, e in REGISTRY.items() if e.section is not None}
    named = {m.value for m in SECTION_METHODS if m is not Method.AUTO}
    assert on_sections == named | {FOUNDATION, BOTH, CHECKED}


def test_the_entries_that_run_on_plates_are_every_method_a_plate_names():
    on_plates = {name for name, e in REGISTRY.items() if e.run is not None}
    assert on_plates == {m.value for m in Method if m is not Method.AUTO} | {FOUNDATION}


def test_an_entrys_options_are_those_of_the_solver_table():
    spec = paper_case("c1")
    solver = structs.replace(spec.solver, method=Method.PENALTY, penalty=5.0, max_iterations=7)
    assert entry("penalty").options_of(solver) == PenaltyOptions(penalty=5.0)
    assert entry("active-set").options_of(solver).max_iterations == 7


@pytest.mark.parametrize("method", ["enumerate", "active-set", "interior-point", "penalty"])
def test_a_result_names_its_method_and_a_route_of_its_links(method):
    spec = paper_case("c1").with_mesh(8, 4)
    spec = structs.replace(spec, solver=structs.replace(spec.solver, method=method))
    with solve(spec) as analysis:
        result = analysis.result
    assert result.method == method and result.method_chosen_by == "given"
    assert result.route[0] == method
    assert set(result.route) <= set(REGISTRY[method].links)


def test_a_tensionless_foundation_runs_its_own_entry():
    d = bending_stiffness(1.0e9, 0.3, 1e-3)
    zone = ObstacleSpec("all", foundation_stiffness=100.0 * math.pi**4 * d)
    spec = plate_case("strip", length=1.0, width=1.0, thickness=1e-3, nx=8, ny=8, zone=zone)
    with solve(spec) as analysis:
        result = analysis.result
    assert result.method == FOUNDATION and result.route[0] == FOUNDATION
    assert set(result.route) <= set(REGISTRY[FOUNDATION].links)


def _accepted_methods():
    """The method names the command line's --method and the problem file's schema accept."""
    from unibuckle_fenicsx.cli.flags import build_parser

    _, commands = build_parser()
    (flag,) = [a for a in commands["solve"]._actions if a.dest == "method"]
    cli = set(flag.choices)
    schema = set(json_schema()["$defs"]["Method"]["enum"])
    assert cli == schema == {m.value for m in Method}
    return sorted(cli)


def _square_box(h, **changes):
    """A filled square box b = 0.1 m, L = 0.3 m: 6 (4 b/h) (L/h + 1) DOFs, none built."""
    return SectionParameters(
        "box", width=0.1, depth=0.1, thickness=0.002, length=0.3, E=2.1e11, nu=0.3,
        mesh_size=h, ends="simply_supported", core=True, **changes,
    )  # fmt: skip


@pytest.mark.parametrize("method", _accepted_methods())
def test_every_accepted_method_resolves_to_a_plate_entry(method):
    # The paper's plate C1: t/b = 0.06, above THIN_PLATE = 0.02; the same plate 0.1 mm
    # thick is thin. "auto" enumerates 2^4 sets at 1 ms each, and takes the active set
    # (thick) or the interior point (thin) past max_candidates = 10^5 (i = 2000).
    thick = paper_case("c1")
    thin = structs.replace(thick, plate=structs.replace(thick.plate, thickness=1e-4))
    chosen = set()
    for spec in (thick, thin):
        spec = structs.replace(spec, solver=structs.replace(spec.solver, method=method))
        for i in (4, 2000):
            name, _ = choose_method(spec, i, 1e-3)
            assert entry(name).run is not None, name
            chosen.add(name)
    expected = {"enumerate", "active-set", "interior-point"} if method == "auto" else {method}
    assert chosen == expected


@pytest.mark.parametrize("method", _accepted_methods())
def test_every_accepted_method_resolves_to_a_section_entry_or_is_refused(method):
    # Cells 12.5 mm: 6 x 32 x 25 = 4 800 DOFs, below INTERIOR_POINT_DOFS; 6.25 mm:
    # 6 x 64 x 49 = 18 816, above it.
    small, large = _square_box(0.0125), _square_box(0.00625)
    assert 4800 < INTERIOR_POINT_DOFS <= 18816
    solver = SolverSpec(method=method)
    if method not in SECTION_METHODS:
        with pytest.raises(FieldError) as refused:
            choose_section_method(small, solver)
        assert str(refused.value).startswith("solver.method must be one of")
        return
    chosen = {choose_section_method(p, solver)[0] for p in (small, large)}
    for name in chosen:
        assert entry(name).section is not None, name
    assert chosen == ({BOTH, CHECKED} if method == "auto" else {method})


def test_an_elastic_core_and_a_tensionless_foundation_resolve_to_the_foundations_entry():
    elastic = _square_box(0.0125, foundation_stiffness=1e9)
    assert choose_section_method(elastic, SolverSpec())[0] == FOUNDATION
    d = bending_stiffness(1.0e9, 0.3, 1e-3)
    zone = ObstacleSpec("all", foundation_stiffness=100.0 * math.pi**4 * d)
    spec = plate_case("strip", length=1.0, width=1.0, thickness=1e-3, nx=8, ny=8, zone=zone)
    assert choose_method(spec, 81, 1e-3)[0] == FOUNDATION
    assert entry(FOUNDATION).run is not None and entry(FOUNDATION).section is not None


def test_a_section_only_entry_is_refused_for_a_plate_naming_the_key():
    problem = build_problem(paper_case("c1").with_mesh(8, 4), MPI.COMM_WORLD)
    with problem, pytest.raises(FieldError) as refused:
        entry(BOTH).solve(problem)
    assert refused.value.field == "solver.method"
    assert str(refused.value) == (
        "solver.method = 'both' does not run on a plate: enumerate, interior-point, "
        "active-set, penalty, foundation do"
    )


def test_a_plate_only_entry_is_refused_for_a_section_naming_the_key():
    # Refused before anything is built (the section's parameters only).
    with pytest.raises(FieldError) as refused:
        entry("penalty").solve_section(_square_box(0.0125), 0, MPI.COMM_SELF, SolverSpec())
    assert refused.value.field == "solver.method"
    assert str(refused.value) == (
        "solver.method = 'penalty' does not run on a section: interior-point, active-set, "
        "foundation, both, interior-point+seeds do"
    )
