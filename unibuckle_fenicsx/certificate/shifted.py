"""The shifted matrix K(lambda) = sym(A - lambda B) with rigorous error bounds, and mirror maps.

The common ground of the copositivity routes (:mod:`~unibuckle_fenicsx.certificate.copositivity`,
:mod:`~unibuckle_fenicsx.certificate.copositivity_sdp`,
:mod:`~unibuckle_fenicsx.certificate.copositivity_lowrank`): the matrix each certifies, its
refined solves with floating-point bounds, and the plate's mirror symmetries of the
constrained nodes.

Note:
    Collective on the problem's communicator. The factorisations go through the mesh's
    shared :math:`LDL^T` (:class:`~unibuckle_fenicsx.la.factor.SharedFactorization`, options
    prefix ``unibuckle_ldl_``) when one is given, else under ``unibuckle_certify_``.
"""

from __future__ import annotations

import time
import weakref
from dataclasses import dataclass

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.la.factor import SharedFactorization, SymmetricFactorization, same_pattern
from unibuckle_fenicsx.la.options import Prefix
from unibuckle_fenicsx.la.ownership import Owner, release
from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.tolerances import GEOMETRY_RTOL

__all__ = ["EPS", "ShiftedMatrix", "Solve", "absdot", "mirror_maps", "norm2", "rayleigh"]

EPS = float(np.finfo(float).eps)


@dataclass
class Solve:
    """A refined solve x = K^-1 w: x, the computed residual and its error data."""

    w: PETSc.Vec
    x: PETSc.Vec
    rho: PETSc.Vec  # computed w - K x
    err: PETSc.Vec  # componentwise bound on the rounding of rho
    d: PETSc.Vec  # K^-1 rho: estimate of the remaining error of x

    def destroy(self) -> None:
        """Destroy the vectors."""
        for v in (self.w, self.x, self.rho, self.err, self.d):
            v.destroy()


def norm2(v: PETSc.Vec) -> float:
    """The 2-norm of ``v`` (collective)."""
    return float(v.norm())  # type: ignore[arg-type]


def rayleigh(problem: UnilateralProblem, u: PETSc.Vec) -> float | None:
    """The load a(u, u)/b(u, u) of the mode u, or None when b(u, u) <= 0 (collective)."""
    Au, Bu = u.duplicate(), u.duplicate()
    try:
        problem.model.A.mult(u, Au)
        problem.model.B.mult(u, Bu)
        a, b = float(u.dot(Au).real), float(u.dot(Bu).real)
    finally:
        Au.destroy()
        Bu.destroy()
    return a / b if b > 0 else None


def absdot(a: PETSc.Vec, b: PETSc.Vec) -> float:
    """The sum of |a_i| |b_i| (collective)."""
    comm = a.getComm().tompi4py()
    return float(comm.allreduce(float(np.abs(a.array_r) @ np.abs(b.array_r)), op=MPI.SUM))


