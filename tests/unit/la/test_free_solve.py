r"""The free plate's smallest eigenpair, shifted near an estimate and proven by an inertia.

:meth:`~unibuckle_fenicsx.la.eigen.GEPSolver.smallest` factorises :math:`A - \sigma B` once
at a shift just above an estimate of the lowest load, solves at that target, and reads
from the inertia that the pair is the smallest; a shift that lies above two eigenvalues,
or below the first, is lowered or checked. The reference values are LAPACK's
(``scipy.linalg.eigh`` on the dense pencil, ``tests/support/exhaustive.py``), never the solver's.
"""

from __future__ import annotations

import math

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

import unibuckle_fenicsx.la.eigen as eigen_module
import unibuckle_fenicsx.model.build as build_module
from support.exhaustive import dense
from support.families import stress_family, tension_somewhere
from support.paths import MPI_SCRIPTS
from support.processes import run_mpi
from unibuckle_fenicsx import paper_case
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.eigen import (
    EIGEN_OPTIONS,
    FREE_BELOW,
    EigenSolveError,
    GEPSolver,
)
from unibuckle_fenicsx.la.options import mumps_ordering
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.problem import Problem

#: SLEPc converges to a relative residual of eps_tol = 1e-10 and LAPACK to about 1e-13 on
#: these pencils, so 1e-8 leaves a margin of 100 (tests/support/exhaustive.py).
RTOL = 1e-8

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference: serial")


def lowest_loads(problem: Problem, count: int = 2) -> np.ndarray:
    """The pencil's ``count`` lowest positive loads, independently of PETSc and SLEPc.

    theta = 1/lambda of B x = theta A x: LAPACK (``scipy.linalg.eigh``) on the dense
    pencil up to 1000 DOFs, round-off out; ARPACK with SuperLU
    (``scipy.sparse.linalg.eigsh``, A in the inner product) above.
    """
    if problem.model.A.getSize()[0] <= 1000:
        A, B = dense(problem.model.A), dense(problem.model.B)
        theta = scipy.linalg.eigh(B, A, eigvals_only=True)[::-1]
        theta = theta[theta > 1e-10 * np.abs(theta).max()]
        return 1.0 / theta[:count]
    A, B = (
        scipy.sparse.csr_matrix(m.getValuesCSR()[::-1]) for m in (problem.model.A, problem.model.B)
    )
    theta = scipy.sparse.linalg.eigsh(
        B, k=count, M=A, which="LA", tol=1e-14, return_eigenvectors=False
    )
    return 1.0 / np.sort(theta)[::-1]


def smallest(problem: Problem, estimate: tuple[float, ...]):
    """The solver's smallest pair from ``estimate`` and its proof (a new solver, prefix test_)."""
    gep = GEPSolver(
        problem.model.A,
        problem.model.B,
        indefinite=problem.prestress.indefinite,
        prefix="test_smallest_",
        options=EIGEN_OPTIONS,
    )
    try:
        pair, proof = gep.smallest(estimate=estimate)
        return pair, proof, gep.solves
    finally:
        gep.destroy()


@pytest.fixture(scope="module")
def paper():
    """The paper's free plate at 20x10 and its two lowest loads (LAPACK)."""
    problem = build_problem(paper_case("free", 20, 10), MPI.COMM_SELF)
    yield problem, lowest_loads(problem)
    problem.destroy()


@serial
def test_one_factorisation_above_the_load_proves_it(paper):
    """A shift 1 % above an estimate of lambda_1, below lambda_2: one inertia proves it.

    The inertia counts one eigenvalue below the shift, and the pair found lies below it:
    it is that eigenvalue's, its load at or below lambda_1 (Rayleigh-Ritz) to RTOL.
    """
    problem, (first, second) = paper
    assert second > 1.15 * first  # m = 3 against m = 2 half-waves: a gap of 17 %
    pair, proof, _ = smallest(problem, (first, second))
    assert proof is not None and proof.below == 1 and len(proof.shifts) == 1
    assert proof.shift == pytest.approx(1.01 * first, rel=1e-12)
    assert pair.value == pytest.approx(first, rel=RTOL)
    assert pair.value <= proof.shift


