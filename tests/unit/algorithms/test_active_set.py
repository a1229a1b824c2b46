r"""Active-set method (algorithms/active_set.py) against independent computations.

- A randomised, seeded family of small problems (random plates of aspect 1-3, random
  box zones, coarse meshes, i <= 12): the exhaustive minimum over all 2^i contact sets,
  computed here with dense numpy (the pencil condensed onto w by a Schur complement,
  every subset's reduced pencil solved with ``numpy.linalg.eigh``), must equal the
  active-set load to 1e-8 and its contact set.
- The paper's zones: a certified KKT point; the interlacing order of the zones
  (c2 within c1 within c3) orders the loads; multilevel equals single-level.
- The lattice lower bound is valid, and closes on small problems.
- The iteration with looser thresholds first ends at KKT points of the exact problem,
  checked with scipy's sparse Lanczos (ARPACK): on the random family (and never below
  the dense exhaustive minimum), and on a thin plate (t/b = 1e-3, whole-plate obstacle)
  where the thresholds are what lets the polish of the prolonged coarse contact set end
  within its iterate budget.
- ``mpiexec -n 2``: the distributed result equals the serial one.
- ``-m convergence``: the unilateral load of each zone converges at rate h^2 (20x10 ..
  160x80), with a Richardson-extrapolated value.
"""

from __future__ import annotations

import json
import math

from mpi4py import MPI

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg

from support.exhaustive import RTOL, exhaustive_minimum, satisfies_kkt
from support.paths import MPI_SCRIPTS
from support.plates import STEEP_TOML
from support.processes import run_mpi
from unibuckle_fenicsx.algorithms import RunStatus
from unibuckle_fenicsx.algorithms.active_set import (
    POLISH_ITERATIONS,
    THRESHOLDS,
    distinct_kkt,
    multi_seed,
    solve_active_set,
)
from unibuckle_fenicsx.algorithms.multilevel import prolong, prolong_contact_set
from unibuckle_fenicsx.algorithms.pdas import iterate
from unibuckle_fenicsx.certificate.certify import certify
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.results.records import jsonable
from unibuckle_fenicsx.spec import ObstacleSpec, ProblemSpec
from unibuckle_fenicsx.spec.cases import paper_case, plate_case

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference is serial")


# -- random family ----------------------------------------------------------------------
@pytest.fixture(scope="module")
def family(active_specs) -> list[ProblemSpec]:
    return active_specs


#: Problems of the family where the iteration (all seeds) stops at a KKT point that is
#: not the global minimum (checked against the exhaustive list: e.g. random29 has KKT
#: points Z = (0, 1) at 23.646 MPa and the global Z = (1, 2) at 23.142 MPa). A local
#: method cannot exclude this (the problem is NP-hard); the lattice search recovers it.
KNOWN_LOCAL_MINIMA = {"random29"}


@pytest.mark.slow
@serial
def test_random_family_matches_exhaustive_enumeration(family):
    """Same load (1e-8) and contact set as the dense exhaustive minimum, 50 problems.

    The iteration alone (``bound_budget=0``) agrees except on :data:`KNOWN_LOCAL_MINIMA`,
    where it returns a certified, non-global KKT point (an upper bound); with the lattice
    search those are solved and proven optimal too.
    """
    report = []
    disagreements = {}
    for spec in family:
        problem = build_problem(spec, MPI.COMM_SELF)
        problem.solve_free()
        sol = solve_active_set(problem, bound_budget=0)
        best, minimisers, _ = exhaustive_minimum(problem)
        z = tuple(int(k) for k in sol.active)
        rel = abs(sol.load - best) / best
        report.append((spec.name, problem.num_constrained, rel, len(minimisers)))
        assert best > sol.details.free_load * (1 + RTOL)  # the obstacle is active
        assert certify(problem, sol).kkt, (spec.name, jsonable(sol.details).get("warning"))
        assert sol.load >= best * (1 - RTOL)  # a feasible load is an upper bound
        assert sol.lower_bound <= best * (1 + RTOL)
        if rel > RTOL or z not in minimisers:
            disagreements[spec.name] = (
                f"{spec.name} {spec.mesh} zone {spec.obstacle.zone}: active-set "
                f"{sol.load:.12g} Z={z}, exhaustive {best:.12g} Z={minimisers}"
            )
            full = solve_active_set(problem, bound_budget=2**problem.num_constrained)
            assert abs(full.load - best) <= RTOL * best
            assert tuple(int(k) for k in full.active) in minimisers
            assert full.global_optimum_proven
        problem.destroy()
    assert set(disagreements) <= KNOWN_LOCAL_MINIMA, "\n".join(disagreements.values())
    # Large zones are represented; ties (several minimisers) are the exception.
    assert sum(n >= 8 for _, n, _, _ in report) >= 5, report
    assert sum(m == 1 for *_, m in report) >= 40, report


