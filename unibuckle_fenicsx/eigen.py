r"""Smallest eigenpair of the buckling pencil with a set of DOFs removed (SLEPc).

:math:`A u = \lambda B u`, A SPD (after the edge conditions), B the geometric
stiffness. Removed DOFs (an active contact set) get zero rows and columns with
diagonal 1 in A and 0 in B, on work copies of the once-assembled matrices, so that
they map to :math:`\lambda = \infty`.

- B positive semidefinite (compressive prestress everywhere): GHEP, Krylov-Schur with
  shift-and-invert at target 0 and a MUMPS LU of A.
- B indefinite (tension somewhere): the swapped pencil :math:`B x = \mu A x` (A SPD)
  for the largest real :math:`\mu`, :math:`\lambda = 1/\mu`; the smallest positive
  :math:`\lambda` whatever the negative ones.

Note:
    Every object here is collective on the matrices' communicator; :meth:`GEPSolver.destroy`
    is collective.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

try:
    from petsc4py import PETSc
    from slepc4py import SLEPc
except ImportError as err:  # pragma: no cover
    raise ImportError(
        "unibuckle_fenicsx.eigen needs petsc4py and slepc4py (real scalars); install "
        "the 'fenics' extra: pip install 'unibuckle_fenicsx[fenics]'"
    ) from err

__all__ = ["EIGEN_OPTIONS", "EigenPair", "EigenSolveError", "GEPSolver"]

logger = logging.getLogger(__name__)

#: Default EPS options (overridable per solver or on the command line under the prefix).
EIGEN_OPTIONS: dict[str, str | float | int] = {
    "eps_type": "krylovschur",
    "st_ksp_type": "preonly",
    "st_pc_type": "lu",
    "st_pc_factor_mat_solver_type": "mumps",
    "eps_max_it": 500,
}


class EigenSolveError(RuntimeError):
    """The eigen solve did not converge."""


@dataclass(frozen=True)
class EigenPair:
    r"""Smallest eigenpair of a (reduced) pencil.

    Attributes:
        value: :math:`\lambda`.
        error: SLEPc relative residual :math:`\|Ax-\lambda Bx\|/(|\lambda|\|x\|)`.
        iterations: Krylov-Schur restarts used.
        converged: Converged pairs returned by SLEPc.
    """

    value: float
    error: float
    iterations: int
    converged: int


def _is_zero(B: PETSc.Mat) -> bool:
    """Whether B has no non-zero entry (collective)."""
    return bool(B.norm(PETSc.NormType.INFINITY) == 0.0)  # type: ignore[arg-type]


class GEPSolver:
    """Smallest eigenpair of :math:`(A, B)` with optional removed DOFs.

    Args:
        A: Stiffness matrix, SPD (owned by the caller; not modified).
        B: Geometric stiffness matrix (owned by the caller; not modified).
        indefinite: B is indefinite: solve the swapped pencil.
        prefix: Options prefix, non-empty; ``-<prefix>eps_view`` and friends apply.
        tol: EPS tolerance.
        options: Options pushed under ``prefix`` (default :data:`EIGEN_OPTIONS`).

    Note:
        Collective on ``A.comm``.
    """

    def __init__(
        self,
        A: PETSc.Mat,
        B: PETSc.Mat,
        *,
        indefinite: bool = False,
        prefix: str = "unibuckle_",
        tol: float = 1e-10,
        options: dict[str, str | float | int] | None = None,
    ) -> None:
        if not prefix:
            raise ValueError("GEPSolver needs a non-empty options prefix")
        self.A, self.B = A, B
        self.indefinite = indefinite
        self.prefix = prefix
        self._Aw: PETSc.Mat | None = None
        self._Bw: PETSc.Mat | None = None
        self.solves = 0

        eps = SLEPc.EPS().create(A.comm)
        eps.setOptionsPrefix(prefix)
        eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
        eps.setDimensions(1)
        eps.setTolerances(tol)
        st = eps.getST()
        if indefinite:
            eps.setWhichEigenpairs(SLEPc.EPS.Which.LARGEST_REAL)
            st.setType(SLEPc.ST.Type.SHIFT)
            st.setShift(0.0)
        else:
            eps.setTarget(0.0)
            eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_REAL)
            st.setType(SLEPc.ST.Type.SINVERT)
        opts = PETSc.Options()
        opts.prefixPush(prefix)
        for key, value in (EIGEN_OPTIONS if options is None else options).items():
            opts.setValue(key, value)
        opts.prefixPop()
        eps.setFromOptions()
        opts.prefixPush(prefix)
        for key in EIGEN_OPTIONS if options is None else options:
            opts.delValue(key)
        opts.prefixPop()
        self.eps = eps

    def _work(self, removed: npt.NDArray[np.int64]) -> tuple[PETSc.Mat, PETSc.Mat]:
        same = PETSc.Mat.Structure.SAME_NONZERO_PATTERN
        if self._Aw is None:
            self._Aw = self.A.duplicate(copy=True)
            self._Bw = self.B.duplicate(copy=True)
        else:
            self.A.copy(self._Aw, structure=same)  # type: ignore[arg-type]
            self.B.copy(self._Bw, structure=same)  # type: ignore[arg-type]
        assert self._Bw is not None
        rows = np.ascontiguousarray(removed, dtype=PETSc.IntType)
        self._Aw.zeroRowsColumns(rows, diag=1.0)  # type: ignore[arg-type]
        self._Bw.zeroRowsColumns(rows, diag=0.0)  # type: ignore[arg-type]
        return self._Aw, self._Bw

    def solve(
        self,
        removed: npt.NDArray[np.int64] | None = None,
        out: PETSc.Vec | None = None,
        initial: PETSc.Vec | None = None,
    ) -> EigenPair:
        """Smallest eigenpair with the DOFs ``removed`` set to zero.

        Args:
            removed: Global row indices owned by this rank to remove (may be empty on
                some ranks; every rank must call).
            out: Vector receiving the eigenvector (B-normalised by SLEPc).
            initial: Optional start vector (e.g. the previous mode).

        Returns:
            The eigenpair, with value ``inf`` when the removed DOFs leave no geometric
            stiffness (no finite load); raises :class:`EigenSolveError` if SLEPc converged no pair
            or returned a non-positive or non-finite load.

        Note:
            Collective.
        """
        n_removed = self.A.comm.tompi4py().allreduce(0 if removed is None else len(removed))
        if n_removed:
            assert removed is not None
            A, B = self._work(removed)
        else:
            A, B = self.A, self.B
        if _is_zero(B):
            # Every DOF carrying geometric stiffness is removed: no finite load.
            if out is not None:
                out.zeroEntries()
            return EigenPair(float("inf"), 0.0, 0, 0)
        if self.indefinite:
            self.eps.setOperators(B, A)
        else:
            self.eps.setOperators(A, B)
        if initial is not None:
            self.eps.setInitialSpace([initial])
        self.eps.solve()
        self.solves += 1
        nconv = self.eps.getConverged()
        its = self.eps.getIterationNumber()
        if nconv < 1:
            reason = self.eps.getConvergedReason()
            raise EigenSolveError(
                f"SLEPc ({self.prefix}) converged no eigenpair after {its} iterations "
                f"(reason {reason}, tol {self.eps.getTolerances()[0]:.1e}); try "
                f"-{self.prefix}eps_max_it or a looser -{self.prefix}eps_tol"
            )
        theta = self.eps.getEigenvalue(0).real
        value = 1.0 / theta if self.indefinite else theta
        if not np.isfinite(value) or value <= 0.0:
            raise EigenSolveError(
                f"SLEPc ({self.prefix}) returned a non-positive load {value!r}: the "
                "pencil has no buckling load under a positive load factor"
            )
        if out is not None:
            self.eps.getEigenvector(0, out)
        error = self.eps.computeError(0)
        return EigenPair(float(value), float(error), int(its), int(nconv))

    def destroy(self) -> None:
        """Destroy the EPS and work matrices (collective)."""
        for name in ("eps", "_Aw", "_Bw"):
            obj = getattr(self, name, None)
            if obj is not None:
                obj.destroy()
                setattr(self, name, None)

    def __del__(self) -> None:
        self.destroy()