@serial
def test_a_shift_below_the_load_is_checked_just_below_the_pair(paper):
    """An estimate 10 % low: the pair found above the shift is checked just below itself.

    Nothing lies below the shift, the pair found is the nearest above it, and a second
    inertia just below the pair (1e3 eigen tolerances) shows nothing there either.
    """
    problem, (first, _) = paper
    pair, proof, _ = smallest(problem, (0.9 * first,))
    assert proof is not None and proof.below == 0 and len(proof.shifts) == 2
    assert proof.shifts[0] == pytest.approx(0.909 * first, rel=1e-12)
    assert proof.shift == pytest.approx(pair.value * (1 - 1e3 * 1e-10), rel=1e-15)
    assert pair.value == pytest.approx(first, rel=RTOL)


@serial
def test_a_shift_above_two_eigenvalues_asks_for_two_pairs(paper):
    """The estimate at lambda_2: two eigenvalues below the shift, and both pairs found.

    The inertia counts two; Krylov-Schur asks for the two pairs nearest the shift, finds
    both below it (lambda_1 lies nearer than lambda_3 = 1.57 lambda_1), and the lower is
    the smallest: one factorisation.
    """
    problem, (first, second) = paper
    pair, proof, solves = smallest(problem, (second,))
    assert proof is not None and proof.below == 2 and len(proof.shifts) == 1
    assert solves == 1
    assert pair.value == pytest.approx(first, rel=RTOL)


@serial
def test_a_pair_found_above_the_shift_asks_for_more_pairs(paper):
    """One eigenvalue below the shift but lambda_2 nearer to it: three pairs are asked for.

    The estimate 1.14 lambda_1 (lambda_2 / lambda_1 = 1.17): the first shift, 1.01 times
    it, counts one eigenvalue below and lies eight times nearer lambda_2 than lambda_1;
    the one pair found lies above it, the three nearest include lambda_1's below it: the
    same factorisation proves it.
    """
    problem, (first, second) = paper
    assert 1.16 * first < second < 1.18 * first
    pair, proof, solves = smallest(problem, (1.14 * first,))
    assert proof is not None and proof.below == 1 and len(proof.shifts) == 1
    assert solves == 2
    assert pair.value == pytest.approx(first, rel=RTOL)


@serial
def test_two_below_the_shift_and_a_nearer_pair_above_ask_for_five(paper):
    """Two eigenvalues below the shift, lambda_3 nearer to it: five pairs are asked for.

    The estimate 1.5 lambda_1 (lambda_3 = 1.57 lambda_1, LAPACK on this plate): the shift
    1.515 lambda_1 counts lambda_1 and lambda_2 below it, the two nearest pairs are
    lambda_3's and lambda_2's, so the solve asks again for 2 k + 1 = 5 pairs with a
    larger Krylov subspace (the subspace's bound must grow with it, or SLEPc refuses the
    dimensions); the same factorisation then proves lambda_1.
    """
    problem, (first, second) = paper
    (third,) = lowest_loads(problem, 3)[2:]
    assert abs(third - 1.515 * first) < abs(1.515 * first - second)
    pair, proof, solves = smallest(problem, (1.5 * first,))
    assert proof is not None and proof.below == 2 and len(proof.shifts) == 1
    assert solves == 2
    assert pair.value == pytest.approx(first, rel=RTOL)