class ShiftedMatrix(Owner):
    r""":math:`K(\lambda) = \mathrm{sym}(A - \lambda B)`, its :math:`|K|`, and its :math:`LDL^T`.

    The pattern is built once; :meth:`factor` rebuilds the values for a new
    :math:`\lambda` and factorises (MUMPS Cholesky, symmetric indefinite; the SPD flag of
    A, which ``MatDuplicate`` propagates, is cleared, else MUMPS assumes a positive
    definite matrix and may report a wrong inertia without error).

    Args:
        A: Stiffness (AIJ).
        B: Geometric stiffness (AIJ).
        prefix: Options prefix of the factorisation (when not ``shared``).
        shared: The mesh's shared :math:`LDL^T` (``problem.eigensolver.factorization``):
            K's values are copied into its matrix and factorised there, reusing the
            symbolic analysis of the interior-point method and the shifted eigen solves
            (when K has its pattern; otherwise K gets its own factorisation).

    Note:
        Collective. The owner must :meth:`destroy` it.
    """

    def __init__(
        self,
        A: PETSc.Mat,
        B: PETSc.Mat,
        prefix: str = Prefix.CERTIFY,
        shared: SharedFactorization | None = None,
    ) -> None:
        for mat, name in ((A, "A"), (B, "B")):
            if mat.getType() not in ("seqaij", "mpiaij"):
                raise TypeError(f"{name} must be AIJ for the LDL^T inertia, got {mat.getType()}")
        self.A, self.B, self.prefix = A, B, prefix
        self.K: PETSc.Mat | None = None
        self.Kt: PETSc.Mat | None = None
        self.Kabs: PETSc.Mat | None = None
        self.factorization: SymmetricFactorization | None = None
        self.shared = shared
        self._on_shared = False  # the last factorisation went through ``shared``
        self._fits: bool | None = None  # whether K has the shared matrix's pattern
        self._symmetric_pattern = False  # K and K^T have one CSR pattern (checked once)
        self.row_length = 0
        self.solves = 0
        self.factorisations = 0
        self.factor_s = 0.0
        self.solve_s = 0.0

    def build(self, lam: float) -> PETSc.Mat:
        """Assemble K(lam) and |K| (collective).

        A's and B's patterns are merged once; K^T is added as values on K's own pattern
        when the two patterns are one (checked once), and |K| is made from K's values in
        one piece (``createAIJWithArrays``) rather than refilled value by value. K and |K|
        are the same to the last bit as with pattern merges, and faster
        (:doc:`/verification/tuning`).
        """
        subset = PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN
        transposed = subset  # after the first merge K's pattern holds K^T's
        first = self.K is None
        if self.K is None:
            K = self.A.duplicate(copy=True)
            K.axpy(-lam, self.B, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)  # type: ignore[arg-type]
            K.setOption(PETSc.Mat.Option.SYMMETRIC, False)  # type: ignore[arg-type]
            self.Kt = K.transpose(PETSc.Mat())  # not in place: an output matrix
            self._symmetric_pattern = same_pattern(K, self.Kt)
            self.K = K
            transposed = PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
        else:
            K = self.K
            if self.Kt is None:
                raise RuntimeError("build: expected self.Kt is not None (an internal invariant)")
            K.zeroEntries()
            K.axpy(1.0, self.A, structure=subset)  # type: ignore[arg-type]
            K.axpy(-lam, self.B, structure=subset)  # type: ignore[arg-type]
            K.setOption(PETSc.Mat.Option.SYMMETRIC, False)  # type: ignore[arg-type]
            self.Kt.destroy()
            self.Kt = K.transpose(PETSc.Mat())
        assert self.Kt is not None
        if self._symmetric_pattern:
            transposed = PETSc.Mat.Structure.SAME_NONZERO_PATTERN
        K.axpy(1.0, self.Kt, structure=transposed)  # type: ignore[arg-type]
        K.scale(0.5)
        K.setOption(PETSc.Mat.Option.SPD, False)  # type: ignore[arg-type]
        K.setOption(PETSc.Mat.Option.SYMMETRIC, True)  # type: ignore[arg-type]
        ai, aj, av = K.getValuesCSR()
        if first:
            local = int(np.diff(ai).max()) if len(ai) > 1 else 0
            self.row_length = int(K.getComm().tompi4py().allreduce(local, op=MPI.MAX))
        if self.Kabs is not None:
            self.Kabs.destroy()
        self.Kabs = PETSc.Mat().createAIJWithArrays(
            K.getSizes(),  # type: ignore[arg-type]
            (ai, aj, np.abs(av)),  # type: ignore[arg-type]
            comm=K.getComm(),
        )
        return K

    def factor(self, lam: float) -> tuple[int, int, int]:
        """Build and factorise K(lam); its inertia (negative, zero, positive)."""
        t0 = time.perf_counter()
        return self._factorise(self.build(lam), t0)

    def factor_reduced(self, rows: npt.NDArray[np.int64], sigma: float) -> tuple[int, int, int]:
        r"""Factorise :math:`A_Z - \sigma B_Z` (``rows`` removed: zero, diagonal 1); its inertia.

        The same matrix and pattern as :meth:`factor`, so the symbolic analysis is not
        repeated (one numeric :math:`LDL^T`); ``rows`` are the global rows owned by this
        rank. K then holds the reduced pencil (and :math:`|K|` a stale one): call
        :meth:`factor` before :meth:`solve` or :meth:`refined` again.
        """
        t0 = time.perf_counter()
        if self.K is None:
            K = self.build(sigma)
        else:  # A - sigma B is symmetric: no symmetrisation, and |K| is not needed
            K = self.K
            subset = PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN
            K.zeroEntries()
            K.axpy(1.0, self.A, structure=subset)  # type: ignore[arg-type]
            K.axpy(-sigma, self.B, structure=subset)  # type: ignore[arg-type]
        K.zeroRowsColumns(np.ascontiguousarray(rows, dtype=PETSc.IntType), diag=1.0)  # type: ignore[arg-type]
        return self._factorise(K, t0)

    def _factorise(self, K: PETSc.Mat, t0: float) -> tuple[int, int, int]:
        """Factorise K (its symbolic analysis done once, on the first call); its inertia."""
        if self._fits is None:  # K is built once (build): its pattern never changes
            self._fits = self.shared is not None and self.shared.fits(K)
        self._on_shared = self._fits
        if self._on_shared:
            inertia = self._factor_shared(K)
        else:
            if self.factorization is None:
                self.factorization = SymmetricFactorization(K, self.prefix)
            else:
                self.factorization.ksp.setOperators(K)
                self.factorization.ksp.setUp()
            inertia = self.factorization.inertia()
        self.factorisations += 1
        self.factor_s += time.perf_counter() - t0
        return inertia

    def _factor_shared(self, K: PETSc.Mat) -> tuple[int, int, int]:
        assert self.shared is not None
        K.copy(self.shared.matrix, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)  # type: ignore[arg-type]
        return self.shared.factor(self)

    @property
    def factored(self) -> bool:
        """Whether K has been factorised (:meth:`factor` or :meth:`factor_reduced`)."""
        return self._on_shared or self.factorization is not None

    def _current(self) -> SymmetricFactorization | SharedFactorization:
        """The factorisation of K as it is now (the shared one: again if another took it)."""
        if self._on_shared:
            assert self.shared is not None and self.K is not None
            if not self.shared.holds(self):
                self._factor_shared(self.K)
                self.factorisations += 1
            return self.shared
        if self.factorization is None:
            raise RuntimeError("ShiftedMatrix: call factor() first")
        return self.factorization

    def inertia(self) -> tuple[int, int, int]:
        """(negative, zero, positive) eigenvalue counts of the factorised K."""
        return self._current().inertia()

    def solve(self, b: PETSc.Vec, x: PETSc.Vec) -> None:
        """X = K^-1 b with the current factorisation."""
        factorization = self._current()
        t0 = time.perf_counter()
        factorization.ksp.solve(b, x)
        self.solves += 1
        self.solve_s += time.perf_counter() - t0

    def refined(self, w: PETSc.Vec) -> Solve:
        r"""Solve K x = w, refined once, with the residual and the rounding bound of it.

        The residual's rounding is bounded componentwise by
        :math:`\gamma_m(|w| + |K||x|)`, :math:`\gamma_m = m\epsilon/(1 - m\epsilon)`,
        m the longest row plus one. ``w`` is owned by the returned :class:`Solve`.
        """
        if self.K is None or self.Kabs is None:
            raise RuntimeError(
                "refined: expected self.K is not None and self.Kabs is not None (an internal "
                "invariant)"
            )
        x, rho, dx = w.duplicate(), w.duplicate(), w.duplicate()
        self.solve(w, x)
        self.K.mult(x, rho)
        rho.aypx(-1.0, w)
        self.solve(rho, dx)
        x.axpy(1.0, dx)
        self.K.mult(x, rho)
        rho.aypx(-1.0, w)
        err = w.duplicate()
        dx.array[:] = np.abs(x.array_r)
        self.Kabs.mult(dx, err)
        err.array[:] += np.abs(w.array_r)
        m = self.row_length + 1
        err.scale(m * EPS / (1 - m * EPS))
        self.solve(rho, dx)
        return Solve(w, x, rho, err, dx)

    def _dense(self, values: npt.NDArray[np.float64]) -> PETSc.Mat:
        """A dense matrix with K's row layout on the memory of ``values`` (owned rows x columns).

        ``values`` must be a Fortran-ordered float64 array kept alive while the matrix is.
        """
        assert self.K is not None
        rows, cols = self.K.getSizes()[0], values.shape[1]
        return PETSc.Mat().createDense(
            (rows, (PETSc.DECIDE, cols)),  # type: ignore[arg-type]
            array=values,  # type: ignore[arg-type]
            comm=self.K.getComm(),
        )

    def solve_block(self, rhs: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """:math:`K^{-1}` applied to the columns of ``rhs`` (owned rows), in one MUMPS call.

        ``MatMatSolve`` on the factor solves all right-hand sides at once (dense BLAS-3 in
        the triangular solves: several times faster per column than one solve each).
        """
        if rhs.shape[1] == 0:
            return np.zeros_like(rhs)
        factor = self._current().ksp.getPC().getFactorMatrix()
        rhs = np.asfortranarray(rhs, dtype=np.float64)
        out = np.zeros_like(rhs, order="F")
        b, x = self._dense(rhs), self._dense(out)
        try:
            t0 = time.perf_counter()
            factor.matSolve(b, x)
            self.solve_s += time.perf_counter() - t0
            self.solves += rhs.shape[1]
            return out
        finally:
            b.destroy()
            x.destroy()

    def multiply_block(
        self, x: npt.NDArray[np.float64]
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(K X, |K| |X|) for the columns of ``x`` (owned rows): sparse times dense."""
        if self.K is None or self.Kabs is None:
            raise RuntimeError(
                "multiply_block: expected self.K is not None and self.Kabs is not None (an "
                "internal invariant)"
            )
        out = []
        for mat, values in ((self.K, x), (self.Kabs, np.abs(x))):
            source = np.asfortranarray(values, dtype=np.float64)
            a = self._dense(source)
            try:
                product = mat.matMult(a)
                out.append(np.array(product.getDenseArray(), dtype=np.float64))
                product.destroy()
            finally:
                a.destroy()
        return out[0], out[1]

    @staticmethod
    def bilinear(a: Solve, b: Solve) -> tuple[float, float]:
        r""":math:`w_a^T K^{-1} w_b` and a bound on the error of that value.

        :math:`|w_a^TK^{-1}w_b - w_a^Tx_b| = |x_a^T\rho_b|` (exact x, exact residual) is at
        most :math:`|\hat x_a|^T(|\hat\rho_b| + e_b) + \|d_a\|\,\||\hat\rho_b| + e_b\|`,
        plus the rounding of the dot product.
        """
        value = a.w.dot(b.x).real
        rb = b.rho.duplicate()
        rb.array[:] = np.abs(b.rho.array_r) + b.err.array_r
        bound = absdot(a.x, rb) + norm2(a.d) * norm2(rb)
        rb.destroy()
        n = a.w.getSize()
        bound += n * EPS / (1 - n * EPS) * absdot(a.w, b.x)
        return value, bound

    def destroy(self) -> None:
        """Destroy the matrices and the factorisation (collective)."""
        release(self, "factorization", "K", "Kt", "Kabs")

    def __del__(self) -> None:
        self.destroy()


_MIRRORS: weakref.WeakKeyDictionary[UnilateralProblem, dict[str, npt.NDArray[np.int64]]] = (
    weakref.WeakKeyDictionary()
)


def mirror_maps(
    problem: UnilateralProblem, tol: float = GEOMETRY_RTOL
) -> dict[str, npt.NDArray[np.int64]]:
    """Permutations of the constrained nodes under the plate's mirror symmetries.

    A reflection (about x = centre, y = centre, or both) appears only when it maps the
    node set onto itself. The images of a reaction are candidates, nothing more: the
    certificate checks whatever it is given. Computed once per problem (default ``tol``).
    """
    if tol == GEOMETRY_RTOL and problem in _MIRRORS:
        return _MIRRORS[problem]
    maps = _mirror_maps(problem, tol)
    if tol == GEOMETRY_RTOL:
        _MIRRORS[problem] = maps
    return maps


def _mirror_maps(problem: UnilateralProblem, tol: float) -> dict[str, npt.NDArray[np.int64]]:
    xy = problem.contact.coordinates
    (x0, y0), (x1, y1) = problem.spec.plate.corners
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    size = max(x1 - x0, y1 - y0)

    def keys(p: npt.NDArray[np.float64]) -> npt.NDArray[np.int64]:
        return np.round((p - (cx, cy)) / (tol * size)).astype(np.int64)

    own = keys(xy)
    n = len(own)
    out = {}
    for name, (sx, sy) in {"x": (-1, 1), "y": (1, -1), "xy": (-1, -1)}.items():
        image = np.column_stack([cx + sx * (xy[:, 0] - cx), cy + sy * (xy[:, 1] - cy)])
        # Number the distinct keys of the nodes and of their images together; a node
        # maps to the (last) node whose key its image's key equals.
        _, key_id = np.unique(np.vstack([own, keys(image)]), axis=0, return_inverse=True)
        key_id = key_id.reshape(-1)
        node_of = np.full(2 * n, -1, dtype=np.int64)
        node_of[key_id[:n]] = np.arange(n, dtype=np.int64)  # repeated keys: the last wins
        perm = node_of[key_id[n:]]
        if np.all(perm >= 0):
            out[name] = perm
    return out
