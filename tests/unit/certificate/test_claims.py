r"""What the certificate's labels claim is what its checks found.

- A KKT point that is not its reduced pencil's smallest eigenpair is no critical state
  (paper, Lemma 5.1): the paper's plate c3 at 6 x 3 cells with Z = {0, 5} has, by
  scipy's dense ``eigh``, the reduced pencil's two least loads 1.7336e7 and 2.2067e7 Pa;
  the second's mode is admissible and the obstacle only pushes it. The inertia check
  found it not the smallest (``smallest_of_reduced`` False), and the starting code
  still labelled it "kkt-only" (a local critical state).
- The inertias the certificate and the eigen solver read (MUMPS :math:`LDL^T`, null
  pivots apart) count the pencil's eigenvalues below the shift (Sylvester's law): here
  against numpy's dense ``eigvalsh`` of :math:`A_Z - \sigma B_Z`, with the supports'
  and the contact set's rows in the matrices (diagonal 1 in A, 0 in B), on a definite
  and on an indefinite B, and with the foundation's springs added.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
import scipy.linalg

from support.exhaustive import dense
from unibuckle_fenicsx.certificate.certify import (
    certify,
    certify_foundation,
    pencil_inertia,
    reduced_inertia,
    spring_inertia,
)
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.eigen import EigenPair
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec import ObstacleSpec
from unibuckle_fenicsx.spec.cases import paper_case, plate_case

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense references are serial")


def _reduced(problem, active):
    """Dense (A_Z, B_Z) without the rows of ``active``, and the kept rows."""
    A, B = dense(problem.model.A), dense(problem.model.B)
    rows = problem.contact.removed_rows(np.asarray(active, np.int64))
    keep = np.setdiff1d(np.arange(A.shape[0]), rows)
    return A[np.ix_(keep, keep)], B[np.ix_(keep, keep)], keep


def _below(a, b, sigma):
    """Eigenvalues of the pencil (a, b) in (0, sigma): negative ones of a - sigma b (a SPD)."""
    return int((np.linalg.eigvalsh(a - sigma * b) < 0.0).sum())


def test_a_higher_pair_is_not_labelled_a_critical_state():
    with build_problem(paper_case("c3", 6, 3), MPI.COMM_SELF) as problem:
        active = np.array([0, 5], np.int64)
        a, b, keep = _reduced(problem, active)
        theta, vectors = scipy.linalg.eigh(b, a)
        order = np.argsort(-theta)
        least, second = 1.0 / theta[order[0]], 1.0 / theta[order[1]]
        assert least < second * (1 - 1e-3)  # 1.7336e7 < 2.2067e7 Pa
        mode = problem.new_mode()
        mode.x.petsc_vec.array[:] = 0.0
        mode.x.petsc_vec.array[keep] = vectors[:, order[1]]
        mode.x.scatter_forward()
        cand = problem.candidate(mode, second, active, eigen=EigenPair(second, 0.0, 0, 1))
        assert cand.kkt  # admissible, and the obstacle only pushes
        cert = certify(problem, cand, global_bound=True)
        assert cert.smallest_of_reduced is False
        assert cert.status == "not-kkt"


@pytest.mark.parametrize("load", ["uniaxial", "compression+shear"])
def test_the_inertias_count_what_dense_eigenvalues_count(load):
    spec = plate_case(
        "p", length=2.0, width=1.0, thickness=0.01, nx=8, ny=4, load=load,
        zone=ObstacleSpec(zone=((0.5, 1.5), (0.2, 0.8))),
    )  # fmt: skip
    with build_problem(spec, MPI.COMM_SELF) as problem:
        free = problem.solve_free().load
        solver = problem.eigensolver
        assert solver.indefinite == (load != "uniaxial")  # B indefinite under shear
        for active in ((), (0, 1), tuple(range(problem.contact.size))):
            a, b, _ = _reduced(problem, active)
            for factor in (0.5, 0.999, 1.001, 2.0, 5.0):
                sigma = factor * free
                expected = _below(a, b, sigma)
                got = reduced_inertia(problem, np.asarray(active, np.int64), sigma)
                assert got[0] == expected, (active, factor, got)
                if not active:
                    assert pencil_inertia(problem.model.A, problem.model.B, sigma)[0] == expected
                    if solver.indefinite:  # the swapped pencil's count: positive pivots
                        eps = solver.shifted.near_eps()
                        count = solver.shifted.shift_to(eps, solver.A, solver.B, sigma, None)
                    else:
                        count = solver.count_below(sigma)
                    assert count == expected, (factor, count)


def test_the_spring_inertia_counts_what_dense_eigenvalues_count():
    spec = plate_case(
        "strip", length=2.0, width=1.0, thickness=1e-3, nx=8, ny=4,
        zone=ObstacleSpec("all", foundation_stiffness=1.0e3),
    )  # fmt: skip
    with build_problem(spec, MPI.COMM_SELF) as problem:
        free = problem.solve_free().load
        pressing = np.arange(0, problem.contact.size, 3, dtype=np.int64)
        a, b = dense(problem.model.A), dense(problem.model.B)
        diag = problem.model.A.createVecLeft()
        rows, nodes = problem.contact.node_rows(pressing)
        diag.setValues(rows.astype(PETSc.IntType), problem.contact.stiffness[nodes])
        diag.assemble()
        springs = np.diag(diag.array.copy())
        diag.destroy()
        assert springs.any()
        for factor in (0.999, 1.5, 3.0, 10.0):
            sigma = factor * free
            expected = _below(a + springs, b, sigma)
            assert spring_inertia(problem, pressing, sigma)[0] == expected, factor


def test_the_spring_inertia_of_a_rigid_obstacle_is_refused_naming_the_foundation():
    # A rigid obstacle has no springs: the count it asks for is reduced_inertia's.
    with build_problem(paper_case("c3", 6, 3), MPI.COMM_SELF) as problem:
        with pytest.raises(InputError, match="foundation_stiffness"):
            spring_inertia(problem, np.arange(2, dtype=np.int64), 1.0)


def test_a_rigid_obstacles_state_is_refused_by_the_foundations_certificate():
    # certify_foundation reads the springs; a rigid obstacle's state is certify's. The
    # solution is not read: the refusal comes before any solve.
    with build_problem(paper_case("c3", 6, 3), MPI.COMM_SELF) as problem:
        with pytest.raises(InputError, match="foundation_stiffness"):
            certify_foundation(problem, None)  # type: ignore[arg-type]
        assert problem.eigensolver.solves == 0
