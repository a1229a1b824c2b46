"""Solver options given in Python reach every eigen solver of the run, under its prefix.

``build_problem(eps_options=...)`` (what ``solve(..., eps_options=...)`` passes on)
holds the options in PETSc's options database until the problem is destroyed: the
coarse levels of the multilevel active set and the penalty stage build their own eigen
solvers, and must read them there. The option used, ``eps_ncv`` (the Krylov subspace
size), changes no result; it is read back from each solver with ``EPS.getDimensions``.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import pytest

import unibuckle_fenicsx.la.eigen as eigen
from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.algorithms.continuation import penalty_continuation
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec.cases import paper_case

NCV = 17  # SLEPc chooses max(2 nev, nev + 15) = 16 for one eigenpair: 17 is ours


@pytest.fixture
def built(monkeypatch):
    """Every GEPSolver built during the test: (prefix, rows of A, ncv)."""
    seen: list[tuple[str, int, int]] = []
    original = eigen.GEPSolver.__init__

    def spy(self, A, B, **kwargs):
        original(self, A, B, **kwargs)
        seen.append((self.prefix, A.getSize()[0], self.eps.getDimensions()[1]))

    monkeypatch.setattr(eigen.GEPSolver, "__init__", spy)
    return seen


def test_python_options_reach_coarse_levels_and_the_penalty_stage(built):
    spec = paper_case("c1").with_mesh(16, 16)
    with build_problem(spec, MPI.COMM_WORLD, eps_options={"eps_ncv": NCV}) as problem:
        fine_rows = problem.model.A.getSize()[0]
        solve_active_set(problem, max_iterations=20, coarse_min_cells=8, bound_budget=0)
        penalty_continuation(problem, None, penalties=(1.0,), max_iterations=3)
        assert PETSc.Options("unibuckle_").getInt("eps_ncv") == NCV
    coarse = [ncv for prefix, rows, ncv in built if prefix == "unibuckle_" and rows < fine_rows]
    penalty = [ncv for prefix, _, ncv in built if prefix == "unibuckle_penalty_"]
    assert coarse, "expected a coarse level (16 x 16 halves to 8 x 8)"
    assert penalty, "expected the penalty stage's eigen solver"
    assert set(coarse) == set(penalty) == {NCV}
    # Destroying the problem takes its options back: nothing leaks into the next run.
    assert not PETSc.Options("unibuckle_").hasName("eps_ncv")
    assert not PETSc.Options("unibuckle_penalty_").hasName("eps_ncv")


def test_the_command_line_wins_over_python_options(built):
    """An option already in the database (the command line's) is not overwritten."""
    opts = PETSc.Options("unibuckle_penalty_")
    opts.setValue("eps_ncv", NCV + 2)
    try:
        spec = paper_case("c1").with_mesh(8, 8)
        with build_problem(spec, MPI.COMM_WORLD, eps_options={"eps_ncv": NCV}) as problem:
            penalty_continuation(problem, None, penalties=(1.0,), max_iterations=3)
        penalty = {ncv for prefix, _, ncv in built if prefix == "unibuckle_penalty_"}
        assert penalty == {NCV + 2}
        assert opts.getInt("eps_ncv") == NCV + 2  # still the command line's
    finally:
        opts.delValue("eps_ncv")


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="runs its own process")
def test_an_iterative_shift_and_invert_is_refused_with_the_reason(tmp_path):
    """``-unibuckle_st_ksp_type gmres -unibuckle_st_pc_type jacobi``: exit 2, and why.

    Before, Krylov-Schur stopped in the inner solve ("KSPSolve has not converged") and
    SLEPc then failed in its clean-up: "PETSc/SLEPc failed: Operation done in wrong
    order; Need to call MatDenseRestoreSubMatrix() first", exit 3, without saying that
    the shift-and-invert needs a direct factorisation. The console script runs in its own
    process: the options go to PETSc's database at its start.
    """
    import os
    import subprocess
    import sys
    from pathlib import Path

    script = Path(sys.executable).parent / "unibuckle"
    options = ["-unibuckle_st_ksp_type", "gmres", "-unibuckle_st_pc_type", "jacobi"]
    proc = subprocess.run(
        [str(script), "solve", "--case", "c1", "--nx", "8", "--ny", "8", *options],
        capture_output=True, text=True, env={**os.environ, "OMP_NUM_THREADS": "1"},
        cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith(
        "unibuckle: error: -unibuckle_st_ksp_type gmres -unibuckle_st_pc_type jacobi: the "
        "eigen solver's shift-and-invert here needs a direct factorisation"
    ), proc.stderr
    assert "-unibuckle_st_ksp_type preonly" in proc.stderr and "wrong order" not in proc.stderr
    assert "Traceback" not in proc.stderr and proc.stdout == ""
