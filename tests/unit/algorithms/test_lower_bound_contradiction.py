"""An admissible load below a proven lower bound is flagged, never made the lower bound.

No eigenvalue of a reduced pencil lies below the free load (interlacing: removing DOFs
never lowers the smallest eigenvalue), and no admissible mode's load below the critical
load. A filled tube's active set (D = 0.1 m, t = 1 mm, 5 mm cells) once took a pair that
was no eigenpair for an admissible mode at 2.026e9 Pa, below the hollow tube's 2.366e9,
and reported ``lower_bound = min(lower, load)``: that load, as a "verified lower bound".
Here a pair is made spurious on purpose (its load scaled below the free load) on the
paper's plate c1 at 8 x 4 cells; the references are dense scipy eigenvalues of the pencil.
"""

from __future__ import annotations

import dataclasses

from mpi4py import MPI

import numpy as np
import pytest

from support.exhaustive import RTOL, dense_free_load, dense_reduced_load, exhaustive_minimum
from unibuckle_fenicsx.algorithms import UnilateralSolution
from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.algorithms.bounds import bracket
from unibuckle_fenicsx.algorithms.foundation import solve_foundation
from unibuckle_fenicsx.certificate.certify import certify, certify_foundation
from unibuckle_fenicsx.errors import EigenSolveError
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec import ObstacleSpec
from unibuckle_fenicsx.spec.cases import paper_case, plate_case

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial")


@pytest.fixture
def problem():
    p = build_problem(paper_case("c1", 8, 4), MPI.COMM_SELF)
    yield p
    p.destroy()


#: The counts a route's record reads.
TIMINGS = {"factorisations": 0.0, "solves": 0.0, "total_s": 0.0}


@pytest.fixture
def foundation():
    """A 2 x 1 plate (16 x 8 cells) on a whole-face tensionless foundation, solved."""
    spec = plate_case(
        "strip", length=2.0, width=1.0, thickness=1e-3, nx=16, ny=8,
        zone=ObstacleSpec("all", foundation_stiffness=1.0e3), supports="simply_supported",
    )  # fmt: skip
    p = build_problem(spec, MPI.COMM_SELF)
    yield p, solve_foundation(p)
    p.destroy()


def _spurious(cand, load):
    """``cand`` claiming the load ``load``, as a pair that is no eigenpair would."""
    return dataclasses.replace(cand, load=load)


def test_a_load_below_the_free_load_is_solved_again(problem):
    free = problem.solve_free().load
    assert free == pytest.approx(dense_free_load(problem), rel=1e-8)  # scipy
    active = np.arange(3)
    true = dense_reduced_load(problem, tuple(active))
    cand = _spurious(problem.evaluate(active), 0.8 * free)
    closed = bracket(problem, free, cand, 0, "active-set")
    assert closed.chosen.load == pytest.approx(true, rel=1e-8)
    assert closed.lower == free  # the proven bound, not the spurious load
    assert "no eigenpair" in closed.warning
    assert not closed.proven or closed.chosen.load <= free * (1 + 1e-10)


def test_a_load_that_stays_below_is_an_error_not_a_bound(problem, monkeypatch):
    free = problem.solve_free().load
    active = np.arange(3)
    cand = _spurious(problem.evaluate(active), 0.8 * free)
    monkeypatch.setattr(problem, "evaluate", lambda z, **_: cand)  # the solver stays wrong
    with pytest.raises(EigenSolveError, match="not an eigenpair"):
        bracket(problem, free, cand, 0, "active-set")


def test_the_active_set_reports_the_proven_bound(problem, monkeypatch):
    """A pair from a start vector made spurious; solved again from SLEPc's own start."""
    free = problem.solve_free().load
    evaluate = problem.evaluate

    def from_a_start(active, initial=None, near=None):
        cand = evaluate(active, initial=initial, near=near)
        if initial is not None or near is not None:
            return _spurious(cand, 0.9 * free)
        return cand

    monkeypatch.setattr(problem, "evaluate", from_a_start)
    solution = solve_active_set(problem, multilevel=False, bound_budget=0)
    assert solution.lower_bound == free  # the proven bound (interlacing), not 0.9 of it
    assert solution.load >= free
    assert solution.load == pytest.approx(
        dense_reduced_load(problem, tuple(solution.active)), rel=1e-8
    )
    assert "no eigenpair" in solution.details.warning


