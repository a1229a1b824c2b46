r"""Sparse :math:`LDL^T` factorisations with inertia (MUMPS), and matrix helpers.

The inertia of :math:`A - \sigma B` counts the pencil's eigenvalues below
:math:`\sigma` (Sylvester's law, A SPD): the shifted eigen solves, the interior point's
inertia control and the certificate all read it. The matrices that have the stiffness
matrix's pattern share one factorisation per mesh (:class:`SharedFactorization`), whose
symbolic analysis is done once.

Note:
    Every object here is collective on its matrix's communicator; ``destroy()`` is
    collective.
"""

from __future__ import annotations

from typing import Any

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from unibuckle_fenicsx.la.options import Options, ordering_options, set_options
from unibuckle_fenicsx.la.ownership import Owner, release

__all__ = [
    "LDL_OPTIONS",
    "SharedFactorization",
    "SymmetricFactorization",
    "abs_matrix",
    "compact",
    "same_pattern",
    "set_ldl_options",
]

#: Default options of :class:`SymmetricFactorization`: a MUMPS LDLᵀ (symmetric
#: indefinite), with the settings MUMPS needs to report the inertia in parallel
#: (ICNTL(13) = 1) and the null pivots (ICNTL(24) = 1).
LDL_OPTIONS: dict[str, str | float | int | bool] = {
    "ksp_type": "preonly",
    "pc_type": "cholesky",
    "pc_factor_mat_solver_type": "mumps",
    "mat_mumps_icntl_13": 1,
    "mat_mumps_icntl_24": 1,
}


def _without_zeros(mat: PETSc.Mat, values: Any, csr: Any) -> PETSc.Mat:
    """An AIJ matrix with ``mat``'s layout: ``values`` at its local CSR rows ``csr``, zeros out."""
    indptr, indices, _ = csr
    keep = values != 0.0
    kept = np.concatenate(([0], np.cumsum(keep)))  # kept entries before each entry
    new = (
        kept[indptr].astype(PETSc.IntType),
        indices[keep].astype(PETSc.IntType),
        values[keep],
    )
    out = PETSc.Mat().createAIJWithArrays(mat.getSizes(), new, comm=mat.comm)  # type: ignore[arg-type]
    out.setOption(PETSc.Mat.Option.SYMMETRIC, mat.isSymmetricKnown()[1])  # type: ignore[arg-type]
    return out


def abs_matrix(mat: PETSc.Mat) -> PETSc.Mat:
    """A new matrix with the entries' absolute values, without stored zeros.

    The caller destroys it. Collective.
    """
    csr = mat.getValuesCSR()
    return _without_zeros(mat, np.abs(csr[2]), csr)


def compact(mat: PETSc.Mat) -> PETSc.Mat:
    """A copy of ``mat`` without its stored zeros (the same products, to the last bit).

    The geometric stiffness B is assembled in the three-field pattern of the stiffness
    matrix, of which only the deflection block is nonzero (a tenth of the entries);
    its products, in every step of an eigen solve, cost a fifth as much compacted. The
    caller destroys it. Collective.
    """
    csr = mat.getValuesCSR()
    return _without_zeros(mat, csr[2], csr)


def set_ldl_options(ksp: PETSc.KSP, prefix: str, reused: bool = False) -> None:
    """Make ``ksp`` a MUMPS :math:`LDL^T` with inertia (:data:`LDL_OPTIONS`), unfactorised.

    :func:`set_options` with ``setup=True`` would factorise the current operator (the
    MUMPS controls are read at the first factorisation, while the defaults are in the
    options database); a matrix whose values are set before every factorisation (the
    interior point's Newton matrix) does not need that one. The controls go onto the
    factor matrix instead, which PETSc hands to MUMPS when it starts; the rest of
    :data:`LDL_OPTIONS` goes through the database (a command-line option under
    ``prefix`` still wins). The ordering is
    :func:`~unibuckle_fenicsx.la.options.mumps_ordering`'s for the operator's size
    (``reused``: for an analysis that serves many numeric factorisations). The operator
    must be set. Collective.
    """
    options = {**ordering_options(ksp.getOperators()[0], reused=reused), **LDL_OPTIONS}
    mumps = {k: v for k, v in options.items() if k.startswith("mat_mumps_icntl_")}
    others = {k: v for k, v in options.items() if k not in mumps}
    set_options(ksp, prefix, others)
    pc = ksp.getPC()
    pc.setFactorSetUpSolverType()
    factor = pc.getFactorMatrix()
    for key, value in mumps.items():
        factor.setMumpsIcntl(int(key.rsplit("_", 1)[1]), int(value))


