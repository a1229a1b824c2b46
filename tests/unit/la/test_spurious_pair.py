"""A returned pair with a residual of order one is solved again, not taken as the load.

A filled tube D = 0.1 m, t = 1 mm, L = 0.1 m, simply supported, 5 mm cells, with every
one of its 1 216 core directions removed: the reduced pencil's B has lost most of its
rank, and Krylov-Schur in shift-and-invert (SLEPc's default subspace, from its own start)
returned a pair whose relative residual was about 1 (a load of -2.1e10 Pa, or, from the
last mode, 1.58e10 Pa, on a pencil whose least load is above 8e10). The active set's
descent took such a pair for an admissible mode 14 % below the hollow tube's load, which
interlacing forbids. The reference needs no eigen solver: Sylvester's law of inertia on
MUMPS's LDL^T of A - sigma B says how many loads lie below sigma.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest

from unibuckle_fenicsx import SectionParameters
from unibuckle_fenicsx.model.shell.section import build_section

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial")


def _loads_below(A: PETSc.Mat, B: PETSc.Mat, sigma: float) -> int:
    """The pencil's eigenvalues in (0, sigma) (A SPD): negative pivots of A - sigma B."""
    K = A.copy()
    K.axpy(-sigma, B)
    K.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    ksp = PETSc.KSP().create(K.comm)
    ksp.setOptionsPrefix("test_inertia_")
    ksp.setOperators(K)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("cholesky")
    pc.setFactorSolverType("mumps")
    opts = PETSc.Options()
    opts["test_inertia_mat_mumps_icntl_24"] = 1
    opts["test_inertia_mat_mumps_icntl_13"] = 1
    ksp.setFromOptions()
    ksp.setUp()
    negative = pc.getFactorMatrix().getInertia()[0]
    for name in ("mat_mumps_icntl_24", "mat_mumps_icntl_13"):
        opts.delValue("test_inertia_" + name)
    ksp.destroy()
    K.destroy()
    return int(negative)


def test_a_pair_with_a_residual_of_order_one_is_solved_again():
    tube = SectionParameters(
        "tube", diameter=0.1, thickness=0.001, length=0.1, E=2.1e11, nu=0.3,
        mesh_size=0.005, ends="simply_supported", core=True,
    )  # fmt: skip
    section = build_section(tube, MPI.COMM_SELF)
    try:
        problem = section.problem
        solver = problem.eigensolver
        free = problem.solve_free().load
        rows = problem.contact.removed_rows(np.arange(problem.contact.size))
        pair = solver.solve(rows)
        A, B = solver.reduced(rows)
        # The smallest load of the reduced pencil: none below 0.999 of it, one below 1.001.
        assert _loads_below(A, B, 0.999 * pair.value) == 0
        assert _loads_below(A, B, 1.001 * pair.value) >= 1
        assert pair.value > free  # interlacing: removing directions never lowers a load
        assert pair.error < 1e-8
    finally:
        section.destroy()