def test_the_certificate_refuses_a_bracket_upside_down(problem):
    free = problem.solve_free().load
    cand = problem.evaluate(np.arange(problem.contact.size))  # Z = I: admissible
    assert cand.feasible and cand.eigen is not None
    solution = UnilateralSolution(
        candidate=cand,
        method="candidate",
        eigensolves=0,
        lower_bound=1.1 * cand.load,  # claimed proven, and above an admissible load
        global_optimum_proven=False,
        upper_bound=cand.load,
        lower_bound_by="lattice",
    )
    assert cand.load > free
    with pytest.raises(EigenSolveError, match="below the proven lower bound"):
        certify(problem, solution, global_bound=False)


def test_a_continued_solve_below_the_proven_bound_is_an_error(problem):
    """The solve continued from a refuting mode cannot end below the proven bound.

    A refuting mode is admissible, so its load is at least the critical load, at least
    the free load (interlacing; scipy's reference above). One made to claim 0.8 of the
    free load (as a pair that is no eigenpair would) was kept as the answer and made the
    lower bound (``min(lower, load)``) by the starting code.
    """
    from unibuckle_fenicsx.algorithms.descent import continue_from

    free = problem.solve_free().load
    solution = solve_active_set(problem, multilevel=False, bound_budget=0)
    assert solution.lower_bound == pytest.approx(free, rel=1e-12)
    start = _spurious(problem.evaluate(np.arange(problem.contact.size)), 0.8 * free)
    assert start.feasible
    with pytest.raises(EigenSolveError, match="below the proven lower bound"):
        continue_from(problem, solution, start, 5)


def test_a_copositivity_bound_above_the_load_is_an_error_not_a_proof(problem, monkeypatch):
    """A route's bound above the KKT point's own (admissible) load is refused.

    No admissible mode has a load below the critical load, which is at most the KKT
    point's: a bound above it is none. The starting code clipped it to the load
    (``min(bound, upper)``), closing the bracket: "proven" by a false bound. The
    reference: the exhaustive minimum over the 2^i contact sets by dense LAPACK lies at
    the KKT point's load, below the claimed bound.
    """
    from unibuckle_fenicsx.certificate import certify as certify_module
    from unibuckle_fenicsx.certificate.copositivity import LowerBound

    solution = solve_active_set(problem, multilevel=False, bound_budget=0)
    cand = solution.candidate
    assert cand.feasible and cand.eigen is not None
    minimum, _, _ = exhaustive_minimum(problem)
    assert minimum <= cand.load * (1 + RTOL)  # the critical load: no bound lies above it
    false = 1.1 * cand.load

    def wrong_bound(*args, **kwargs):
        return LowerBound(false, "rank2-spn", -0.1, timings=TIMINGS)

    monkeypatch.setattr(certify_module, "copositivity_bound", wrong_bound)
    with pytest.raises(EigenSolveError, match="below the proven lower bound"):
        certify(problem, solution, global_bound=True)


def test_a_foundation_load_below_the_free_load_is_an_error(foundation):
    """The tensionless foundation's load cannot lie below the free load.

    The springs only stiffen (a positive semidefinite term added to A): every eigenvalue
    of the pencil with them lies at or above the free plate's (scipy's dense value, as
    the reference). A pair claiming 0.8 of the free load (as one that is no eigenpair
    would) was made the lower bound and the upper by the starting code (``min``).
    """
    problem, solution = foundation
    free = problem.solve_free().load
    assert free == pytest.approx(dense_free_load(problem), rel=1e-8)  # scipy
    wrong = dataclasses.replace(solution, candidate=_spurious(solution.candidate, 0.8 * free))
    with pytest.raises(EigenSolveError, match="below the proven lower bound"):
        certify_foundation(problem, wrong)
    assert certify_foundation(problem, solution).lower_bound == pytest.approx(free, rel=1e-12)