@pytest.mark.slow
@serial
def test_lattice_bound_is_valid_and_closes(family):
    """Lower bound <= exhaustive minimum; proven optimum equals it (first 8 problems)."""
    proven = 0
    for spec in family[:8]:
        problem = build_problem(spec, MPI.COMM_SELF)
        sol = solve_active_set(problem, bound_budget=512)
        best, _, _ = exhaustive_minimum(problem)
        assert sol.lower_bound <= best * (1 + 1e-10)
        assert sol.lower_bound >= sol.details.free_load * (1 - 1e-10)
        assert abs(sol.load - best) <= RTOL * best
        if sol.details.bound_search_complete:
            assert sol.global_optimum_proven
        proven += sol.global_optimum_proven
        problem.destroy()
    assert proven >= 4


# -- the paper's zones --------------------------------------------------------------------
@pytest.fixture(scope="module")
def paper_loads() -> dict[str, float]:
    """Active-set loads of the paper's zones at 20x10 (certified and proven on each)."""
    loads = {}
    for case in ("c1", "c2", "c3"):
        problem = build_problem(paper_case(case, 20, 10))
        free = problem.solve_free().load
        sol = solve_active_set(problem)
        cert = certify(problem, sol)
        assert cert.kkt and cert.global_optimum_proven, (case, cert)
        assert free <= sol.lower_bound <= sol.load
        loads[case] = sol.load
        loads["free"] = free
        problem.destroy()
    return loads


def test_paper_zones_certified_and_ordered(paper_loads):
    """Zones c2 within c1 within c3: interlacing of the cones orders the loads."""
    lam = paper_loads
    assert lam["free"] < lam["c2"] <= lam["c1"] * (1 + RTOL)
    assert lam["c1"] <= lam["c3"] * (1 + RTOL)
    # The obstacle raises the paper's plate load noticeably (paper, section 6: about
    # 13 % here, since the m = 2 mode must change).
    assert lam["c1"] / lam["free"] > 1.05


def test_multilevel_equals_single_level():
    """Seeding on 20x10 and polishing gives the single-level multi-seed answer (40x20)."""
    for case in ("c1", "c2"):
        problem = build_problem(paper_case(case, 40, 20))
        problem.solve_free()
        multi = solve_active_set(problem, bound_budget=0)
        single = solve_active_set(problem, multilevel=False, bound_budget=0)
        assert multi.details.levels, "expected a coarse level"
        assert abs(multi.load - single.load) <= RTOL * single.load
        assert np.array_equal(multi.active, single.active)
        assert multi.details.fine_eigensolves < single.details.fine_eigensolves
        problem.destroy()


def test_fine_polish_solves_below_the_extrapolated_load():
    """The fine polish's eigen solves shift below the extrapolated load, and answer.

    c3 at 80x40 (levels 20x10 and 40x20): every 80x40 solve is a shifted one (none
    falls back to target 0), and the load is the smallest eigenvalue of the returned
    set's pencil, solved again at target 0 without an estimate.
    """
    problem = build_problem(paper_case("c3", 80, 40))
    problem.solve_free()
    solver = problem.eigensolver
    shifted, again = solver.shifted_solves, solver.unshifted_again
    solution = solve_active_set(problem, bound_budget=0)
    assert solution.details.fine_eigensolves >= 1
    assert solver.shifted_solves - shifted == solution.details.fine_eigensolves
    assert solver.unshifted_again == again
    cold = problem.evaluate(solution.active)
    problem.destroy()
    assert abs(solution.load - cold.load) <= RTOL * cold.load


