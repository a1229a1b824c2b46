"""The penalty method: monotone in rho, tends to the exact critical load from below."""

from __future__ import annotations

import json

from mpi4py import MPI

import numpy as np
import pytest

from unibuckle_fenicsx import paper_case
from unibuckle_fenicsx.algorithms.penalty import PenaltySolver, solve_penalty
from unibuckle_fenicsx.certificate.certify import certify
from unibuckle_fenicsx.model.build import build_problem

#: Eigenvalues are solved to a relative residual of 1e-10 (SolverSpec.eps_tol), so loads
#: compare to 1e-9 relative: an order of magnitude of margin over the solver's error.
LOAD_RTOL = 1e-9


@pytest.fixture(scope="module")
def c1_small():
    """The paper's plate, zone c1, 8 x 4 quads (i = 9), with its exact critical load.

    The reference is computed independently of the penalty code: the minimum of
    lambda(Z) over the 2^9 = 512 contact sets Z whose reduced first mode is feasible
    (problem.evaluate), which is the critical load (paper, Lemma 5.1).
    """
    problem = build_problem(paper_case("c1", 8, 4), MPI.COMM_WORLD)
    free = problem.solve_free().load
    i = problem.num_constrained
    assert i == 9
    best = np.inf
    for mask in range(2**i):
        cand = problem.evaluate(np.flatnonzero([(mask >> k) & 1 for k in range(i)]))
        if cand.feasible:
            best = min(best, cand.load)
    yield problem, free, best
    problem.destroy()


def test_penalty_is_monotone_and_tends_to_the_exact_load_from_below(c1_small):
    """lambda(rho) non-decreasing, <= lambda_c, gap and penetration shrink like 1/rho.

    R_rho grows pointwise with rho and equals a/b on the cone, so lambda(rho) is
    non-decreasing and <= lambda_c (to LOAD_RTOL). The penalised mode is the exact one
    plus O(1/rho), so gap and penetration fall by about 100 per factor 100 of rho once
    the contact set is found (rho >= 1 here); we ask for a factor 30. At rho = 1e6 the
    gap is about 3e-10 (measured; 3e-4/rho), asserted below 1e-8.
    """
    problem, free, exact = c1_small
    rhos = [1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6]
    loads, gaps, pens = [], [], []
    for rho in rhos:
        sol = solve_penalty(problem, rho)
        assert not sol.global_optimum_proven
        assert sol.lower_bound == pytest.approx(free, rel=LOAD_RTOL)
        assert sol.details.penalty_status == "converged"
        loads.append(sol.load)
        gaps.append((exact - sol.load) / exact)
        pens.append(sol.details.penalty_max_penetration)
    loads_a = np.array(loads)
    assert np.all(np.diff(loads_a) >= -LOAD_RTOL * exact), loads
    assert np.all(loads_a <= exact * (1 + LOAD_RTOL)), (loads, exact)
    assert loads_a[0] >= free * (1 - LOAD_RTOL)
    for k in range(2, len(rhos) - 1):
        assert gaps[k + 1] < gaps[k] / 30, gaps
        assert pens[k + 1] < pens[k] / 30, pens
    assert 0.0 <= gaps[-1] < 1e-8, gaps
    assert pens[-1] < 1e-8


def test_penalty_limit_set_is_the_exact_contact_set(c1_small):
    """At a large penalty the penetrating set is a contact set whose mode is certified.

    Removing the penetrating nodes exactly (problem.evaluate) gives a feasible mode whose
    load is the exhaustive minimum of the fixture, within LOAD_RTOL.
    """
    problem, _, exact = c1_small
    sol = solve_penalty(problem, 1e8)
    cand = problem.evaluate(sol.active)
    assert cand.feasible
    assert cand.load == pytest.approx(exact, rel=LOAD_RTOL)
    assert certify(problem, cand).kkt