class SymmetricFactorization(Owner):
    r"""Sparse :math:`LDL^T` factorisation of a symmetric (indefinite) matrix, with inertia.

    A KSP ``preonly`` + PC ``cholesky`` with MUMPS (:data:`LDL_OPTIONS`); the matrix
    must not carry PETSc's SPD flag (MUMPS would then assume a positive definite
    matrix). Used by the global-optimality certificate: the inertia of
    :math:`A - \lambda B` counts the pencil's eigenvalues below :math:`\lambda`.

    Args:
        mat: Symmetric matrix (referenced, not copied; keep it alive).
        prefix: Options prefix, e.g. ``unibuckle_certify_`` (so
            ``-unibuckle_certify_ksp_view`` works).
        options: Options pushed under ``prefix`` (default :data:`LDL_OPTIONS`).

    Note:
        Collective. The owner must :meth:`destroy` it.
    """

    def __init__(self, mat: PETSc.Mat, prefix: str, options: Options | None = None) -> None:
        mat.setOption(PETSc.Mat.Option.SPD, False)  # type: ignore[arg-type]
        mat.setOption(PETSc.Mat.Option.SYMMETRIC, True)  # type: ignore[arg-type]
        self.ksp = PETSc.KSP().create(mat.comm)
        self.ksp.setOperators(mat)
        defaults = {**ordering_options(mat), **(LDL_OPTIONS if options is None else options)}
        set_options(self.ksp, prefix, defaults, setup=True)
        self.prefix = prefix

    def inertia(self) -> tuple[int, int, int]:
        """(negative, zero, positive) eigenvalue counts of the factorised matrix."""
        nneg, nzero, npos = self.ksp.getPC().getFactorMatrix().getInertia()
        return int(nneg), int(nzero), int(npos)

    def solve(self, b: PETSc.Vec, x: PETSc.Vec) -> None:
        """Solve M x = b for x (collective)."""
        self.ksp.solve(b, x)

    def destroy(self) -> None:
        """Destroy the KSP and its factor (collective)."""
        release(self, "ksp")

    def __del__(self) -> None:
        self.destroy()


def _local_pattern(mat: PETSc.Mat) -> tuple[Any, Any]:
    """The row offsets and column indices of ``mat``'s local rows (copies; not collective)."""
    if mat.getType() == "seqaij":  # the indices alone: the values are not copied
        ai, aj = mat.getRowIJ()
        return ai, aj
    ai, aj, _ = mat.getValuesCSR()
    return ai, aj


def same_pattern(a: PETSc.Mat, b: PETSc.Mat) -> bool:
    """Whether ``a`` and ``b`` have one CSR nonzero pattern on every rank (collective).

    Matrices with different numbers of stored entries on a rank differ there without a
    look at their indices.
    """
    local = PETSc.Mat.InfoType.LOCAL
    same = a.getInfo(local)["nz_used"] == b.getInfo(local)["nz_used"]  # type: ignore[arg-type]
    if same:
        ai, aj = _local_pattern(a)
        bi, bj = _local_pattern(b)
        same = bool(np.array_equal(ai, bi) and np.array_equal(aj, bj))
    return bool(a.getComm().tompi4py().allreduce(same, op=MPI.LAND))


class SharedFactorization(Owner):
    r"""One MUMPS :math:`LDL^T` (with inertia) for the matrices of one mesh that have A's pattern.

    The interior-point Newton matrix :math:`A - \lambda B + \Sigma`, the shifted matrices
    of the eigen solves near an estimate (:math:`A_Z - \sigma B_Z`) and the
    certificate's :math:`A - \lambda B` all have the stiffness matrix's nonzero pattern.
    Each user writes its values into ``matrix`` and calls :meth:`factor`; MUMPS's
    symbolic analysis (the fill-reducing ordering) is done on the first call only; an
    analysis costs as much as a numeric factorisation (:doc:`/verification/tuning`).

    The factorisation belongs to whoever called :meth:`factor` last (:meth:`holds`): a
    user that solves with it later checks that first and factorises again if not.

    Args:
        A: The stiffness matrix (AIJ); ``matrix`` is a copy with its pattern.
        prefix: Options prefix of the factorisation (:data:`LDL_OPTIONS`).
        reused: Its analysis will serve many numeric factorisations (a route's), for
            the ordering (:func:`~unibuckle_fenicsx.la.options.mumps_ordering`).

    Note:
        Collective. Owned by the problem's :class:`~unibuckle_fenicsx.la.eigen.GEPSolver`
        (:attr:`~unibuckle_fenicsx.la.eigen.GEPSolver.factorization`).
    """

    def __init__(self, A: PETSc.Mat, prefix: str, reused: bool = False) -> None:
        self.matrix = A.duplicate(copy=True)
        self.matrix.setOption(PETSc.Mat.Option.SPD, False)  # type: ignore[arg-type]
        self.matrix.setOption(PETSc.Mat.Option.SYMMETRIC, True)  # type: ignore[arg-type]
        self.ksp = PETSc.KSP().create(A.comm)
        self.ksp.setOperators(self.matrix)
        set_ldl_options(self.ksp, prefix, reused)
        self.prefix = prefix
        self._holder: object | None = None

    def factor(self, holder: object) -> tuple[int, int, int]:
        """Factorise ``matrix`` for ``holder``; the inertia (negative, zero, positive)."""
        self.ksp.setOperators(self.matrix)
        self.ksp.setUp()
        self._holder = holder
        return self.inertia()

    def claim(self, holder: object) -> None:
        """Record that ``holder`` factorised ``matrix`` through ``ksp`` (SLEPc's ST)."""
        self._holder = holder

    def holds(self, holder: object) -> bool:
        """Whether the current factorisation is ``holder``'s."""
        return self._holder is holder

    def inertia(self) -> tuple[int, int, int]:
        """(negative, zero, positive) eigenvalue counts of the factorised matrix."""
        nneg, nzero, npos = self.ksp.getPC().getFactorMatrix().getInertia()
        return int(nneg), int(nzero), int(npos)

    def fits(self, mat: PETSc.Mat) -> bool:
        """Whether ``mat`` has exactly ``matrix``'s pattern (ask once per matrix).

        A value copy with ``SAME_NONZERO_PATTERN`` trusts the caller: PETSc compares
        only the number of nonzeros. Collective.
        """
        return same_pattern(self.matrix, mat)

    def destroy(self) -> None:
        """Destroy the matrix and its factorisation (collective)."""
        release(self, "ksp", "matrix")

    def __del__(self) -> None:
        self.destroy()