def _sparse_kkt(problem: UnilateralProblem, active) -> tuple[bool, float]:
    """KKT conditions of the contact set ``active`` and its load, by scipy alone.

    The largest eigenvalue theta of B x = theta A x on the DOFs left after removing the
    edge DOFs and the w-DOFs of Z (ARPACK Lanczos, ``scipy.sparse.linalg.eigsh``), load
    1/theta, checked by :func:`support.exhaustive.satisfies_kkt`.
    """

    def csr(mat):
        indptr, indices, data = mat.getValuesCSR()
        return sp.csr_matrix((data, indices, indptr), shape=mat.getSize())

    A, B = csr(problem.model.A), csr(problem.model.B)
    rows = problem.contact.global_rows()
    removed = np.union1d(problem.model.bc_dofs, rows[np.asarray(active, dtype=int)])
    keep = np.setdiff1d(np.arange(A.shape[0]), removed)
    Ak, Bk = A[keep][:, keep].tocsc(), B[keep][:, keep]
    theta, x = scipy.sparse.linalg.eigsh(Bk, k=1, M=Ak, which="LA", tol=1e-12)
    load = 1.0 / theta[0]
    u = np.zeros(A.shape[0])
    u[keep] = x[:, 0]
    return satisfies_kkt(problem, A, B, u, load, active), load


@serial
def test_threshold_iteration_ends_at_kkt_points(active_specs):
    """From the free mode's violating sets, with thresholds: dense-checked KKT points."""
    for spec in active_specs[:10]:
        problem = build_problem(spec, MPI.COMM_SELF)
        free = problem.solve_free().function.x.petsc_vec
        values = problem.contact.values(free)
        best, _, _ = exhaustive_minimum(problem)
        for start in (np.flatnonzero(values > 0), np.flatnonzero(values < 0)):
            run = iterate(problem, "t", start, free, 100, thresholds=THRESHOLDS)
            if run.status != "kkt":  # a cycle, as without thresholds (measured)
                continue
            ok, load = _sparse_kkt(problem, run.final.active)
            assert ok and abs(run.final.load - load) <= RTOL * load, spec.name
            assert run.final.load >= best * (1 - RTOL), spec.name
        problem.destroy()


@serial
def test_thresholds_polish_a_thin_plate_within_budget():
    """Thin SSSS plate 0.3 x 0.1 m, t = 1e-4, whole-plate obstacle, 60 x 20.

    The best KKT contact set of the 30 x 10 level, prolonged: iterating at tau = 1e-8 at
    once takes 33 iterates (measured), more than the polish budget; with the thresholds it
    ends at a KKT point (checked by scipy) within the budget.
    """
    spec = plate_case(
        "thin",
        length=0.3,
        width=0.1,
        thickness=1e-4,
        supports="simply_supported",
        load="uniaxial",
        nx=60,
        ny=20,
        zone=ObstacleSpec(zone="all"),
    )
    with (
        build_problem(spec, MPI.COMM_SELF) as fine,
        build_problem(spec.with_mesh(30, 10), MPI.COMM_SELF) as coarse,
    ):
        best = distinct_kkt(multi_seed(coarse, 100))[0]
        start = prolong(coarse, fine, best.active)
        plain = iterate(fine, "plain", start, None, POLISH_ITERATIONS)
        run = iterate(fine, "thresholds", start, None, POLISH_ITERATIONS, thresholds=THRESHOLDS)
        assert plain.status is RunStatus.MAX_ITERATIONS
        assert run.status == "kkt"
        ok, load = _sparse_kkt(fine, run.final.active)
        assert ok and abs(run.final.load - load) <= RTOL * load


def test_prolongation_includes_midway_nodes():
    """Coarse contact at x = 0.5, 1 (h = 0.5, 4 x 2 cells) marks fine 0.5, 0.75, 1 only."""
    coarse = np.array([[0.5, 0.5], [1.0, 0.5], [1.5, 0.5]])
    fine = np.array([[x, 0.5] for x in (0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75)])
    z = prolong_contact_set(np.array([0, 1]), coarse, fine, (0.0, 0.0), (0.5, 0.5), (4, 2))
    # 0.25 lies between the edge node x = 0 (abstains) and contact node 0.5: in contact.
    assert z.tolist() == [0, 1, 2, 3]


