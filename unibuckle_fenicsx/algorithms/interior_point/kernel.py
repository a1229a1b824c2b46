r"""The Newton step of the interior-point method: its matrix, inertia control and line search.

:class:`NewtonKernel` holds the work of one Newton step on one mesh: the Newton matrix

.. math::

    K = A - \lambda B + E\,\mathrm{diag}(\nu/g)\,E^T

(E scatters oriented nodal values into W), factorised by the mesh's shared
:math:`LDL^T` (:class:`~unibuckle_fenicsx.la.factor.SharedFactorization`: the pattern is
A's, so the symbolic analysis is done once per mesh), the two solves of a step,
:math:`y_2 = K^{-1}Bu` and :math:`y_1 = K^{-1}(-F_u + E(F_c/g))`, and
:math:`\delta\lambda = (-F_n - (Bu)^Ty_1)/((Bu)^Ty_2)`, :math:`\delta u = y_1 +
\delta\lambda\, y_2`, :math:`\delta\nu = (-F_c + \nu \circ E^T\delta u)/g`.

Inertia control (Nocedal & Wright, *Numerical Optimization*, 2nd ed., ch. 19; Wächter &
Biegler, Math. Program. 106, 2006): the bordered matrix :math:`[[K, -Bu], [-Bu^T, 0]]`
must have exactly one negative eigenvalue, i.e. :math:`\mathrm{neg}(K) + [(Bu)^Ty_2 > 0]
= 1`, read off MUMPS's inertia; otherwise :math:`\delta M` is added (M:
``NewtonOptions.metric``) and K refactorised. After
a full step (or one that needed no correction) the unmodified matrix is tried first
(IPOPT's rule): a correction carried from step to step damps the steps and the
convergence turns linear. The line search backtracks on the barrier objective while the
residual is large.

Note:
    All decisions use values reduced over the ranks; every method is collective on the
    problem's communicator.
"""

from __future__ import annotations

import math

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms.interior_point.options import NewtonOptions
from unibuckle_fenicsx.la.ownership import Owner, release
from unibuckle_fenicsx.model.problem import UnilateralProblem, require_obstacle
from unibuckle_fenicsx.tolerances import MERIT_RTOL, RESIDUAL_ROUNDING

__all__ = ["Direction", "NewtonKernel", "dot"]

_SAME = PETSc.Mat.Structure.SAME_NONZERO_PATTERN
_SUBSET = PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN

#: A Newton direction: :math:`(\delta\lambda, z(\delta u), \delta\nu)`.
Direction = tuple[float, npt.NDArray[np.float64], npt.NDArray[np.float64]]


def dot(a: PETSc.Vec, b: PETSc.Vec) -> float:
    """:math:`a^T b` of real vectors (collective)."""
    return float(a.dot(b))  # type: ignore[arg-type]