def test_certificate_rejects_a_penetrating_penalty_mode(c1_small):
    """At rho = 1 the mode penetrates by ~2.5e-3 on its spring set: not feasible (tau 1e-8)."""
    problem, _, _ = c1_small
    sol = solve_penalty(problem, 1.0)
    assert sol.details.penalty_max_penetration > 1e-4
    assert not certify(problem, sol).feasible


def test_condition_number_matches_dense_eigenvalues():
    """SLEPc's extreme eigenvalues of A_pen (free DOFs) equal numpy's dense ones.

    Independent: the dense matrix of A + rho_abs sum_S e_k e_k^T, edge rows removed,
    numpy.linalg.eigvalsh. Both to 1e-6 relative (SLEPc tol 1e-8 on the extreme pairs).
    """
    if MPI.COMM_WORLD.size > 1:
        pytest.skip("dense comparison in serial only")
    problem = build_problem(paper_case("c2", 8, 4), MPI.COMM_SELF)
    pen = PenaltySolver(problem)
    try:
        sol = pen.solve(1e4, condition=True)
        n = problem.model.num_dofs
        dense = pen.A_pen.getValues(range(n), range(n))
        keep = np.setdiff1d(np.arange(n), problem.model.bc_dofs)
        eig = np.linalg.eigvalsh(dense[np.ix_(keep, keep)])
        details = sol.details
        assert details.penalty_eig_min_A_pen == pytest.approx(eig[0], rel=1e-6)
        assert details.penalty_eig_max_A_pen == pytest.approx(eig[-1], rel=1e-6)
        # The springs sit on the diagonal: the largest eigenvalue is about rho_abs.
        assert eig[-1] >= details.penalty_rho_abs
    finally:
        pen.destroy()
        problem.destroy()


def test_mirror_tie_is_broken_deterministically():
    """Symmetric plate and zone: the mode does not flip to its mirror image as rho moves.

    The free mode is antisymmetric about x = 0, so both orientations penetrate c1 alike
    and the two unilateral modes are mirror images of equal load. With the tie rule the
    penetrating set is the same for nearby penalties (12 x 6 mesh, where leaving the tie
    to rounding flips the mode at a few, run-dependent rho: demos/study_penalty.py).
    """
    problem = build_problem(paper_case("c1", 12, 6), MPI.COMM_WORLD)
    try:
        sets = {tuple(solve_penalty(problem, r).active) for r in (1e6, 1.01e6, 1e8)}
        assert len(sets) == 1, sets
        (z,) = sets
        x = problem.contact.coordinates[list(z), 0]
        assert np.all(x < 0), x  # the lexicographically smaller mirror twin
    finally:
        problem.destroy()


@pytest.mark.parametrize("rho", [0.0, -1.0, float("nan"), float("inf")])
def test_bad_rho_raises(c1_small, rho):
    problem, _, _ = c1_small
    with pytest.raises(ValueError, match="rho"):
        solve_penalty(problem, rho)


def test_bad_options_raise(c1_small):
    problem, _, _ = c1_small
    with pytest.raises(ValueError, match="max_iterations"):
        solve_penalty(problem, 1.0, max_iterations=0)
    with pytest.raises(ValueError, match="initial_active"):
        solve_penalty(problem, 1.0, initial_active=np.array([99]))
    with pytest.raises(ValueError, match="tie_rtol"):
        solve_penalty(problem, 1.0, tie_rtol=1.0)


def test_penalty_needs_an_obstacle():
    problem = build_problem(paper_case("free", 4, 2), MPI.COMM_WORLD)
    try:
        with pytest.raises(ValueError, match="obstacle"):
            solve_penalty(problem, 1.0)
    finally:
        problem.destroy()