@serial
def test_shifts_above_the_load_are_lowered_and_refactorised(paper, monkeypatch):
    """Shifts above lambda_1 are lowered, the pencil factorised again, until one lies below.

    No pairs are asked for below a shift here (FREE_MAX_BELOW = 0). The estimate at
    lambda_2 = 1.17 lambda_1: the shifts 1.01, 0.99 and 0.96 times it count two, one
    and one eigenvalues below them, 0.84 times it none; the pair found above that shift
    is checked just below itself (a fifth factorisation).
    """
    problem, (first, second) = paper
    monkeypatch.setattr(eigen_module, "FREE_MAX_BELOW", 0)
    pair, proof, solves = smallest(problem, (second,))
    assert proof is not None and proof.below == 0
    expected = [f * second for f in (1.01, *FREE_BELOW)]
    np.testing.assert_allclose(proof.shifts[:4], expected, rtol=1e-12)
    assert len(proof.shifts) == 5 and solves == 1
    assert pair.value == pytest.approx(first, rel=RTOL)


@serial
def test_no_shift_that_proves_it_leaves_the_solve_at_target_zero(paper):
    """An estimate ten times too high: the pair comes from the solve at target 0.

    Every shift lies above more than FREE_MAX_BELOW eigenvalues; the pair is unproven
    (the caller checks it).
    """
    problem, (first, _) = paper
    pair, proof, _ = smallest(problem, (10 * first,))
    assert proof is None
    assert pair.value == pytest.approx(first, rel=RTOL)


@serial
def test_the_swapped_pencil_of_a_plate_in_tension_somewhere():
    """An indefinite B: the inertia of B - A/sigma counts the loads below sigma.

    The left edge clamped in plane: Poisson's effect puts part of the plate in tension.
    """
    with build_problem(tension_somewhere(20, 10), MPI.COMM_SELF) as problem:
        assert problem.prestress.indefinite
        first, second = lowest_loads(problem)
        for estimate, below in (((first, second), 1), ((0.9 * first,), 0)):
            pair, proof, _ = smallest(problem, estimate)
            assert proof is not None and proof.below == below
            assert pair.value == pytest.approx(first, rel=RTOL)


@serial
def test_random_plates_and_estimates_give_the_lowest_load():
    """Random plates and estimates of the stress family: LAPACK's lowest load, proven.

    Stiff, thin (t/b down to 1e-4), sheared (indefinite B) and tiny pencils, with
    estimates drawn 20 % around the two lowest loads: the load is LAPACK's lowest, and a
    proof says how it was proven.

    On these coarse meshes the loads may lie far apart or close together: every branch of
    the shifts is taken somewhere (one below, none below, lowered).
    """
    rng = np.random.default_rng(20261130)
    branches = set()
    for spec, _, _ in stress_family(24):
        try:
            problem = build_problem(spec.without_obstacles(), MPI.COMM_SELF)
        except InputError:  # b(w, w) vanishes on this mesh: no load to find
            continue
        with problem:
            loads = lowest_loads(problem)
            if not math.isfinite(loads[0]) or loads.size < 2:
                continue
            scale = rng.uniform(0.8, 1.2, 2)
            estimate = tuple(sorted(loads * scale))
            pair, proof, _ = smallest(problem, estimate)
            # Conditioning: thin plates fix the load to about 1e-9 (load_resolution).
            assert pair.value == pytest.approx(loads[0], rel=RTOL), spec.name
            if proof is not None:
                branches.add((min(proof.below, 2), len(proof.shifts) > 1 + (proof.below == 0)))
                if proof.below:
                    assert pair.value < proof.shift
                else:
                    assert proof.shift <= pair.value
    assert {(1, False), (0, False)} <= branches, branches


@serial
def test_the_free_run_estimates_on_a_coarser_mesh(monkeypatch):
    """The free run estimates its load on the mesh four times coarser and proves it.

    The threshold is lowered to this small mesh. The load is ARPACK's, proven by the
    solve's own inertia, and verify_free factorises nothing more.
    """
    monkeypatch.setattr(build_module, "FREE_ESTIMATE_DOFS", 0)
    spec = paper_case("free", 48, 24)
    with solve(spec, MPI.COMM_SELF) as analysis:
        problem = analysis.problem
        proof = problem.free_proof
        assert proof is not None and len(proof.shifts) == 1
        first = lowest_loads(problem, 1)[0]
        assert analysis.result.free_load_Pa == pytest.approx(first, rel=RTOL)

        def factorised_again(shift):
            raise AssertionError(f"verify_free factorised again at {shift}")

        monkeypatch.setattr(problem.eigensolver, "count_below", factorised_again)
        problem.verify_free()