class NewtonKernel(Owner):
    r"""The Newton matrix, its factorisation, the step and the work vectors of one mesh.

    Args:
        problem: A problem with a rigid obstacle.
        options: Settings (default :class:`~.options.NewtonOptions`).

    Attributes:
        dofs: Local W DOF of each owned constrained node.
        signs: Side :math:`s_k` of each owned constrained node.
        Au: :math:`Au` at the last point evaluated (``Bu``, ``Fu``: :math:`Bu`, :math:`F_u`).
        du: The last Newton direction's :math:`\delta u`.
        trial: A work vector, as are ``y1``, ``y2`` and ``rhs`` (:math:`y_2 = K^{-1}Bu`
            after a direction).
        last_correction: The inertia correction of the last step (0: none).
        delta_last: The last nonzero inertia correction.
        factorizations: Numeric factorisations so far.

    Note:
        Construction, every method and :meth:`destroy` are collective.
    """

    def __init__(self, problem: UnilateralProblem, options: NewtonOptions | None = None) -> None:
        require_obstacle(problem, "InteriorPointNewton")
        if problem.tensionless:
            raise ValueError("InteriorPointNewton needs a problem with a rigid obstacle")
        self.problem = problem
        self.options = options or NewtonOptions()
        if self.options.metric not in ("geometric", "stiffness"):
            raise ValueError(
                f'NewtonOptions.metric must be "geometric" or "stiffness", '
                f"got {self.options.metric!r}"
            )
        self.comm = problem.comm
        self.contact = problem.contact
        self.dofs = self.contact.owned_local_dofs
        self.signs = self.contact.owned_signs
        A, B = problem.model.A, problem.model.B
        self.A, self.B = A, B
        self.ldl = problem.eigensolver.factorization
        self.K, self.ksp = self.ldl.matrix, self.ldl.ksp  # shared: not destroyed here
        # B with A's pattern (explicit zeros where B has none): K = A - lambda B is then
        # an axpy of two value arrays, not a pattern merge (the same values up to the
        # rounding of a fused multiply-add).
        self.B_on_A = A.duplicate(copy=False)
        self.B_on_A.axpy(1.0, B, structure=_SUBSET)
        self.factorizations = 0
        self.diag_A = A.createVecLeft()
        A.getDiagonal(self.diag_A)
        self.diag = A.createVecLeft()  # diagonal modification of K
        self.Au, self.Bu, self.Fu = A.createVecLeft(), A.createVecLeft(), A.createVecLeft()
        self.y1, self.y2, self.rhs = A.createVecLeft(), A.createVecLeft(), A.createVecLeft()
        self.du, self.trial = A.createVecLeft(), A.createVecLeft()
        # |A| and |B| for the rounding floor of the residual (thin plates: |A||u| >> |Au|);
        # the problem's (not destroyed here).
        self.abs_A, self.abs_B = problem.abs_pencil()
        # The regularisation's diagonal: diag(A), or the row sums of |B| (D - B is then
        # diagonally dominant: D bounds B above).
        self.reg = self.diag_A
        if self.options.metric == "geometric":
            self.reg = A.createVecLeft()
            self.trial.set(1.0)
            self.abs_B.mult(self.trial, self.reg)
        self.delta_last = 0.0
        self.last_correction = 0.0

    def oriented(self, vec: PETSc.Vec) -> npt.NDArray[np.float64]:
        """:math:`z = s_k u_k` at the owned constrained nodes of the W-vector ``vec``."""
        return self.signs * vec.array_r[self.dofs]  # type: ignore[return-value]

    def add_zone(self, vec: PETSc.Vec, values: npt.NDArray[np.float64]) -> None:
        """``vec += E values`` (oriented values at the owned constrained nodes)."""
        vec.array[self.dofs] += self.signs * values

    # (On one rank the reductions skip MPI: mpi4py's allreduce of a Python float pickles
    # it, a tenth of a Newton step on the coarsest mesh.)
    def min(self, values: npt.NDArray[np.float64]) -> float:
        """The smallest of ``values`` over the ranks (``inf`` if none)."""
        local = float(values.min()) if values.size else math.inf
        return local if self.comm.size == 1 else float(self.comm.allreduce(local, op=MPI.MIN))

    def max(self, values: npt.NDArray[np.float64]) -> float:
        """The largest of ``values`` over the ranks (``-inf`` if none)."""
        local = float(values.max()) if values.size else -math.inf
        return local if self.comm.size == 1 else float(self.comm.allreduce(local, op=MPI.MAX))

    def sum(self, value: float) -> float:
        """``value`` summed over the ranks."""
        local = float(value)
        return local if self.comm.size == 1 else float(self.comm.allreduce(local, op=MPI.SUM))

    def factor(
        self,
        load: float,
        sigma: npt.NDArray[np.float64] | None,
        delta: float = 0.0,
        stiff: tuple[npt.NDArray[np.bool_], float] | None = None,
    ) -> tuple[int, int]:
        r"""Factorise :math:`A - \lambda B + E \Sigma E^T + \delta\,diag(A)`; its inertia.

        ``stiff = (mask, value)`` adds ``value`` to the diagonal of the owned DOFs in
        ``mask``.
        """
        self.A.copy(self.K, structure=_SAME)
        if load:
            self.K.axpy(-load, self.B_on_A, structure=_SAME)  # type: ignore[arg-type]
        self.diag.zeroEntries()
        if delta:
            geometric = self.options.metric == "geometric"
            self.diag.axpy(delta * load if geometric else delta, self.reg)
        if sigma is not None:
            # E diag(sigma) E^T: the entries are s_k^2 sigma_k = sigma_k, whatever the side.
            self.diag.array[self.dofs] += sigma
        if stiff is not None:
            self.diag.array[stiff[0]] += stiff[1]
        self.K.setDiagonal(self.diag, addv=PETSc.InsertMode.ADD_VALUES)  # type: ignore[arg-type]
        nneg, nzero, _ = self.ldl.factor(self)
        self.factorizations += 1
        return nneg, nzero

    def held_diagonal(self) -> float:
        """Diagonal entry that holds a DOF (the starts' relax and lift): max diag(A) scaled.

        ``options.held_stiffness`` times the largest diagonal entry of A: a DOF held by
        it moves by the inverse of that factor of the correction.
        """
        return self.options.held_stiffness * float(self.diag_A.norm(PETSc.NormType.INFINITY))

    def forget_corrections(self) -> None:
        """Start the next run as a new method would: no inertia correction remembered."""
        self.delta_last = 0.0
        self.last_correction = 0.0

    def normalize(self, vec: PETSc.Vec) -> None:
        """Scale ``vec`` to :math:`u^TBu = 1`; leaves :math:`Bu` (before scaling) in ``Bu``."""
        self.B.mult(vec, self.Bu)
        b = dot(vec, self.Bu)
        if not b > 0.0:
            raise FloatingPointError("b(u, u) <= 0: the mode carries no geometric stiffness")
        vec.scale(1.0 / math.sqrt(b))

    def merit(self, vec: PETSc.Vec, mu_abs: float) -> float:
        """Barrier objective of the normalised ``vec`` (inf outside the cone)."""
        gap = -self.oriented(vec)
        if self.min(gap) <= 0.0:
            return math.inf
        self.A.mult(vec, self.Au)
        return 0.5 * dot(vec, self.Au) - mu_abs * self.sum(np.log(gap).sum())

    def residual(self, u: PETSc.Vec, lam: float, nu: npt.NDArray[np.float64] | None = None) -> None:
        r""":math:`Au`, :math:`Bu`, :math:`F_u = Au - \lambda Bu\ (+ E\nu)` into work vectors."""
        self.A.mult(u, self.Au)
        self.B.mult(u, self.Bu)
        self.Au.copy(self.Fu)
        self.Fu.axpy(-lam, self.Bu)
        if nu is not None:
            self.add_zone(self.Fu, nu)

    def rounding(self, u: PETSc.Vec, lam: float) -> float:
        r"""Rounding level of :math:`F_u`: :math:`c\,\epsilon\,(|A| + \lambda|B|)|u|`.

        The largest entry, with c = :data:`~unibuckle_fenicsx.tolerances.RESIDUAL_ROUNDING`;
        on thin plates it lies far above :math:`\epsilon |Au|`.
        """
        u.copy(self.trial)
        self.trial.abs()
        self.abs_A.mult(self.trial, self.rhs)
        self.rhs.abs()
        self.abs_B.mult(self.trial, self.y1)
        self.rhs.axpy(lam, self.y1)
        eps = float(np.finfo(float).eps)
        return RESIDUAL_ROUNDING * eps * float(self.rhs.norm(PETSc.NormType.INFINITY))

    def direction(
        self,
        u: PETSc.Vec,
        lam: float,
        nu: npt.NDArray[np.float64],
        gap: npt.NDArray[np.float64],
        mu_abs: float,
        plain_first: bool = True,
    ) -> Direction | None:
        r"""The Newton direction at (u, lambda, nu) for the absolute barrier ``mu_abs``.

        Solves the linearised optimality conditions (module docstring) with the
        inertia-controlled factorisation of K; :math:`\delta u` is left in ``self.du``
        (valid until the next call). ``self.Fu`` must hold :math:`F_u` and
        ``self.Bu`` :math:`Bu` at u.

        Returns:
            :math:`(\delta\lambda, z(\delta u), \delta\nu)`, or None when the
            regularisation reached ``delta_max`` without the right inertia.
        """
        opts = self.options
        f_c = nu * gap - mu_abs
        sigma = nu / gap
        # The unmodified matrix is tried first (IPOPT's rule IC-1) after a full step
        # or an uncorrected one: a regularisation kept from step to step damps the
        # steps and makes the convergence linear. Otherwise (short corrected steps, far
        # from a minimiser) the correction starts from a fraction of the last one.
        if opts.plain_first:
            memory = self.delta_last
        else:
            memory = self.last_correction
            memory = memory if memory > opts.forgotten_correction else 0.0
        retry = memory / opts.correction_decay if memory else opts.delta_first
        limit = min(opts.delta_max, 1.0) if opts.metric == "geometric" else opts.delta_max
        delta = retry if memory and not plain_first else 0.0
        while True:
            nneg, nzero = self.factor(lam, sigma, delta)
            self.ksp.solve(self.Bu, self.y2)
            by2 = dot(self.Bu, self.y2)
            if nzero == 0 and nneg + (1 if by2 > 0.0 else 0) == 1:
                break
            if delta >= limit:
                return None
            growth = opts.correction_growth_remembered if memory else opts.correction_growth
            delta = min(limit, retry if delta == 0.0 else delta * growth)
        self.last_correction = delta
        if delta:
            self.delta_last = delta
        self.Fu.copy(self.rhs)
        self.rhs.scale(-1.0)
        self.add_zone(self.rhs, f_c / gap)
        self.ksp.solve(self.rhs, self.y1)
        self.y1.copy(self.du)
        dlam = self.add_load_step(u, self.du, by2)
        dz = self.oriented(self.du)
        dnu = (-f_c + nu * dz) / gap
        return dlam, dz, dnu

    def add_load_step(self, u: PETSc.Vec, y: PETSc.Vec, by2: float) -> float:
        r""":math:`\delta\lambda` from the linearised normalisation; ``y`` becomes :math:`\delta u`.

        ``y`` solves K y = (right-hand side without the load term), ``self.y2`` is
        :math:`K^{-1}Bu` and ``by2`` :math:`(Bu)^Ty_2`; :math:`\delta u = y + \delta\lambda\,y_2`.
        """
        dlam = (-0.5 * (dot(u, self.Bu) - 1.0) - dot(self.Bu, y)) / by2
        y.axpy(dlam, self.y2)
        return dlam

    def line_search(
        self,
        u: PETSc.Vec,
        mu_abs: float,
        alpha: float,
        dz: npt.NDArray[np.float64],
        gap: npt.NDArray[np.float64],
        e_u: float,
    ) -> float:
        """Backtrack from ``alpha`` on the barrier objective; apply the step to ``u``.

        Returns the step length applied: the accepted one, or the last tried when every
        backtrack fails.
        """
        local = e_u <= self.options.local_residual
        phi0 = self.merit(u, mu_abs)
        self.A.mult(u, self.Au)
        slope = dot(self.Au, self.du) + mu_abs * self.sum((dz / gap).sum())
        opts = self.options
        for tried in range(1, opts.max_backtracks + 1):
            u.copy(self.trial)
            self.trial.axpy(alpha, self.du)
            self.normalize(self.trial)
            if local or slope >= 0.0 or tried == opts.max_backtracks:
                break
            phi = self.merit(self.trial, mu_abs)
            if phi <= phi0 + opts.armijo * alpha * slope + MERIT_RTOL * abs(phi0):
                break
            alpha *= opts.backtrack
        self.trial.copy(u)
        return alpha

    def destroy(self) -> None:
        """Destroy the work matrix and vectors (collective); K is the problem's, kept."""
        if getattr(self, "reg", None) is getattr(self, "diag_A", None):
            self.reg = None
        release(self, "B_on_A", "diag_A", "diag", "reg")
        release(self, "Au", "Bu", "Fu", "y1", "y2", "rhs", "du", "trial")

    def __del__(self) -> None:
        self.destroy()
