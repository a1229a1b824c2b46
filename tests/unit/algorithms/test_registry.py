"""The registry of methods: each method once, its options, the links of its route.

Every method a problem file may name (``spec.Method``) except "auto", which chooses among
them, runs through one entry of ``algorithms.registry.REGISTRY``; the entry's options
Struct is the one ``spec.OPTIONS`` gives (the command line's method flags come from it),
read from the problem's ``[solver]`` table; a result's ``route`` starts with its method
and takes only the links its entry lists. The problems are the paper's plate C1
(section 6.1) on coarse meshes and a square plate on a tensionless foundation; the
checks are of names and options, not of loads (those are tested per method).
"""

from __future__ import annotations

import math

import pytest
from msgspec import structs

from unibuckle_fenicsx.algorithms.registry import FOUNDATION, REGISTRY, entry
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.materials import bending_stiffness
from unibuckle_fenicsx.spec import OPTIONS, Method, ObstacleSpec
from unibuckle_fenicsx.spec.cases import paper_case, plate_case
from unibuckle_fenicsx.spec.solver import PenaltyOptions


def test_every_method_but_auto_has_one_entry_with_the_specs_options():
    assert set(REGISTRY) == {m.value for m in Method if m is not Method.AUTO} | {FOUNDATION}
    for method in Method:
        if method is not Method.AUTO:
            assert REGISTRY[method].options is OPTIONS[method]
            assert REGISTRY[method].links[0] == method.value
    assert REGISTRY[FOUNDATION].links[0] == FOUNDATION
    with pytest.raises(InputError, match="unknown method 'auto'"):
        entry("auto")


def test_the_entries_that_run_on_sections_are_the_methods_a_section_names():
    # A section file may name SECTION_METHODS (spec, no PETSc); each but "auto" must run
    # through an entry with a section runner, and an elastic core through the foundation's.
    from unibuckle_fenicsx.spec.section import SECTION_METHODS

    on_sections = {name for name, e in REGISTRY.items() if e.section is not None}
    assert on_sections == {m.value for m in SECTION_METHODS if m is not Method.AUTO} | {FOUNDATION}


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
