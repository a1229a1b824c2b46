"""A pair that is no eigenpair of a definite pencil is solved again, never returned.

A filled tube D = 0.1 m, t = 1 mm, L = 0.1 m, simply supported, 10 mm cells (2 112 DOFs),
with every one of its 288 core directions removed: B, semidefinite, has lost most of its
rank. Krylov-Schur in shift-and-invert at 0, started from the free mode (nonzero on the
removed rows, as the active set's last mode is), "converged" to pairs that are none: from
that start the starting code returned 6.474e10 Pa, 20 % below the pencil's least load
(SLEPc's default subspace alone gave 2.674e9, its vector's Rayleigh quotient 9.78e10). The
5 mm tube's active set took such pairs for admissible modes. The references need no eigen
solver of the package: scipy's dense ``eigh`` of the swapped pencil (A SPD), and
Sylvester's law of inertia (numpy's ``eigvalsh`` of A - sigma B).
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
import scipy.linalg

from support.exhaustive import dense
from support.tubes import filled_tube
from unibuckle_fenicsx.model.shell.section import build_section

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial")


def _reduced_dense(
    A: PETSc.Mat, B: PETSc.Mat, removed: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The pencil without the removed rows and columns, as dense arrays."""
    keep = np.setdiff1d(np.arange(A.getSize()[0]), removed)
    a = dense(A)[np.ix_(keep, keep)]
    b = dense(B)[np.ix_(keep, keep)]
    return a, b


def _loads_below(a: np.ndarray, b: np.ndarray, sigma: float) -> int:
    """The pencil's eigenvalues in (0, sigma) (a SPD, Sylvester): negative ones of a - sigma b."""
    return int((np.linalg.eigvalsh(a - sigma * b) < 0.0).sum())


def test_a_pair_that_is_no_eigenpair_is_solved_again():
    section = build_section(filled_tube(), MPI.COMM_SELF)
    try:
        problem = section.problem
        solver = problem.eigensolver
        free = problem.solve_free()
        rows = problem.contact.removed_rows(np.arange(problem.contact.size))
        start = free.function.x.petsc_vec  # nonzero on the removed rows
        out = start.duplicate()
        pair = solver.solve(rows, out=out, initial=start)
        A, B = solver.reduced(rows)
        a, b = _reduced_dense(A, B, rows)
        # scipy: the largest mu of b x = mu a x (a SPD) is 1 / the least load, 8.0533462e10 Pa
        mu = scipy.linalg.eigh(b, a, eigvals_only=True, subset_by_index=[a.shape[0] - 1] * 2)
        least = float(1.0 / mu[-1])
        assert least > free.load  # interlacing, as a check of the reference
        assert pair.value == pytest.approx(least, rel=1e-8)
        # Sylvester's law on a - sigma b: no load below 0.999 of the pair's, one below 1.001.
        assert _loads_below(a, b, 0.999 * pair.value) == 0
        assert _loads_below(a, b, 1.001 * pair.value) >= 1
        # The vector is its eigenvector: its Rayleigh quotient is the load.
        Ax, Bx = A.createVecLeft(), B.createVecLeft()
        A.mult(out, Ax)
        B.mult(out, Bx)
        assert out.dot(Ax) / out.dot(Bx) == pytest.approx(pair.value, rel=1e-10)
        for vec in (Ax, Bx, out):
            vec.destroy()
    finally:
        section.destroy()