#: The plate of STEEP_TOML shortened to 100 x 100 mm on 8 x 20 cells (the compressed
#: strip of b/10 two cells across), the obstacle over part of that strip (6 nodes; one on
#: 4 x 10 cells).
STEEP_STRIP_TOML = (
    STEEP_TOML.replace("[0.3, 0.1]", "[0.1, 0.1]").replace("nx = 30", "nx = 8")
    + "[obstacle]\nzone = [[0.03, 0.07], [0.0, 0.01]]\n"
).replace("ny = 10", "ny = 20")


@serial
def test_a_coarse_level_with_no_load_is_skipped(tmp_path):
    """A level whose strip is one cell (no positive load there) seeds nothing; the fine does.

    The 4 x 10 level (``coarse_min_cells = 4``) has no positive load; the seeds run on
    the 8 x 20 mesh and end at the exhaustive minimum over the 2^6 contact sets by LAPACK
    (:func:`support.exhaustive.exhaustive_minimum`), the answer of the active set without
    levels. Before, the level's free solve refused the plate ("no positive buckling load
    on this mesh", exit 2), whose fine mesh has one.
    """
    from unibuckle_fenicsx.spec.files import load_toml

    path = tmp_path / "strip.toml"
    path.write_text(STEEP_STRIP_TOML)
    with build_problem(load_toml(path), MPI.COMM_SELF) as problem:
        assert problem.num_constrained == 6
        expected, minimisers, _ = exhaustive_minimum(problem)
        solution = solve_active_set(problem, coarse_min_cells=4, bound_budget=0)
        single = solve_active_set(problem, multilevel=False, bound_budget=0)
    (level,) = solution.details.levels
    assert level.mesh == [4, 10] and level.runs == []
    assert level.skipped == "no positive buckling load on this mesh"
    assert solution.details.seeded_on == [8, 20]
    assert solution.load == pytest.approx(expected, rel=RTOL)
    assert tuple(int(k) for k in solution.active) in minimisers
    assert solution.load == pytest.approx(single.load, rel=1e-12)


def test_bad_options_raise_before_work():
    problem = build_problem(paper_case("c2", 4, 2))
    with pytest.raises(ValueError, match="max_iterations"):
        solve_active_set(problem, max_iterations=0)
    with pytest.raises(ValueError, match="bound_budget"):
        solve_active_set(problem, bound_budget=-1)
    with pytest.raises(ValueError, match="refine_margin"):
        solve_active_set(problem, refine_margin=math.nan)
    assert problem.eigensolver.solves == 0
    problem.destroy()
    free = build_problem(paper_case("free", 4, 2))
    with pytest.raises(ValueError, match="obstacle"):
        solve_active_set(free)
    free.destroy()


# -- MPI ----------------------------------------------------------------------------------
@serial
@pytest.mark.mpi
@pytest.mark.parametrize(("case", "nx", "ny"), [("c1", 40, 20), ("c3", 80, 40)])
def test_distributed_equals_serial(case, nx, ny):
    """Mpiexec -n 2 on a distributed mesh (multilevel) gives the serial answer.

    At 80x40 (two coarser levels) the fine polish's eigen solves are shifted below the
    extrapolated load; at 40x20 (one coarser level) they are solved at 0.
    """
    out = run_mpi(MPI_SCRIPTS / "active_parallel.py", 2, case, str(nx), str(ny))
    par = json.loads(out.strip().splitlines()[-1])
    problem = build_problem(paper_case(case, nx, ny), MPI.COMM_SELF)
    sol = solve_active_set(problem)
    assert abs(par["load"] - sol.load) <= RTOL * sol.load
    assert np.allclose(par["coordinates"], problem.contact.coordinates[sol.active], atol=1e-12)
    problem.destroy()