def test_cli_penalty_end_to_end(tmp_path, capsys, c1_small):
    """`unibuckle solve --method penalty --penalty RHO`: a valid bracket, no upper bound.

    The penalised mode penetrates, so its load is not an upper bound: the JSON gives none,
    and the lower bound (the free load) lies below the exhaustive minimum of the fixture.
    The load at rho = 1e6 is within 1e-8 below that minimum (1/rho law, above).
    """
    from unibuckle_fenicsx.cli import main

    _, _, exact = c1_small
    out = tmp_path / "p.json"
    args = ["solve", "--case", "c1", "--nx", "8", "--ny", "4", "--method", "penalty"]
    assert main([*args, "--penalty", "1e6", "--json", str(out)]) == 0
    if MPI.COMM_WORLD.rank == 0:
        data = json.loads(out.read_text())
        assert data["method"] == "penalty"
        assert data["details"]["penalty_status"] == "converged"
        assert data["certificate"]["global_optimum_proven"] is False
        assert data["upper_bound_Pa"] is None
        assert data["lower_bound_Pa"] <= exact
        assert 0.0 <= (exact - data["critical_load_Pa"]) / exact < 1e-8
    assert main([*args, "--penalty", "-1"]) == 2
    if MPI.COMM_WORLD.rank == 0:  # errors are printed on rank 0
        assert "penalty" in capsys.readouterr().err


def _no_load_in_the_cone():
    """A plate whose cone holds no mode with a positive load, though the free plate has one.

    0.2 x 0.1 m, t = 0.1 mm, 7 x 3 cells; the long edge y = 0 clamped, y = 0.1 free, the
    short edges simply supported under sigma_x = -1 at y = 0 to +2 at y = 0.1 (psi = -2);
    a face below over the whole plate, so every free deflection must be >= 0. The free
    plate buckles at 19.77 MPa with a mode of both signs; every one-signed mode has
    b(w, w) <= 0 (the dense minimum over all 2^18 contact sets, :func:`support.exhaustive.
    exhaustive_minimum`, is inf: checked by the slow test below).
    """
    from unibuckle_fenicsx import problem_from_dict

    edge = {"support": "simply_supported", "normal_stress": [-1.0, 2.0]}
    return problem_from_dict(
        {
            "name": "no_load_in_the_cone",
            "plate": {"corners": [[0.0, 0.0], [0.2, 0.1]], "thickness": 1e-4},
            "material": {"E": 1e9, "nu": 0.3},
            "edges": {
                "left": edge,
                "right": edge,
                "bottom": {"support": "clamped"},
                "top": {"support": "free"},
            },
            "mesh": {"nx": 7, "ny": 3},
            "obstacle": {"zone": "all", "side": "below"},
        }
    )


def test_a_cone_without_a_positive_load_is_reported_not_a_division_by_zero():
    """The penalty fallback met a mode with no deflection (w = 0) and divided by max|w| = 0.

    Before: ``ZeroDivisionError`` from auto, the active set and the interior point (each
    falls back to the penalty continuation here); now the documented
    NoAdmissibleModeError (exit status 3 on the command line), as the slow test's dense
    reference (no positive load over any contact set) requires.
    """
    from unibuckle_fenicsx.analysis import solve
    from unibuckle_fenicsx.errors import NoAdmissibleModeError

    with pytest.raises(NoAdmissibleModeError, match="no admissible mode with a finite load"):
        with solve(_no_load_in_the_cone(), MPI.COMM_WORLD):
            pass


@pytest.mark.slow
@pytest.mark.serial
def test_the_cone_without_a_positive_load_by_dense_enumeration():
    """Every one of the 2^18 contact sets, by LAPACK: no admissible mode with b(w, w) > 0."""
    from support.exhaustive import dense_free_load, exhaustive_minimum

    problem = build_problem(_no_load_in_the_cone(), MPI.COMM_SELF)
    try:
        assert problem.num_constrained == 18
        assert dense_free_load(problem) == pytest.approx(1.97737e7, rel=1e-5)
        assert exhaustive_minimum(problem)[0] == np.inf
    finally:
        problem.destroy()
