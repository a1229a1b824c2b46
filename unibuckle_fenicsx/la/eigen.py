r"""The buckling pencil's smallest eigenpair, and extreme eigenvalues (SLEPc).

:math:`A u = \lambda B u`, A SPD (after the edge conditions), B the geometric
stiffness. Removed DOFs (an active contact set) get zero rows and columns with
diagonal 1 in A and 0 in B, on work copies of the once-assembled matrices, so that
they map to :math:`\lambda = \infty`.

- B positive semidefinite (compressive prestress everywhere): GHEP, Krylov-Schur with
  shift-and-invert at target 0 and a MUMPS LU of A. A solve given an estimate of the
  eigenvalue (a contact set read off a nearby state) runs a second Krylov-Schur
  shifted just below it, with a MUMPS :math:`LDL^T` whose inertia proves that no
  eigenvalue lies below the shift (else the solve at target 0 runs).
- B indefinite (tension somewhere): the swapped pencil :math:`B x = \mu A x` (A SPD)
  for the largest real :math:`\mu`, :math:`\lambda = 1/\mu`; the smallest positive
  :math:`\lambda` whatever the negative ones. A solve given an estimate shifts the
  swapped pencil to :math:`1/\sigma`: :math:`B - A/\sigma` has a positive eigenvalue
  for each eigenvalue of the pencil in :math:`(0, \sigma)`, so its inertia proves
  the same.

Note:
    Every object here is collective on its matrices' communicator; ``destroy()`` is
    collective.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

from petsc4py import PETSc
from slepc4py import SLEPc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import EigenSolveError, InputError
from unibuckle_fenicsx.la.factor import SharedFactorization, compact
from unibuckle_fenicsx.la.options import (
    Options,
    Prefix,
    option_defaults,
    ordering_options,
    set_options,
)
from unibuckle_fenicsx.la.ownership import Owner, destroyed_after, release
from unibuckle_fenicsx.tolerances import SMALLEST_RTOL_FACTOR

__all__ = [
    "EIGEN_OPTIONS",
    "EXTREME_OPTIONS",
    "NEAR_MARGIN",
    "NEAR_NCV",
    "EigenPair",
    "GEPSolver",
    "ShiftedSolves",
    "SmallestProof",
    "SmallestSearch",
    "extreme_eigenvalues",
    "lowest_eigenvalues",
    "spurious_pair",
    "swapped_eigenpairs",
]

logger = logging.getLogger(__name__)

#: Default EPS options of :class:`GEPSolver` (overridable per solver or on the command
#: line under the prefix). The solves at target 0 factorise with an LU; the shifted
#: solves (``near=...``) with the mesh's
#: :class:`~unibuckle_fenicsx.la.factor.SharedFactorization`, a symmetric :math:`LDL^T`
#: whose inertia they need. An LU at target 0 keeps the rounding that decides between
#: mirror-image contact sets of equal load the same on any number of ranks
#: (:doc:`/verification/tuning`).
EIGEN_OPTIONS: dict[str, str | float | int | bool] = {
    "eps_type": "krylovschur",
    "st_ksp_type": "preonly",
    "st_pc_type": "lu",
    "st_pc_factor_mat_solver_type": "mumps",
    "eps_max_it": 500,
}

#: A solve given an estimate ``near`` of the eigenvalue shifts to ``near * (1 -
#: NEAR_MARGIN)`` (relative, in (0, 1)): 0.1 % below the eigenvalue the transformed
#: spectrum separates by a factor of about ten per 1 % gap between the two lowest loads,
#: so a few restarts converge (:doc:`/verification/tuning`).
NEAR_MARGIN = 1e-3
#: Krylov vectors of a shifted solve (>= 2): the wanted pair dominates after the shift.
NEAR_NCV = 4
#: Krylov vectors of the second try of a solve at target 0 that converged no pair (of a
#: definite pencil, :meth:`GEPSolver._wider_pair`), at least; twice the first try's if
#: that is more: a cluster of loads near the smallest can keep the default subspace from
#: converging, a wider one separates them (a filled tube's case:
#: docs/history/2026-11-30c-sections.md).
WIDER_NCV = 32
#: A returned pair :math:`(\lambda, x)` of a definite pencil is none when the Rayleigh
#: quotient :math:`\rho(x) = x^TAx / x^TBx` differs from :math:`\lambda` by more than this,
#: relatively (or :data:`~unibuckle_fenicsx.tolerances.SMALLEST_RTOL_FACTOR` times a
#: looser ``eps_tol``). An eigenpair's agree to second order in the vector's error, even
#: where the vector mixes a cluster of nearly equal loads; Krylov-Schur in shift-and-invert
#: measures the error in the B-norm, blind to the null space of a semidefinite B, and
#: its spurious pairs' differ by far more. The constant sits between the two
#: (docs/history/2026-11-30g-spurious.md holds both).
SPURIOUS_RTOL = 1e-2
#: Krylov vectors of the solve again after such a pair (or a negative load), at least: a
#: pencil whose B has lost most of its rank to the removed rows needs more than
#: :data:`WIDER_NCV` (docs/history/2026-11-30g-spurious.md).
SPURIOUS_NCV = 64

#: The smallest eigenpair of the whole pencil given estimates of its lowest eigenvalues
#: (:meth:`GEPSolver.smallest`; a coarser mesh's) shifts first to ``FREE_ABOVE`` above the
#: estimate of the lowest and at most ``FREE_GAP_SHARE`` of the way to the second: above
#: the lowest eigenvalue (a coarse mesh's load lies above the fine one, or within a few
#: tenths of a percent below it), below the second, so that the inertia of one
#: factorisation proves the pair the smallest. Each later try lies further below the
#: estimate (``FREE_BELOW``, times the estimate).
FREE_ABOVE = 0.01
FREE_GAP_SHARE = 1.0 / 3.0
FREE_BELOW = (0.99, 0.96, 0.84)
#: The free solve asks for as many pairs as the inertia counts eigenvalues below its
#: shift, up to this many (a long plate's lowest loads lie within a percent or two of
#: each other, closer than the coarse mesh's error); more, and the shift is lowered.
FREE_MAX_BELOW = 8
#: Krylov subspace of the free solve's shifted Krylov-Schur: a shift within a few percent
#: of the lowest eigenvalue separates it from the second by a factor of five or more, and
#: a few solves converge.
FREE_NCV = 4

#: Default options of :func:`extreme_eigenvalues` (the smallest eigenvalue uses them all;
#: the largest only ``eps_type`` and ``eps_max_it``).
EXTREME_OPTIONS: dict[str, str | float | int | bool] = {
    "eps_type": "krylovschur",
    "eps_max_it": 2000,
    "st_ksp_type": "preonly",
    "st_pc_type": "lu",
    "st_pc_factor_mat_solver_type": "mumps",
}


@dataclass(frozen=True)
class EigenPair:
    r"""Smallest eigenpair of a (reduced) pencil (the vector is written to the caller's).

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


@dataclass(frozen=True)
class SmallestProof:
    r"""Why an eigenpair is the smallest of its pencil: the inertia of one factorisation.

    Sylvester's law of inertia (A positive definite): :math:`A - \sigma B` has as many
    negative eigenvalues as the pencil has eigenvalues in :math:`(0, \sigma)`.

    Attributes:
        shift: :math:`\sigma` of the factorisation that proves it.
        below: Eigenvalues of the pencil below ``shift`` by that inertia: 1 when the
            shift lies above the pair's eigenvalue (no other lies below the shift), 0
            when it lies at or just below it (none lies lower).
        shifts: Every shift factorised, in order (the last is ``shift``).
        solves: Eigen solves (Krylov-Schur runs) it took.
    """

    shift: float
    below: int
    shifts: tuple[float, ...]
    solves: int


#: Ratio to which the inertias of :meth:`GEPSolver._by_inertia` bracket the smallest
#: load before the shifted solve, whose shift then lies 0.1 % to 0.2 % below that load
#: and no other load (as :data:`NEAR_MARGIN` of a solve near an estimate).
INERTIA_BRACKET = 1.001


def _is_zero(B: PETSc.Mat) -> bool:
    """Whether B has no non-zero entry (collective)."""
    return bool(B.norm(PETSc.NormType.INFINITY) == 0.0)  # type: ignore[arg-type]


def _negative(eps: SLEPc.EPS) -> bool:
    """Whether the first converged eigenvalue of ``eps`` is not positive (collective)."""
    return eps.getConverged() >= 1 and eps.getEigenvalue(0).real <= 0.0


def _no_load(out: PETSc.Vec | None, iterations: int, converged: int) -> EigenPair:
    """The pair of a pencil with no finite load: ``inf``, its vector (into ``out``) zero."""
    if out is not None:
        out.zeroEntries()
    return EigenPair(float("inf"), 0.0, iterations, converged)


#: The spectral transformation's solves must be exact: a KSP "preonly" with one of these.
DIRECT_PCS = ("lu", "cholesky")


def _require_direct_solve(eps: SLEPc.EPS, prefix: str) -> None:
    r"""Refuse an iterative solve in the spectral transformation (options from the user).

    The inverse of :math:`A - \sigma B` is applied inside Krylov-Schur and its
    factorisation's inertia proves which eigenvalue is the smallest: an inexact inner
    solve (e.g. ``-<prefix>st_ksp_type gmres -<prefix>st_pc_type jacobi``) stops with
    "KSPSolve has not converged", and SLEPc then fails in its clean-up with "Operation
    done in wrong order". Raises :class:`~unibuckle_fenicsx.errors.InputError` naming the
    options; the caller destroys the EPS.
    """
    ksp = eps.getST().getKSP()
    ksp_type, pc_type = ksp.getType(), ksp.getPC().getType()
    if ksp_type == "preonly" and pc_type in DIRECT_PCS:
        return
    raise InputError(
        f"-{prefix}st_ksp_type {ksp_type} -{prefix}st_pc_type {pc_type}: the eigen solver's "
        "shift-and-invert here needs a direct factorisation (an iterative inner solve is "
        "inexact, and so are the transformed spectrum and the eigenvalue; it stops with "
        f"'KSPSolve has not converged'): give -{prefix}st_ksp_type preonly with "
        f"-{prefix}st_pc_type {' or '.join(DIRECT_PCS)} (the default: lu with MUMPS)"
    )


def _agrees(A: PETSc.Mat, B: PETSc.Mat, x: PETSc.Vec, value: float, tol: float) -> bool:
    """Whether ``x``'s Rayleigh quotient x·Ax / x·Bx is the load ``value`` (collective).

    Within :data:`SPURIOUS_RTOL` (relative), or a thousand times the solve's tolerance
    ``tol`` if that is looser; never for a vector on which B is not positive.
    """
    y = A.createVecLeft()
    try:
        A.mult(x, y)
        stiffness = float(x.dot(y).real)
        B.mult(x, y)
        geometric = float(x.dot(y).real)
    finally:
        y.destroy()
    rtol = max(SPURIOUS_RTOL, SMALLEST_RTOL_FACTOR * tol)
    return bool(geometric > 0.0 and abs(stiffness / geometric - value) <= rtol * value)


def _residual(A: PETSc.Mat, B: PETSc.Mat, x: PETSc.Vec, value: float) -> float:
    r"""The pair's relative residual :math:`\|Ax-\lambda Bx\|/(|\lambda|\|x\|)` (collective).

    As SLEPc's ``computeError`` with its default relative error.
    """
    ax, bx = A.createVecLeft(), B.createVecLeft()
    try:
        A.mult(x, ax)
        B.mult(x, bx)
        ax.axpy(-value, bx)
        return float(ax.norm() / (abs(value) * x.norm()))  # type: ignore[operator]
    finally:
        ax.destroy()
        bx.destroy()


def spurious_pair(eps: SLEPc.EPS, index: int = 0) -> bool:
    """Whether pair ``index`` of ``eps`` is none of its definite pencil (collective).

    A load that is not positive, or one its vector's Rayleigh quotient disagrees
    with beyond :data:`SPURIOUS_RTOL` (relative; a thousand times the EPS's
    tolerance if that is looser). False when that pair did not converge. Every
    solve of the pencil (A, B), B semidefinite, is checked so: at target 0, near
    an estimate (:meth:`GEPSolver.solve`, :meth:`GEPSolver.lowest_pairs`) and the free one
    (:class:`SmallestSearch`). The swapped pencil's solves (``indefinite``,
    :func:`swapped_eigenpairs`) measure in the norm of A, positive definite, and
    need no check.
    """
    if eps.getConverged() <= index:
        return False
    value = eps.getEigenvalue(index).real
    if not value > 0.0:
        return True
    A, B = eps.getOperators()
    x = A.createVecRight()
    try:
        eps.getEigenvector(index, x)
        return not _agrees(A, B, x, value, eps.getTolerances()[0])
    finally:
        x.destroy()


def _swapped_pair(
    eps: SLEPc.EPS, prefix: str, out: PETSc.Vec | None, ncv: int, value: float, error: float
) -> EigenPair:
    r"""The least load from the swapped pencil :math:`Bx = \theta Ax`, checked.

    The last resort after :meth:`GEPSolver._wider_pair` returned a pair that is none of the
    pencil (``value``, ``error`` its load and residual, for the message): the same
    reduced pencil (``eps``'s operators) with A, positive definite, in the inner-product
    slot and the largest :math:`\theta = 1/\lambda` wanted (spectral transformation
    "shift", options prefix ``<prefix>swapped_``, :func:`swapped_eigenpairs`). Its
    largest eigenvalue is
    well separated wherever B has lost most of its rank (the removed rows' zero
    eigenvalues lie at the other end of its spectrum). Its pair is kept only if its
    Rayleigh quotient agrees with it (:func:`_agrees`); otherwise raises
    :class:`EigenSolveError`. Collective.
    """
    A, B = eps.getOperators()
    tol = eps.getTolerances()[0]
    largest = SLEPc.EPS.Which.LARGEST_REAL
    pairs = swapped_eigenpairs(
        A, B, prefix + "swapped_", which=largest, tol=tol, vectors=True, ncv=ncv
    )
    try:
        for theta, vec in pairs[:1]:
            if vec is not None and theta > 0.0 and _agrees(A, B, vec, 1.0 / theta, tol):
                if out is not None:
                    vec.copy(out)
                its = int(eps.getIterationNumber())
                residual = _residual(A, B, vec, 1.0 / theta)
                return EigenPair(1.0 / theta, residual, its, len(pairs))
    finally:
        for _, vec in pairs:
            if vec is not None:
                vec.destroy()
    raise EigenSolveError(
        f"SLEPc ({prefix}) returned a pair that is not an eigenpair of the "
        f"definite pencil (load {value:.6g}, relative residual {error:.3g}) with {ncv} "
        f"Krylov vectors, nor did the swapped pencil (-{prefix}swapped_*); try a "
        f"larger -{prefix}eps_ncv"
    )


class ShiftedSolves(Owner):
    r"""The solves of a :class:`GEPSolver`'s pencils at a shift, through the shared :math:`LDL^T`.

    One MUMPS :math:`LDL^T` of the mesh (:attr:`factorization`, made on first use) and
    the two Krylov-Schur EPS that solve with it (the solves near an estimate,
    :meth:`near_eps`, and the smallest pair's, :meth:`free_eps`): the pencil shifted to
    :math:`\sigma` is factorised once (:meth:`shift_to`), and its inertia counts the
    eigenvalues below :math:`\sigma` (Sylvester's law).

    Args:
        A: The stiffness matrix (owned by the caller), whose pattern the factorisation has.
        main: The solver's EPS at target 0 (owned by the solver): the shifted EPS take its
            tolerance.
        prefix: The solver's options prefix.
        options: The solver's options (the smallest pair's EPS takes them).
        indefinite: B is indefinite: the swapped pencil is shifted.
        reused: As :class:`GEPSolver`'s.

    Attributes:
        free_ncv: Krylov vectors of the smallest pair's EPS for one pair (the options').

    Note:
        Collective on ``A.comm``. The solver owns it and destroys it.
    """

    def __init__(
        self,
        A: PETSc.Mat,
        main: SLEPc.EPS,
        prefix: str,
        options: Options,
        indefinite: bool,
        reused: bool,
    ) -> None:
        self.A, self.main, self.prefix, self.options = A, main, prefix, options
        self.indefinite, self.reused = indefinite, reused
        self._near: SLEPc.EPS | None = None  # the shifted solves' EPS, made when needed
        self._free: SLEPc.EPS | None = None  # the smallest pair's EPS, made when needed
        self.free_ncv = FREE_NCV
        self._ldl: SharedFactorization | None = None  # made when needed

    def count_below(self, A: PETSc.Mat, B: PETSc.Mat, shift: float) -> int:
        r"""Negative pivots of :math:`A - \sigma B` (one numeric :math:`LDL^T`). Collective."""
        ldl = self.factorization
        same, subset = PETSc.Mat.Structure.SAME_NONZERO_PATTERN, PETSc.Mat.Structure.SUBSET
        A.copy(ldl.matrix, structure=same)  # type: ignore[arg-type]
        ldl.matrix.axpy(-shift, B, structure=subset)  # type: ignore[arg-type]
        negative, _, _ = ldl.factor(self)
        return int(negative)

    @property
    def factorization(self) -> SharedFactorization:
        """The mesh's :class:`SharedFactorization` (prefix ``<prefix>ldl_``), made on first use.

        The shifted solves factorise through it, and so do the interior-point method and
        the certificate on the same problem: one symbolic analysis per mesh.
        """
        if self._ldl is None:
            self._ldl = SharedFactorization(self.A, self.prefix + "ldl_", self.reused)
        return self._ldl

    def near_eps(self) -> SLEPc.EPS:
        """The shifted solves' EPS (prefix ``<prefix>near_``), made on first use."""
        if self._near is None:
            self._near = self._eps(self.prefix + "near_", NEAR_NCV)
        return self._near

    def _eps(self, prefix: str, ncv: int) -> SLEPc.EPS:
        """A Krylov-Schur EPS whose spectral transformation solves with the shared LDLᵀ.

        Its spectral transformation shifts the first operator in place and solves with
        the :attr:`factorization`'s KSP: the operator passed is that factorisation's
        matrix, filled by :meth:`shift_to` before each solve. It takes the EPS options
        (not the ``st_`` ones: its solver is the shared one) under ``prefix``: the
        solver's ``options`` under its own prefix (the smallest pair's EPS), else
        :data:`EIGEN_OPTIONS`'s. The shifted solves (``<prefix>near_``), which recover from
        a failed solve at target 0 (:meth:`GEPSolver._by_inertia`), take an option given for the
        solver's prefix (in Python or on the command line) by its tolerance only: an
        iteration limit meant for the first solve leaves the recovery alone.
        """
        eps = SLEPc.EPS().create(self.A.comm)
        eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
        eps.setDimensions(1, ncv)
        eps.setTolerances(self.main.getTolerances()[0])
        eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_REAL)
        st = eps.getST()
        st.setType(SLEPc.ST.Type.SINVERT)
        given = self.options if prefix == self.prefix else EIGEN_OPTIONS
        eps_only = {k: v for k, v in given.items() if not k.startswith("st_")}
        set_options(eps, prefix, eps_only)
        st.setMatMode(SLEPc.ST.MatMode.INPLACE)
        st.setMatStructure(PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        st.setKSP(self.factorization.ksp)
        return eps

    def shift_to(
        self, eps: SLEPc.EPS, A: PETSc.Mat, B: PETSc.Mat, shift: float, initial: PETSc.Vec | None
    ) -> int:
        r"""Factorise the pencil (A, B) shifted to ``shift`` for ``eps``; eigenvalues below it.

        The first operator goes into the shared matrix (A's pattern), which the spectral
        transformation shifts in place and factorises (numeric only, after the first
        analysis): :math:`A - \sigma B`, or for the swapped pencil :math:`B - A/\sigma`,
        whose positive eigenvalues count the pencil's eigenvalues in :math:`(0,
        \sigma)`. Returns that count (the inertia). Collective.
        """
        ldl = self.factorization
        if self.indefinite:
            ldl.matrix.zeroEntries()
            ldl.matrix.axpy(1.0, B, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)  # type: ignore[arg-type]
            eps.setOperators(ldl.matrix, A)
            eps.setTarget(1.0 / shift)
        else:
            A.copy(ldl.matrix, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)  # type: ignore[arg-type]
            eps.setOperators(ldl.matrix, B)
            eps.setTarget(shift)
        if initial is not None:
            eps.setInitialSpace([initial])
        eps.setUp()
        ldl.claim(self)
        negative, _, positive = ldl.inertia()
        return int(positive if self.indefinite else negative)

    def solve_below(
        self, A: PETSc.Mat, B: PETSc.Mat, near: float, initial: PETSc.Vec | None
    ) -> bool:
        r"""Solve at the shift :data:`NEAR_MARGIN` below ``near``; whether that answers.

        False when the inertia of :math:`A - \sigma B` (the shared
        :attr:`factorization`) shows an eigenvalue below the shift :math:`\sigma` (the
        pair found would be the nearest to it, not necessarily the smallest), or when
        nothing converged. Collective.
        """
        eps = self.near_eps()
        if self.shift_to(eps, A, B, near * (1.0 - NEAR_MARGIN), initial) != 0:
            return False
        eps.solve()
        return eps.getConverged() >= 1

    def free_eps(self) -> SLEPc.EPS:
        """The smallest pair's EPS (prefix ``<prefix>``, :data:`FREE_NCV`), made on first use."""
        if self._free is None:
            self._free = self._eps(self.prefix, FREE_NCV)
            self.free_ncv = int(self._free.getDimensions()[1])
        return self._free

    def lowest_pairs(
        self, A: PETSc.Mat, B: PETSc.Mat, near: float, count: int, start: PETSc.Vec | None
    ) -> list[tuple[EigenPair, PETSc.Vec]] | None:
        """The ``count`` smallest pairs of (A, B) by one solve :data:`NEAR_MARGIN` below ``near``.

        None when the inertia shows an eigenvalue below the shift (nothing solved); after
        the solve, empty when fewer pairs converge or one is none of the pencil
        (:func:`spurious_pair`). See :meth:`GEPSolver.lowest_pairs`. Collective.
        """
        eps = self.near_eps()
        nev, ncv, mpd = eps.getDimensions()
        eps.setDimensions(count, max(ncv, 2 * count + 2))
        try:
            below = self.shift_to(eps, A, B, near * (1.0 - NEAR_MARGIN), start)
            if below != 0:
                return None
            eps.solve()
            if eps.getConverged() < count:
                return []
            if not self.indefinite and any(spurious_pair(eps, k) for k in range(count)):
                return []  # a pair that is none of the pencil proves nothing
            its = int(eps.getIterationNumber())
            pairs: list[tuple[EigenPair, PETSc.Vec]] = []
            for k in range(count):
                vec = A.createVecRight()
                eps.getEigenvector(k, vec)
                theta = eps.getEigenvalue(k).real
                value = 1.0 / theta if self.indefinite else theta
                pair = EigenPair(float(value), float(eps.computeError(k)), its, count)
                pairs.append((pair, vec))
        finally:
            eps.setDimensions(nev, ncv, mpd)
        return sorted(pairs, key=lambda p: p[0].value)

    def solve_by_inertia(self, A: PETSc.Mat, B: PETSc.Mat, radius: float) -> bool:
        r"""Bracket the swapped pencil's smallest load by inertias, then solve below it.

        A relative tolerance cannot be met by eigenvalues that are round-off (a load that
        does not buckle the plate on this mesh, as a steep stress gradient on a coarse
        mesh), nor always by a small one in a cluster, and an eigen solve with an
        absolute tolerance need not converge either. The inertia of :math:`B - A/\sigma`
        (one :math:`LDL^T` through the shared :attr:`factorization`) counts the loads in
        :math:`(0, \sigma)` with no eigen solve: none below :math:`\sigma = 10^{10}/r`
        (r = ``radius``, the spectral radius of :math:`A^{-1}B`, the round-off ceiling of
        :meth:`GEPSolver._is_roundoff`) means no finite load: False (nothing solved).
        Else geometric bisection between :math:`1/2r`, below every load, and that ceiling
        brackets the smallest load to a ratio of :data:`INERTIA_BRACKET`, and the
        :meth:`near_eps` shifted :data:`NEAR_MARGIN` below the bracket (no load below
        it) solves for it, the nearest to the shift: True. Collective.
        """
        eps = self.near_eps()
        # Every load is at least 1/r; the radius is converged to 1e-6 only, hence 1/2r.
        low, high = 0.5 / radius, 1e10 / radius
        if self.shift_to(eps, A, B, high, None) == 0:
            return False
        while high > low * INERTIA_BRACKET:
            middle = float(np.sqrt(low * high))
            if self.shift_to(eps, A, B, middle, None) == 0:
                low = middle
            else:
                high = middle
        # Just below the bracket (a shift may sit on a load within MUMPS's null pivot
        # threshold, counted as none below): the nearest load above is the smallest.
        self.shift_to(eps, A, B, low * (1.0 - NEAR_MARGIN), None)
        eps.solve()
        return True

    def destroy(self) -> None:
        """Destroy the EPS and the factorisation (collective)."""
        release(self, "_near", "_free", "_ldl")

    def __del__(self) -> None:
        self.destroy()


class GEPSolver(Owner):
    """Smallest eigenpair of :math:`(A, B)` with optional removed DOFs.

    Args:
        A: Stiffness matrix, SPD (owned by the caller; not modified; its values may
            change between solves, see :meth:`operators_changed`).
        B: Geometric stiffness matrix (owned by the caller; not modified, and not
            changed afterwards: the solver keeps a
            :func:`~unibuckle_fenicsx.la.factor.compact` copy, ``B``).
        indefinite: B is indefinite: solve the swapped pencil.
        prefix: Options prefix, non-empty; ``-<prefix>eps_view`` and friends apply.
        tol: EPS tolerance.
        options: Options pushed under ``prefix`` (default :data:`EIGEN_OPTIONS`).
        reused: Many solves will follow (the contact sets of a route): the analyses of
            its factorisations serve many numeric ones, which orders them by METIS from
            fewer rows (:func:`~unibuckle_fenicsx.la.options.mumps_ordering`). False for
            the free plate alone.

    Attributes:
        solves: Eigen solves performed so far.

    Note:
        Collective on ``A.comm``. The owner must :meth:`destroy` it.
    """

    def __init__(
        self,
        A: PETSc.Mat,
        B: PETSc.Mat,
        *,
        indefinite: bool = False,
        prefix: str = Prefix.EIGEN,
        tol: float = 1e-10,
        options: Options | None = None,
        reused: bool = True,
    ) -> None:
        if not prefix:
            raise ValueError("GEPSolver needs a non-empty options prefix")
        self.reused = reused
        self.A = A
        self.B = compact(B)  # owned: its products cost a fifth of B's
        self.indefinite = indefinite
        self._norm_ratio: float | None = None
        self._radius: float | None = None
        self._Bx: PETSc.Vec | None = None
        self.prefix = prefix
        self.tol = tol
        self._Aw: PETSc.Mat | None = None
        self._Bw: PETSc.Mat | None = None
        self.solves = 0

        eps = SLEPc.EPS().create(A.comm)
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
        self._options = dict(EIGEN_OPTIONS if options is None else options)
        set_options(eps, prefix, self._options)
        self.eps = eps
        try:
            _require_direct_solve(eps, prefix)
        except InputError:
            self.destroy()  # collective: every rank reads the same options
            raise
        self.shifted = ShiftedSolves(A, eps, prefix, self._options, indefinite, reused)
        self.shifted_solves = 0  # solves at a shift below an estimate (near=...)
        self.unshifted_again = 0  # ... of which an eigenvalue lay below the shift

    def reduced(self, removed: npt.NDArray[np.int64]) -> tuple[PETSc.Mat, PETSc.Mat]:
        """The pencil with the global rows ``removed`` zeroed (diagonal 1 in A, 0 in B).

        Returns work matrices owned by the solver, valid until the next call.

        Note:
            Collective; every rank passes its owned rows (possibly none).
        """
        same = PETSc.Mat.Structure.SAME_NONZERO_PATTERN
        if self._Aw is None:
            self._Aw = self.A.duplicate(copy=True)
            self._Bw = self.B.duplicate(copy=True)
        else:
            self.A.copy(self._Aw, structure=same)  # type: ignore[arg-type]
            self.B.copy(self._Bw, structure=same)  # type: ignore[arg-type]
        if self._Bw is None:
            raise RuntimeError("reduced: expected self._Bw is not None (an internal invariant)")
        rows = np.ascontiguousarray(removed, dtype=PETSc.IntType)
        self._Aw.zeroRowsColumns(rows, diag=1.0)  # type: ignore[arg-type]
        self._Bw.zeroRowsColumns(rows, diag=0.0)  # type: ignore[arg-type]
        return self._Aw, self._Bw

    def solve(
        self,
        removed: npt.NDArray[np.int64] | None = None,
        out: PETSc.Vec | None = None,
        initial: PETSc.Vec | None = None,
        near: float | None = None,
    ) -> EigenPair:
        """Smallest eigenpair with the DOFs ``removed`` set to zero.

        Args:
            removed: Global row indices owned by this rank to remove (may be empty on
                some ranks; every rank must call).
            out: Vector receiving the eigenvector (B-normalised by SLEPc).
            initial: Optional start vector (e.g. the previous mode).
            near: Optional estimate of the eigenvalue (the same on every rank): a
                second EPS (options prefix ``<prefix>near_``) shifts to
                :data:`NEAR_MARGIN` below it, and its factorisation's inertia
                (:attr:`factorization`, prefix ``<prefix>ldl_``) proves that no
                eigenvalue lies below the shift; if one does (or nothing converges, or
                its pair is none of the pencil), the solve at target 0 runs instead.

        Returns:
            The eigenpair, with value ``inf`` when no finite load exists (the removed DOFs
            leave no geometric stiffness, or it is nowhere positive); raises
            :class:`EigenSolveError` if SLEPc converged no pair or returned a non-positive
            or non-finite load.

        Note:
            Collective.
        """
        # Always the work copies, even with nothing removed: the factorisation of the
        # shift-and-invert then keeps one matrix, whose symbolic analysis serves every
        # solve (the free plate's and each contact set's).
        A, B = self.reduced(np.empty(0, np.int64) if removed is None else removed)
        if _is_zero(B):
            # Every DOF carrying geometric stiffness is removed: no finite load.
            return _no_load(out, 0, 0)
        start = initial if initial is not None and self._useful_start(initial, B) else None
        eps = self._run(A, B, start, near)
        self.solves += 1
        if eps is not self.eps and not self.indefinite and spurious_pair(eps):
            # The shifted solve's pair is none of the pencil (its load may even lie below
            # the least, under the shift's inertia): the solve at target 0 from SLEPc's
            # own start, checked below as every other.
            logger.debug("%s: no eigenpair from the shifted solve (%.6g); at 0 instead",
                         self.prefix, eps.getEigenvalue(0).real)  # fmt: skip
            self.unshifted_again += 1
            start = None
            eps = self._run(A, B, None, None)
            self.solves += 1
        if eps is self.eps and not self.indefinite and eps.getConverged() < 1:
            return self._wider_pair(start, out)
        if start is not None and eps is self.eps and not self.indefinite and _negative(eps):
            # A definite pencil has no negative load: a start vector outside the reduced
            # space (the last mode, nonzero on rows now removed) can leave SLEPc a
            # spurious one; the same solve from SLEPc's own start.
            logger.debug("%s: a negative load from the start vector; again without it",
                         self.prefix)  # fmt: skip
            eps = self._run(A, B, None, None)
            self.solves += 1
            if eps.getConverged() < 1:
                return self._wider_pair(None, out)
        if eps is self.eps and not self.indefinite and spurious_pair(eps):
            # A negative load, or one its vector's Rayleigh quotient contradicts, is no eigenpair
            # of a definite pencil: Krylov-Schur in shift-and-invert, on a pencil whose B
            # has lost most of its rank to the removed rows (a section with most of its
            # wall on the core), returns one from any start; a wider subspace finds a pair.
            logger.debug("%s: no eigenpair (%.6g, relative residual %.3g); again wider",
                         self.prefix, eps.getEigenvalue(0).real, eps.computeError(0))  # fmt: skip
            return self._wider_pair(None, out, SPURIOUS_NCV)
        return self._pair(eps, out)

    def _wider_pair(
        self, initial: PETSc.Vec | None, out: PETSc.Vec | None, least: int = WIDER_NCV
    ) -> EigenPair:
        """The solve at target 0 once more, in a wider subspace (:data:`WIDER_NCV`).

        A cluster of loads near the smallest (a tube's, with a contact set holding most of
        its wall) can keep the default subspace from converging within ``eps_max_it``
        restarts; a wider one separates them. ``least``: the fewest Krylov vectors.
        Raises as :meth:`_pair` if it fails too, and if its pair is none
        (:func:`spurious_pair`). Collective.
        """
        eps = self.eps
        nev, ncv, mpd = eps.getDimensions()
        wider = max(2 * ncv, least)  # never the same subspace again
        logger.debug("%s: again with ncv = %d", self.prefix, wider)
        eps.setDimensions(nev, wider, wider)
        try:
            if initial is not None:
                eps.setInitialSpace([initial])
            eps.solve()
            self.solves += 1
            if spurious_pair(eps):
                value, error = eps.getEigenvalue(0).real, eps.computeError(0)
                logger.debug("%s: no eigenpair with %d Krylov vectors (%.6g); swapped",
                             self.prefix, wider, value)  # fmt: skip
                return _swapped_pair(eps, self.prefix, out, wider, value, error)
            return self._pair(eps, out)
        finally:
            eps.setDimensions(nev, ncv, mpd)

    def _run(
        self, A: PETSc.Mat, B: PETSc.Mat, initial: PETSc.Vec | None, near: float | None
    ) -> SLEPc.EPS:
        """Solve the reduced pencil (A, B): shifted below ``near`` if that answers, else at 0."""
        if near is not None and near > 0.0:
            if self.shifted.solve_below(A, B, near, initial):
                self.shifted_solves += 1
                return self.shifted.near_eps()
            self.unshifted_again += 1
            logger.debug("%s: an eigenvalue below %.6g; solved at 0", self.prefix, near)
        eps = self.eps
        if self.indefinite:
            eps.setOperators(B, A)
        else:
            eps.setOperators(A, B)
        if initial is not None:
            eps.setInitialSpace([initial])
        # The ordering, read at the first (symbolic) factorisation of the LU.
        key = "st_mat_mumps_icntl_7"
        with option_defaults(self.prefix, ordering_options(A, key, reused=self.reused)):
            eps.solve()
        return eps

    def _pair(self, eps: SLEPc.EPS, out: PETSc.Vec | None) -> EigenPair:
        """The converged pair of ``eps`` (its vector into ``out``), or a load of ``inf``."""
        nconv = eps.getConverged()
        its = eps.getIterationNumber()
        if nconv < 1 and self.indefinite:
            found = self._by_inertia(out)
            if found is not None:
                return found
        if nconv < 1:
            reason = eps.getConvergedReason()
            raise EigenSolveError(
                f"SLEPc ({self.prefix}) converged no eigenpair after {its} iterations "
                f"(reason {reason}, tol {eps.getTolerances()[0]:.1e}); try "
                f"-{self.prefix}eps_max_it or a looser -{self.prefix}eps_tol"
            )
        theta = eps.getEigenvalue(0).real
        if self.indefinite and self._is_roundoff(theta):
            # No eigenvalue of B x = theta A x is distinguishable from zero above it: the
            # geometric stiffness is nowhere positive on this space, no finite load.
            return _no_load(out, int(its), int(nconv))
        value = 1.0 / theta if self.indefinite else theta
        if not np.isfinite(value) or value <= 0.0:
            raise EigenSolveError(
                f"SLEPc ({self.prefix}) returned a non-positive load {value!r}: the "
                "pencil has no buckling load under a positive load factor"
            )
        if out is not None:
            eps.getEigenvector(0, out)
        error = eps.computeError(0)
        return EigenPair(float(value), float(error), int(its), int(nconv))

    def lowest_pairs(
        self,
        removed: npt.NDArray[np.int64],
        near: float,
        count: int,
        initial: PETSc.Vec | None = None,
    ) -> list[tuple[EigenPair, PETSc.Vec]]:
        """The ``count`` smallest eigenpairs with the DOFs ``removed`` set to zero.

        Solved as :meth:`solve` with ``near`` (the shared factorisation at the shift
        :data:`NEAR_MARGIN` below ``near``, one eigen solve), for ``count`` pairs, in
        ascending order of load; the vectors are the caller's to destroy. Empty when the
        inertia shows an eigenvalue below the shift, fewer pairs converge or one is none
        of the pencil (:func:`spurious_pair`): the pairs returned are then proven the smallest.

        Args:
            removed: Global row indices owned by this rank to remove.
            near: An estimate of the smallest eigenvalue (> 0, the same on every rank).
            count: Pairs wanted, >= 1.
            initial: Optional start vector.

        Note:
            Collective.
        """
        A, B = self.reduced(removed)
        if _is_zero(B):
            return []
        start = initial if initial is not None and self._useful_start(initial, B) else None
        pairs = self.shifted.lowest_pairs(A, B, near, count, start)
        if pairs is not None:
            self.solves += 1
            self.shifted_solves += 1
        return pairs or []

    @property
    def factorization(self) -> SharedFactorization:
        """The mesh's :class:`SharedFactorization`: :attr:`ShiftedSolves.factorization`."""
        return self.shifted.factorization

    def count_below(self, shift: float) -> int:
        r"""Eigenvalues of the whole pencil in :math:`(0, \sigma)`, by an inertia.

        The inertia of :math:`A - \sigma B` (Sylvester's law, A positive definite): one
        numeric :math:`LDL^T` through the shared :attr:`factorization`. Negative pivots
        only: a null one means an eigenvalue within MUMPS's null-pivot threshold of
        :math:`\sigma`, which on a small or stiff pencil is the computed eigenvalue
        itself. Collective.
        """
        return self.shifted.count_below(self.A, self.B, shift)

    def smallest(
        self, out: PETSc.Vec | None = None, estimate: tuple[float, ...] = ()
    ) -> tuple[EigenPair, SmallestProof | None]:
        """The smallest eigenpair of the whole pencil (nothing removed), with its proof.

        Proven by the inertia of shifts near ``estimate`` (:class:`SmallestSearch`);
        without an estimate, or if no shift proves it, the pair at target 0 (a MUMPS
        LU), unproven: the caller checks it (:meth:`count_below`).

        Args:
            out: Vector receiving the eigenvector.
            estimate: Estimates of the lowest eigenvalues, ascending (empty: none).

        Returns:
            The pair (as :meth:`solve`'s) and its proof, or None for the pair at target 0.

        Note:
            Collective.
        """
        return SmallestSearch(self, estimate).run(out)

    def operators_changed(self) -> None:
        """Forget the scales cached from A and B (call after changing them in place)."""
        self._norm_ratio = None
        self._radius = None

    def _useful_start(self, initial: PETSc.Vec, B: PETSc.Mat) -> bool:
        """Whether ``initial`` has a component SLEPc can start from (B x != 0).

        A start vector that the pencil's B annihilates (the zero mode of a set with no
        finite load, or a mode living on removed DOFs only) is refused by SLEPc
        ("initial vector is zero"); the solve then starts from its default vector.
        Collective.
        """
        if self._Bx is None:
            self._Bx = B.createVecLeft()
        B.mult(initial, self._Bx)
        return bool(self._Bx.norm() > 0.0)  # type: ignore[operator]

    def _by_inertia(self, out: PETSc.Vec | None) -> EigenPair | None:
        r"""After a failed solve of :math:`B x = \theta A x`: the smallest load, by inertias.

        A relative tolerance cannot be met by eigenvalues that are round-off, nor always
        by a small one in a cluster: :meth:`ShiftedSolves.solve_by_inertia`, with r the
        spectral radius of :math:`A^{-1}B` (the round-off ceiling of :meth:`_is_roundoff`).
        None if that solve converges no pair. Collective.
        """
        B, A = self.eps.getOperators()
        eps = self.shifted.near_eps()
        radius = self._spectral_radius()
        if not self.shifted.solve_by_inertia(A, B, radius):
            return _no_load(out, int(self.eps.getIterationNumber()), 0)
        self.solves += 1
        if eps.getConverged() < 1:
            return None
        return self._pair(eps, out)

    def _is_roundoff(self, theta: float) -> bool:
        """Whether theta (= 1/lambda) is at most 1e-10 of the spectral radius of A^-1 B.

        Round-off in theta is about 1e-16 of that radius. Only values below 1e-4 of
        ||B||/||A|| (the order of 1/lambda for a plate with t/b <= 0.1 is far above) pay
        for the radius (one eigen solve, then cached). Collective.
        """
        if self._norm_ratio is None:
            inf = PETSc.NormType.INFINITY
            b_norm = float(self.B.norm(inf))  # type: ignore[arg-type]
            a_norm = float(self.A.norm(inf))  # type: ignore[arg-type]
            self._norm_ratio = b_norm / a_norm
        if theta > 1e-4 * self._norm_ratio:
            return False
        return theta <= 1e-10 * self._spectral_radius()

    def _spectral_radius(self) -> float:
        """The largest |theta| of B x = theta A x (relative 1e-6; cached). Collective."""
        if self._radius is None:
            pairs = swapped_eigenpairs(
                self.A, self.B, self.prefix + "radius_", which=SLEPc.EPS.Which.LARGEST_MAGNITUDE
            )
            self.solves += 1
            if not pairs:
                raise EigenSolveError(
                    f"SLEPc ({self.prefix}radius_): the spectral radius of the pencil did "
                    "not converge"
                )
            self._radius = abs(pairs[0][0])
        return self._radius

    def destroy(self) -> None:
        """Destroy the EPS and work matrices (collective)."""
        release(self, "eps", "shifted", "_Aw", "_Bw", "_Bx", "B")

    def __del__(self) -> None:
        self.destroy()


class SmallestSearch:
    r"""The smallest eigenpair of a :class:`GEPSolver`'s whole pencil, with its proof.

    Given ``estimate``, the lowest eigenvalues of a coarser mesh's pencil (ascending,
    the same on every rank), the pencil is factorised once at a shift :math:`\sigma`
    just above the lowest (:data:`FREE_ABOVE`, below the second) by the shared
    :math:`LDL^T`, and Krylov-Schur solves at that target with it. The inertia counts
    the eigenvalues below :math:`\sigma` (Sylvester's law) and proves the pair the
    smallest (:class:`SmallestProof`):

    - k of them (1 to :data:`FREE_MAX_BELOW`): Krylov-Schur asks for the k pairs
      nearest :math:`\sigma` (then 2k + 1, if some lay above it); once k lie below
      it they are every eigenvalue there (B-orthogonal vectors), and the lowest is
      the pencil's smallest (a Ritz value below the shift lies at or below its
      eigenvalue, Rayleigh-Ritz, so the load found is never above it);
    - none: the pair found is the nearest above :math:`\sigma`, and one more
      factorisation just below its eigenvalue (:data:`SMALLEST_RTOL_FACTOR` times the
      tolerance) must show none there either.

    More than :data:`FREE_MAX_BELOW` below :math:`\sigma`, or fewer pairs found below
    it than lie there: the next shift lies below the estimate (``FREE_BELOW``)
    and the pencil is factorised again. If no shift proves it (or nothing converges, or
    a pair is none of the pencil, :func:`spurious_pair`,
    or there is no estimate) the pair comes from :meth:`GEPSolver.solve` at target 0 (a
    MUMPS LU), unproven: the caller checks it (:meth:`GEPSolver.count_below`).

    The EPS (the solver's, made on first use and kept) takes the options under the
    solver's prefix (``-unibuckle_eps_tol``, ``-unibuckle_eps_ncv``, ...; the Krylov
    subspace defaults to :data:`FREE_NCV`), the factorisation those of
    :attr:`GEPSolver.factorization` (``<prefix>ldl_``).

    Args:
        solver: The solver whose pencil (A, B), nothing removed, is searched.
        estimate: Estimates of the lowest eigenvalues, ascending (empty: none).

    Attributes:
        shifts: Every shift factorised so far, in order.

    Note:
        Collective on the solver's communicator.
    """

    def __init__(self, solver: GEPSolver, estimate: tuple[float, ...]) -> None:
        self.solver = solver
        self.estimate = estimate
        self.shifts: list[float] = []
        self.rtol = SMALLEST_RTOL_FACTOR * solver.tol

    def run(self, out: PETSc.Vec | None) -> tuple[EigenPair, SmallestProof | None]:
        """The pair (its vector into ``out``) and its proof, or None for the pair at 0."""
        solver, estimate = self.solver, self.estimate
        solves = solver.solves
        if estimate and estimate[0] > 0.0 and not _is_zero(solver.B):
            lowest = estimate[0]
            above = FREE_ABOVE
            if len(estimate) > 1 and estimate[1] > lowest:
                above = min(above, FREE_GAP_SHARE * (estimate[1] / lowest - 1.0))
            for shift in (lowest * (1.0 + above), *(lowest * f for f in FREE_BELOW)):
                self.shifts.append(shift)
                found = self._at(shift, out)
                if found is None:
                    break  # nothing converged, or a lower eigenvalue was passed over
                pair, below = found
                if pair is not None:
                    shifts = tuple(self.shifts)
                    return pair, SmallestProof(shifts[-1], below, shifts, solver.solves - solves)
            logger.debug("%s: no shift %s proved the smallest pair", solver.prefix, self.shifts)
        return solver.solve(out=out), None

    def _at(self, shift: float, out: PETSc.Vec | None) -> tuple[EigenPair | None, int] | None:
        """One try at ``shift``: (the proven pair or None, count below).

        None when the tries should stop: nothing converged, or the pencil has an
        eigenvalue below the one found and above the shift (Krylov-Schur passed over
        it). Collective.
        """
        solver, rtol = self.solver, self.rtol
        eps = solver.shifted.free_eps()
        below = solver.shifted.shift_to(eps, solver.A, solver.B, shift, None)
        if below > FREE_MAX_BELOW:
            return None, below
        # As many pairs as lie below the shift; then, if pairs above it lay nearer, more.
        for wanted in (below, 2 * below + 1) if below else (1,):
            ncv = max(solver.shifted.free_ncv, 2 * wanted)
            # mpd with ncv: left unset it keeps its first value, below ncv - nev.
            eps.setDimensions(wanted, ncv, ncv)
            eps.solve()
            solver.solves += 1
            loads = [self._load(eps.getEigenvalue(k).real) for k in range(eps.getConverged())]
            if not loads:
                return None
            if not solver.indefinite and any(spurious_pair(eps, k) for k in range(len(loads))):
                return None  # a pair that is none of the pencil: the checked solve at 0
            under = [k for k, load in enumerate(loads) if load <= shift * (1.0 - rtol)]
            if below and len(under) >= below:
                return self._indexed_pair(eps, min(under, key=loads.__getitem__), out), below
        if below:
            return None, below  # pairs nearer the shift lay above it: lower the shift
        pair = self._indexed_pair(eps, 0, out)
        check = pair.value * (1.0 - rtol)
        if check <= shift:
            return pair, below  # the first inertia covers it
        self.shifts.append(check)
        if solver.count_below(check) != 0:
            return None
        return pair, 0

    def _load(self, theta: float) -> float:
        """The load of an eigenvalue of the EPS's pencil (1/theta for the swapped one)."""
        return 1.0 / theta if self.solver.indefinite else theta

    def _indexed_pair(self, eps: SLEPc.EPS, index: int, out: PETSc.Vec | None) -> EigenPair:
        """Converged pair ``index`` of ``eps`` as a load (its vector into ``out``)."""
        value = self._load(eps.getEigenvalue(index).real)
        if out is not None:
            eps.getEigenvector(index, out)
        error = eps.computeError(index)
        return EigenPair(float(value), float(error), eps.getIterationNumber(), eps.getConverged())


def swapped_eigenpairs(
    A: PETSc.Mat,
    B: PETSc.Mat,
    prefix: str,
    *,
    which: Any,
    nev: int = 1,
    tol: float = 1e-6,
    conv: Any = None,
    vectors: bool = False,
    ncv: int | None = None,
) -> list[tuple[float, PETSc.Vec | None]]:
    """Extreme eigenpairs theta of the swapped pencil B x = theta A x (theta = 1/lambda).

    A is positive definite and B may be indefinite (tension somewhere), so this is the
    form every solve with an indefinite B uses: a GHEP with A in the inner-product slot,
    spectral transformation "shift" (one MUMPS LU of A). Its own EPS under ``prefix``,
    destroyed here.

    Args:
        A: Bending stiffness (SPD; not modified).
        B: Geometric stiffness (not modified).
        prefix: Options prefix.
        which: SLEPc ``EPS.Which`` (e.g. ``LARGEST_REAL`` for the lowest positive loads).
        nev: Pairs wanted.
        tol: Tolerance.
        conv: SLEPc ``EPS.Conv`` convergence test (default relative).
        vectors: Also return the eigenvectors (the caller destroys them).
        ncv: Krylov vectors (default SLEPc's); the options may change it.

    Returns:
        The converged pairs (theta, vector or None), at most ``nev``, in SLEPc's order.

    Note:
        Collective.
    """
    with destroyed_after(SLEPc.EPS().create(A.comm)) as eps:
        eps.setOperators(B, A)
        eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
        if ncv is None:
            eps.setDimensions(nev)
        else:
            eps.setDimensions(nev, max(ncv, 2 * nev + 1))
        eps.setWhichEigenpairs(which)
        eps.setConvergenceTest(SLEPc.EPS.Conv.REL if conv is None else conv)
        eps.setTolerances(tol)
        eps.getST().setType(SLEPc.ST.Type.SHIFT)
        set_options(eps, prefix, EIGEN_OPTIONS)
        with option_defaults(prefix, ordering_options(A, "st_mat_mumps_icntl_7")):
            eps.solve()
        pairs: list[tuple[float, PETSc.Vec | None]] = []
        for k in range(min(nev, eps.getConverged())):
            v = A.createVecRight() if vectors else None
            pairs.append((float(eps.getEigenpair(k, v).real), v))
        return pairs


def lowest_eigenvalues(
    A: PETSc.Mat, B: PETSc.Mat, prefix: str, *, count: int = 2, tol: float = 1e-6
) -> tuple[float, ...]:
    r"""The pencil's lowest positive eigenvalues :math:`\lambda` (at most ``count``, ascending).

    For estimates (a coarser mesh's, for :meth:`GEPSolver.smallest`): no proof that they
    are the lowest, and a loose default tolerance (1e-6, far below the few percent by
    which the estimate's mesh differs). The largest :math:`\mu = 1/\lambda` of the
    swapped pencil (:func:`swapped_eigenpairs`, B semidefinite or indefinite alike).

    Args:
        A: Stiffness matrix (SPD; not modified).
        B: Geometric stiffness (not modified).
        prefix: Options prefix.
        count: Eigenvalues wanted.
        tol: EPS tolerance.

    Returns:
        The converged positive eigenvalues (empty if none converged).

    Note:
        Collective.
    """
    pairs = swapped_eigenpairs(A, B, prefix, which=SLEPc.EPS.Which.LARGEST_REAL, nev=count, tol=tol)
    return tuple(sorted(1.0 / theta for theta, _ in pairs if theta > 0.0))


def extreme_eigenvalues(
    mat: PETSc.Mat, prefix: str, options: Options | None = None, tol: float = 1e-8
) -> tuple[float, float]:
    """Smallest and largest eigenvalue of the symmetric matrix ``mat`` (SLEPc, HEP).

    The largest by plain Krylov-Schur, the smallest by shift-and-invert at 0 (a MUMPS
    LU of ``mat``, which must be nonsingular); both under the options prefix ``prefix``.

    Args:
        mat: Symmetric matrix (not modified).
        prefix: Options prefix of both solves.
        options: Options pushed under ``prefix`` (default :data:`EXTREME_OPTIONS`).
        tol: EPS tolerance.

    Returns:
        (smallest, largest).

    Raises:
        EigenSolveError: One of the two does not converge.

    Note:
        Collective.
    """
    options = EXTREME_OPTIONS if options is None else options
    values = []
    for which in ("smallest", "largest"):
        with destroyed_after(SLEPc.EPS().create(mat.comm)) as eps:
            eps.setOperators(mat)
            eps.setProblemType(SLEPc.EPS.ProblemType.HEP)
            eps.setDimensions(1)
            eps.setTolerances(tol)
            if which == "largest":
                eps.setWhichEigenpairs(SLEPc.EPS.Which.LARGEST_REAL)
                used = {k: v for k, v in options.items() if k.startswith("eps_")}
            else:
                eps.setTarget(0.0)
                eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_REAL)
                eps.getST().setType(SLEPc.ST.Type.SINVERT)
                used = dict(options)
            set_options(eps, prefix, used)
            with option_defaults(prefix, ordering_options(mat, "st_mat_mumps_icntl_7")):
                eps.solve()
            if eps.getConverged() < 1:
                raise EigenSolveError(f"SLEPc ({prefix}): the {which} eigenvalue did not converge")
            values.append(float(eps.getEigenvalue(0).real))
    return values[0], values[1]