@serial
def test_python_eps_options_reach_the_free_solve(monkeypatch):
    """eps_options (README, "Solver options") reach the shifted free solve's EPS too."""
    monkeypatch.setattr(build_module, "FREE_ESTIMATE_DOFS", 0)
    with build_problem(paper_case("free", 48, 24), eps_options={"eps_ncv": 5}) as problem:
        problem.solve_free()
        assert problem.free_proof is not None
        assert problem.eigensolver.shifted.free_eps().getDimensions()[1] == 5


@serial
def test_command_line_eps_options_reach_the_free_solve(monkeypatch):
    """Command-line -unibuckle_eps_* options (docs: guide/cli) reach the shifted free solve.

    Its subspace; and an unreachable tolerance in one iteration fails as at target 0 (exit
    3 from the CLI).
    """
    monkeypatch.setattr(build_module, "FREE_ESTIMATE_DOFS", 0)
    opts = PETSc.Options()
    opts["unibuckle_eps_ncv"] = 6
    try:
        with build_problem(paper_case("free", 48, 24)) as problem:
            problem.solve_free()
            assert problem.free_proof is not None
            assert problem.eigensolver.shifted.free_eps().getDimensions()[1] == 6
        opts["unibuckle_eps_max_it"] = 1
        opts["unibuckle_eps_tol"] = 1e-300
        with build_problem(paper_case("free", 48, 24)) as problem:
            with pytest.raises(EigenSolveError, match="converged no eigenpair"):
                problem.solve_free()
    finally:
        for key in ("ncv", "max_it", "tol"):
            opts.delValue(f"unibuckle_eps_{key}")


@serial
def test_loose_options_on_the_shifted_solve_never_overestimate(monkeypatch):
    """Loose options on the shifted solve: the free load never lies above lambda_1.

    A tolerance of 0.1 with three basis vectors (which at target 0 stopped on a pair
    18 % high, tests/unit/model/test_problem.py): shifted above the load, a converged Ritz
    value below the shift lies at or below lambda_1 (Rayleigh-Ritz), so the free load
    stays a lower bound of the critical load.
    """
    monkeypatch.setattr(build_module, "FREE_ESTIMATE_DOFS", 0)
    loose = {"eps_tol": 0.1, "eps_ncv": 3}
    with build_problem(paper_case("free", 48, 24), eps_options=loose) as problem:
        load = problem.solve_free().load
        proof = problem.free_proof
        first = lowest_loads(problem, 1)[0]
    assert proof is not None and proof.below == 1
    assert load <= first * (1 + 1e-12)


@serial
def test_the_factorisations_take_the_package_ordering_and_an_option_wins():
    """The factorisations take mumps_ordering's ordering; a command-line option wins.

    MUMPS's ordering (ICNTL(7), INFOG(7) reports the one used) for the shared LDL^T and
    the eigen solves' LU; -unibuckle_ldl_mat_mumps_icntl_7 wins.
    """
    with build_problem(paper_case("free", 20, 10), MPI.COMM_SELF) as problem:
        problem.solve_free()
        problem.verify_free()
        rows = problem.model.A.getSize()[0]
        ldl = problem.eigensolver.factorization.ksp.getPC().getFactorMatrix()
        assert ldl.getMumpsInfog(7) == mumps_ordering(rows)
        lu = problem.eigensolver.eps.getST().getKSP().getPC().getFactorMatrix()
        assert lu.getMumpsInfog(7) == mumps_ordering(rows)
    opts = PETSc.Options()
    opts["unibuckle_ldl_mat_mumps_icntl_7"] = 4  # PORD
    try:
        with build_problem(paper_case("free", 20, 10), MPI.COMM_SELF) as problem:
            problem.solve_free()
            problem.verify_free()
            ldl = problem.eigensolver.factorization.ksp.getPC().getFactorMatrix()
            assert ldl.getMumpsInfog(7) == 4
    finally:
        del opts["unibuckle_ldl_mat_mumps_icntl_7"]