# -- convergence ------------------------------------------------------------------------
#: The mesh-convergence table of the docs (demos/paper.md; its limits in the README's
#: results): unilateral loads in MPa on 20x10, 40x20, 80x40, 160x80, and the
#: Richardson-extrapolated limits. The tests below recompute them, check the physics they
#: claim (monotone decrease, rate h^2) and that the documentation prints what the code
#: computes, to its printed digits.
README_LOADS_MPA = {
    "c1": (14.568475, 14.376150, 14.328634, 14.316799),
    "c2": (14.566406, 14.373741, 14.326155, 14.314276),
    "c3": (14.569293, 14.376257, 14.329006, 14.317195),
}
README_RICHARDSON_MPA = {"c1": 14.3129, "c2": 14.3103, "c3": 14.3133}
MESHES = ((20, 10), (40, 20), (80, 40), (160, 80))


def _unilateral_loads(case: str, meshes) -> np.ndarray:
    loads = []
    for nx, ny in meshes:
        with build_problem(paper_case(case, nx, ny)) as problem:
            sol = solve_active_set(problem, bound_budget=0)
            assert sol.candidate.kkt
            loads.append(sol.load)
    return np.array(loads)


def _rates(loads: np.ndarray) -> np.ndarray:
    """Observed orders from successive differences (mesh halved each time)."""
    diffs = -np.diff(loads)
    assert np.all(diffs > 0), loads  # the MITC4 loads decrease under refinement
    return np.log2(diffs[:-1] / diffs[1:])


def test_unilateral_load_converges_small():
    """c1 on 20x10, 40x20, 80x40: monotone, observed rate near 2, the README's loads."""
    loads = _unilateral_loads("c1", MESHES[:3])
    rate = _rates(loads)[0]
    assert 1.8 < rate < 2.2, rate
    np.testing.assert_allclose(loads / 1e6, README_LOADS_MPA["c1"][:3], rtol=0, atol=5e-7)


@pytest.mark.convergence
@pytest.mark.parametrize("case", ["c1", "c2", "c3"])
def test_unilateral_load_converges(case):
    """20x10 .. 160x80: monotone, rates in (1.9, 2.1), the README's table and limit."""
    loads = _unilateral_loads(case, MESHES)
    rates = _rates(loads)
    diffs = -np.diff(loads)
    richardson = loads[-1] - diffs[-1] / (2 ** rates[-1] - 1)
    assert np.all((rates > 1.9) & (rates < 2.1)), rates
    np.testing.assert_allclose(loads / 1e6, README_LOADS_MPA[case], rtol=0, atol=5e-7)
    assert abs(richardson / 1e6 - README_RICHARDSON_MPA[case]) <= 5e-5, richardson


def test_a_check_that_stalls_runs_no_fallback_and_warns_of_nothing(monkeypatch, caplog):
    """``check=True``: where the seeds stall, the answer checked stands.

    The seeds are made to count as stalled (``reached_kkt`` false), so the plain run takes
    its fallbacks (the penalty continuation, with a warning); a check takes none, logs
    nothing as a warning, and its route is the active set's alone. The contract of
    ``solve_active_set``'s ``check`` (a section's seeds checking the interior point: a
    filled tube's check ran a 1 000-solve continuation and warned of it).
    """
    import logging

    import unibuckle_fenicsx.algorithms.active_set as active_set

    continuations: list[int] = []
    continuation = active_set.penalty_continuation

    def recorded(*args, **kwargs):
        run, solves = continuation(*args, **kwargs)
        continuations.append(solves)
        return run, solves

    monkeypatch.setattr(active_set, "reached_kkt", lambda problem, runs: False)
    monkeypatch.setattr(active_set, "penalty_continuation", recorded)
    with build_problem(paper_case("c1", 8, 4)) as problem:
        plain = solve_active_set(problem, multilevel=False, bound_budget=0)
        assert continuations and "penalty-continuation" in plain.route
        continuations.clear()
        caplog.clear()
        with caplog.at_level(logging.INFO, logger=active_set.logger.name):
            checked = solve_active_set(problem, multilevel=False, bound_budget=0, check=True)
    assert not continuations and checked.route == ["active-set"]
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]
