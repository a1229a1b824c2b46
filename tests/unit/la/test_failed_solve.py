r"""After Krylov-Schur converges no pair of the swapped pencil: the inertia decides.

A steep stress gradient on a coarse mesh leaves :math:`b(w, w) \le 0` on every free
deflection up to round-off: Krylov-Schur meets no relative tolerance there, and the
answer is "no positive buckling load" (exit 2), never "not converged" (exit 3). When a
load does exist, the inertias bracket it and a shifted solve finds it. The reference
values are LAPACK's (``scipy.linalg.eigh`` on the dense pencil), never the solver's.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import pytest
import scipy.linalg

from support.exhaustive import dense
from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, main
from unibuckle_fenicsx.la.eigen import EIGEN_OPTIONS, GEPSolver
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec.files import load_toml

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference: serial")

#: A 300 x 100 x 3 mm SSSS steel plate under in-plane bending with psi = -9 (edge
#: stresses -1 at y = 0 to 9 at y = b): the compressed strip is b/10, one cell of 30 x 10.
STEEP_TOML = """
name = "steep_gradient"
[plate]
corners = [[0.0, 0.0], [0.3, 0.1]]
thickness = 0.003
[material]
E = 2.1e11
nu = 0.3
[edges.left]
support = "simply_supported"
normal_stress = [-1.0, 9.0]
[edges.right]
support = "simply_supported"
normal_stress = [-1.0, 9.0]
[edges.bottom]
support = "simply_supported"
[edges.top]
support = "simply_supported"
[mesh]
nx = 30
ny = 10
"""


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
    path = tmp_path / "psi1.toml"
    text = STEEP_TOML.replace("[-1.0, 9.0]", "[-1.0, 1.0]").replace("nx = 30", "nx = 12")
    path.write_text(text.replace("ny = 10", "ny = 4"))
    with build_problem(load_toml(path), MPI.COMM_SELF) as problem:
        A, B = dense(problem.model.A), dense(problem.model.B)
        theta = scipy.linalg.eigh(B, A, eigvals_only=True)
        expected = 1.0 / theta[-1]
        assert theta[-1] > 1e-6 * np.abs(theta).max()  # a real load
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

    path = tmp_path / "psi1.toml"
    text = STEEP_TOML.replace("[-1.0, 9.0]", "[-1.0, 1.0]").replace("nx = 30", "nx = 12")
    path.write_text(text.replace("ny = 10", "ny = 4"))
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