@pytest.mark.mpi
@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="launches mpiexec itself")
def test_two_ranks_give_the_shifted_free_load(tmp_path):
    """On 2 ranks the shifted, proven free solve gives the serial load.

    To 1e-8, the MPI tests' tolerance: both converge to a relative residual of 1e-10.
    """
    script = MPI_SCRIPTS / "free_estimate.py"
    serial_line = run_mpi(script, 1).strip().splitlines()[-1]
    parallel_line = run_mpi(script, 2).strip().splitlines()[-1]
    load1, shifts1 = serial_line.split()
    load2, shifts2 = parallel_line.split()
    assert shifts1 == shifts2 == "1"
    assert float(load2) == pytest.approx(float(load1), rel=RTOL)


def pair_solver(problem: Problem) -> GEPSolver:
    """A new solver of ``problem``'s pencil (prefix test_pairs_; the caller destroys it)."""
    return GEPSolver(
        problem.model.A,
        problem.model.B,
        indefinite=problem.prestress.indefinite,
        prefix="test_pairs_",
        options=EIGEN_OPTIONS,
    )


@serial
def test_the_two_lowest_pairs_in_one_shifted_solve(paper):
    """``lowest_pairs`` below an estimate: LAPACK's two lowest loads, ascending.

    One eigen solve at the shift 0.1 % below the estimate; a shift above the lowest
    load (its inertia counts one eigenvalue below) returns nothing: the pairs returned
    are proven the lowest. The plate in tension somewhere (indefinite B) takes the
    swapped pencil.
    """
    none = np.empty(0, np.int64)
    problem, (first, second) = paper
    with build_problem(tension_somewhere(20, 10), MPI.COMM_SELF) as swapped:
        for plate, loads in ((problem, (first, second)), (swapped, lowest_loads(swapped))):
            gep = pair_solver(plate)
            try:
                pairs = gep.lowest_pairs(none, loads[0], 2)
                assert [pair.value for pair, _ in pairs] == pytest.approx(loads, rel=RTOL)
                assert gep.solves == 1
                for _, vec in pairs:
                    vec.destroy()
                assert gep.lowest_pairs(none, 1.01 * loads[0], 2) == []
            finally:
                gep.destroy()


@serial
def test_a_mode_projected_on_two_pairs_takes_their_mixed_load(paper):
    """``project_on_pairs``: u = 0.6 v1 + 0.8 v2 comes back, its load 0.36 l1 + 0.64 l2.

    v1, v2 are B-orthonormal eigenvectors (SLEPc normalises them so), so the quotient
    of the combination is the weighted mean of their loads (LAPACK's) with the squared
    weights; the A-orthogonal projection of a vector already in the span is itself.
    """
    from unibuckle_fenicsx.algorithms.interior_point.links import project_on_pairs

    problem, (first, second) = paper
    gep = pair_solver(problem)
    pairs = gep.lowest_pairs(np.empty(0, np.int64), first, 2)
    try:
        v1, v2 = (vec for _, vec in pairs)
        u = v1.duplicate()
        u.set(0.0)
        u.axpy(0.6, v1)
        u.axpy(0.8, v2)
        projected = project_on_pairs(problem, u, [v1, v2])
        assert projected is not None
        mode, load = projected
        assert load == pytest.approx(0.36 * first + 0.64 * second, rel=RTOL)
        diff = mode.x.petsc_vec.copy()
        diff.axpy(-1.0, u)
        assert diff.norm() <= 1e-8 * u.norm()
    finally:
        for _, vec in pairs:
            vec.destroy()
        gep.destroy()
