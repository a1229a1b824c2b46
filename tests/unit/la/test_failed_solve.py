r"""After Krylov-Schur converges no pair of the swapped pencil: the inertia decides.

A steep stress gradient on a coarse mesh leaves :math:`b(w, w) \le 0` on every free
deflection up to round-off: Krylov-Schur meets no relative tolerance there, and the
answer is "no positive buckling load" (exit 2), never "not converged" (exit 3). When a
load does exist, the inertias bracket it and a shifted solve finds it. The reference
values are LAPACK's (``scipy.linalg.eigh`` on the dense pencil), never the solver's.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc
from slepc4py import SLEPc

import numpy as np
import pytest
import scipy.linalg

from support.exhaustive import dense
from support.plates import STEEP_TOML
from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, main
from unibuckle_fenicsx.la.eigen import EIGEN_OPTIONS, GEPSolver, swapped_eigenpairs
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.outcome import petsc_failure
from unibuckle_fenicsx.spec.files import load_toml

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference: serial")


def psi1_file(tmp_path):
    """The plate of STEEP_TOML with psi = -1 on 12 x 4 cells, written to ``tmp_path``."""
    path = tmp_path / "psi1.toml"
    text = STEEP_TOML.replace("[-1.0, 9.0]", "[-1.0, 1.0]").replace("nx = 30", "nx = 12")
    path.write_text(text.replace("ny = 10", "ny = 4"))
    return path


def lapack_load(path):
    """LAPACK's smallest positive load of ``path``'s pencil (dense ``scipy.linalg.eigh``).

    1/theta, theta the largest eigenvalue of B x = theta A x.
    """
    with build_problem(load_toml(path), MPI.COMM_SELF) as problem:
        A, B = dense(problem.model.A), dense(problem.model.B)
    theta = scipy.linalg.eigh(B, A, eigvals_only=True)
    assert theta[-1] > 1e-6 * np.abs(theta).max()  # a real load
    return 1.0 / theta[-1]


@serial
def test_a_steep_gradient_with_no_load_on_the_mesh_exits_2(tmp_path, capsys):
    """The plate with psi = -9 on 30 x 10 cells: LAPACK's largest theta = 1/lambda is round-off.

    Before, Krylov-Schur and the absolute-tolerance check after it converged no pair
    (exit 3, "converged no eigenpair").
    """
    path = tmp_path / "steep.toml"
    path.write_text(STEEP_TOML)
    with build_problem(load_toml(path), MPI.COMM_SELF) as problem:
        A, B = dense(problem.model.A), dense(problem.model.B)
    theta = scipy.linalg.eigh(B, A, eigvals_only=True)
    assert theta[-1] <= 1e-10 * np.abs(theta).max()  # no positive load above round-off
    assert main(["solve", "--config", str(path), "-q"]) == EXIT_BAD_INPUT
    assert "no positive buckling load" in capsys.readouterr().err


@serial
def test_a_failed_solve_with_a_load_finds_it_by_inertia(tmp_path):
    """A plate with psi = -1 on 12 x 4 cells, Krylov-Schur cut to one iteration: no pair.

    The inertias bracket the smallest load and the shifted solve finds LAPACK's
    lowest positive 1/theta to 1e-8. Before, the failed solve raised
    EigenSolveError.
    """
    path = psi1_file(tmp_path)
    expected = lapack_load(path)
    with build_problem(load_toml(path), MPI.COMM_SELF) as problem:
        gep = GEPSolver(
            problem.model.A,
            problem.model.B,
            indefinite=True,
            prefix="test_failed_",
            options={**EIGEN_OPTIONS, "eps_ncv": 3},
        )
        try:
            gep.eps.setTolerances(max_it=1)  # the solve at target 0 only
            pair = gep.solve()
        finally:
            gep.destroy()
    assert pair.value == pytest.approx(expected, rel=1e-8)


@serial
def test_a_failed_free_solve_counts_every_eigen_solve(tmp_path):
    """A failed free solve, the spectral radius and the shifted solve: three eigen solves.

    The psi = -1 plate on 12 x 4 cells, Krylov-Schur cut to one iteration (the command
    line's ``-unibuckle_eps_max_it 1 -unibuckle_eps_ncv 3``): three SLEPc solves, counted
    by PETSc's own log (its ``EPSSolve`` event), and the result says three. Before, it
    said one (the free solve's count was fixed).
    """
    from petsc4py import PETSc

    from unibuckle_fenicsx import solve

    path = psi1_file(tmp_path)
    PETSc.Log.begin()
    event, options = PETSc.Log.Event("EPSSolve"), PETSc.Options()
    options["unibuckle_eps_max_it"], options["unibuckle_eps_ncv"] = 1, 3
    before = event.getPerfInfo()["count"]
    try:
        with solve(load_toml(path)) as analysis:
            eigensolves = analysis.result.eigensolves
    finally:
        options.delValue("unibuckle_eps_max_it")
        options.delValue("unibuckle_eps_ncv")
    assert event.getPerfInfo()["count"] - before == 3
    assert eigensolves == 3


@serial
def test_an_option_for_the_first_solve_leaves_the_recovery_alike_both_ways(tmp_path):
    """``eps_max_it = 1`` in Python and on the command line: the same load, LAPACK's.

    The psi = -1 plate on 12 x 4 cells: the solve at target 0 (prefix ``unibuckle_``)
    stops after one iteration, and the inertias and the shifted solve under their own
    prefix (``unibuckle_near_``) find the smallest load, LAPACK's lowest positive
    1/theta (``scipy.linalg.eigh`` on the dense pencil) to 1e-8, whichever way the
    option came. Before, the option given in Python reached the shifted solve too, which
    converged nothing ("converged no eigenpair"), where the command line's gave the load.
    """
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    from unibuckle_fenicsx import solve

    path = psi1_file(tmp_path)
    expected = lapack_load(path)
    with solve(load_toml(path), eps_options={"eps_max_it": 1}) as analysis:
        python_load = analysis.result.critical_load_Pa
    script = Path(sys.executable).parent / "unibuckle"
    out = tmp_path / "result.json"
    proc = subprocess.run(
        [str(script), "solve", "--config", str(path), "-q", "--json", str(out),
         "-unibuckle_eps_max_it", "1"],
        capture_output=True, text=True, env={**os.environ, "OMP_NUM_THREADS": "1"},
        cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    command_line_load = json.loads(out.read_text())["critical_load_Pa"]
    assert python_load == pytest.approx(expected, rel=1e-8)
    assert command_line_load == pytest.approx(expected, rel=1e-8)


def _one_restart(path, ncv: int) -> tuple[float, float]:
    """(load of the solve with ``ncv`` vectors and 1 restart, LAPACK's smallest load).

    The solve must take two tries (the first converges no pair) and leave the solver's
    own subspace as it was.
    """
    with build_problem(load_toml(path), MPI.COMM_SELF) as problem:
        A, B = dense(problem.model.A), dense(problem.model.B)
        theta = scipy.linalg.eigh(B, A, eigvals_only=True)
        gep = GEPSolver(
            problem.model.A,
            problem.model.B,
            prefix="test_wider_",
            options={**EIGEN_OPTIONS, "eps_ncv": ncv},
        )
        try:
            gep.eps.setTolerances(max_it=1)
            pair = gep.solve()
            assert gep.solves == 2  # the failed solve and the wider one
            assert gep.eps.getDimensions()[1] == ncv  # the solver's own subspace after it
        finally:
            gep.destroy()
    return pair.value, 1.0 / theta[-1]


@serial
def test_a_failed_solve_of_a_definite_pencil_tries_a_wider_subspace(tmp_path):
    """Uniform compression (B semi-definite), Krylov-Schur cut to 3 vectors, 1 restart.

    The solve at target 0 converges no pair; the second try with WIDER_NCV vectors finds
    LAPACK's smallest load (``scipy.linalg.eigh`` on the dense pencil: 7.427138e8 Pa,
    the next 8.35e8) to 1e-8. Before, the failed solve raised EigenSolveError, as a
    filled tube 60 x 1 mm, L = 60 mm, clamped, on 4 mm cells stopped its run (exit 3)
    at a contact set whose solve converged nothing in 500 restarts.
    """
    path = tmp_path / "uniform.toml"
    text = STEEP_TOML.replace("[-1.0, 9.0]", "-1.0").replace("nx = 30", "nx = 12")
    path.write_text(text.replace("ny = 10", "ny = 4"))
    load, lapack = _one_restart(path, 3)
    assert load == pytest.approx(lapack, rel=1e-8)
    assert lapack == pytest.approx(7.427138e8, rel=1e-6)


@serial
def test_the_second_try_is_wider_than_a_wide_first(tmp_path, monkeypatch):
    """A first try already as wide as WIDER_NCV: the second doubles it, not repeats it.

    WIDER_NCV lowered to 8 stands for a user's ``eps_ncv`` at or above it (here 16, 1
    restart, on 30 x 10 cells: 16 vectors converge no pair, 32 do). The second try
    used ``max(ncv, WIDER_NCV)`` = 16, the same failing solve once more, and raised
    EigenSolveError; with twice the first try's vectors it finds LAPACK's smallest load
    (``scipy.linalg.eigh`` on the dense pencil) to 1e-8.
    """
    import unibuckle_fenicsx.la.eigen as eigen

    monkeypatch.setattr(eigen, "WIDER_NCV", 8)
    path = tmp_path / "uniform.toml"
    path.write_text(STEEP_TOML.replace("[-1.0, 9.0]", "-1.0"))
    load, lapack = _one_restart(path, 16)
    assert load == pytest.approx(lapack, rel=1e-8)


def _diagonal(values, comm):
    mat = PETSc.Mat().createAIJ([len(values), len(values)], nnz=1, comm=comm)
    start, end = mat.getOwnershipRange()
    for i in range(start, end):
        mat.setValue(i, i, values[i])
    mat.assemble()
    return mat


def test_a_failed_slepc_solve_reports_its_own_error_not_the_destroys():
    """SLEPc's error reaches the user even when destroying the failed EPS fails too.

    The swapped pencil puts A in the inner-product slot; an indefinite A (what rounding
    makes of the stiffness of a plate too thin for double precision) makes SLEPc refuse
    the B-inner product ("The inner product is not well defined", PETSc error 95) with a
    work matrix still checked out, and the EPS's destroy then fails with "Need to call
    MatDenseRestoreSubMatrix() first" (58). That second error used to replace the first.
    """
    comm = MPI.COMM_WORLD
    n = 20
    A = _diagonal([(-1.0) ** i * (i + 1) for i in range(n)], comm)  # indefinite
    B = _diagonal([1.0] * n, comm)
    try:
        with pytest.raises(Exception) as raised:
            swapped_eigenpairs(A, B, "test_masked_", which=SLEPc.EPS.Which.LARGEST_MAGNITUDE)
    finally:
        A.destroy()
        B.destroy()
    failure = petsc_failure(raised.value)
    assert failure is not None, raised.value
    assert failure.first_line == "error code 95", failure
    assert "inner product is not well defined" in failure.reason, failure
    assert "MatDenseRestoreSubMatrix" not in failure.reason, failure
