r"""Interior-point Newton method for the unilateral eigenproblem on one mesh.

The critical state minimises the Rayleigh quotient on the cone
:math:`\{u: z_k = s_k u_k \le 0,\ k \in I\}` (oriented values, see
:class:`~unibuckle_fenicsx.model.contact.ContactSetManager`). With the gap
:math:`g = -z > 0` and the obstacle's push :math:`\nu > 0` at the constrained nodes,
the barrier problem :math:`\min \tfrac12 u^TAu - \mu\sum_k \log g_k` on
:math:`u^TBu = 1` has the optimality conditions

.. math::

    F_u = Au - \lambda Bu + E\nu = 0, \qquad F_c = \nu \circ g - \mu = 0, \qquad
    F_n = \tfrac12 (u^TBu - 1) = 0,

(E scatters oriented nodal values into W) which tend to the KKT conditions of the
critical state as :math:`\mu \to 0`. One Newton step is one numeric :math:`LDL^T`
(MUMPS; the pattern is A's, so the symbolic analysis is done once per mesh, and shared
with the shifted eigen solves and the certificate) of

.. math::

    K = A - \lambda B + E\,\mathrm{diag}(\nu/g)\,E^T

and two solves, :math:`y_2 = K^{-1}Bu` and :math:`y_1 = K^{-1}(-F_u + E(F_c/g))`:
:math:`\delta\lambda = (-F_n - (Bu)^Ty_1)/((Bu)^Ty_2)`, :math:`\delta u = y_1 +
\delta\lambda\, y_2`, :math:`\delta\nu = (-F_c + \nu \circ E^T\delta u)/g`.

Why a barrier. On thin long plates the critical mode lies almost flat on the obstacle:
thousands of constrained nodes have both a gap and a push close to zero. An active-set
step must decide for each of them whether it touches; the decisions flip from one step
to the next and their number grows with the mesh. The barrier treats those nodes
smoothly, and Newton's method on the barrier problem needs about the same number of
steps on every mesh (the nested driver, :mod:`.chain`, starts each mesh from the
previous one's solution).

Safeguards (Nocedal & Wright, *Numerical Optimization*, 2nd ed., ch. 19; Wächter &
Biegler, Math. Program. 106, 2006, the IPOPT paper):

- inertia control: the bordered matrix :math:`[[K, -Bu], [-Bu^T, 0]]` must have exactly
  one negative eigenvalue, i.e. :math:`\mathrm{neg}(K) + [(Bu)^Ty_2 > 0] = 1` (K positive
  definite on the tangent space of the constraint), read off MUMPS's inertia; otherwise
  :math:`\delta\lambda D` is added (D: row sums of :math:`|B|`, a fraction
  :math:`\delta` of the geometric stiffness given back; at :math:`\delta = 1` K is
  positive definite) and K refactorised. After a full step (or one that needed no
  correction) the unmodified matrix is tried first (IPOPT's rule): a correction carried
  from step to step damps the steps and the convergence turns linear. Measured on a
  thin plate's fine mesh (90×30; SSSS at 180×60 in brackets), fine-level Newton steps
  with the former correction :math:`\delta\,\mathrm{diag}(A)` decaying from step to
  step, then with both changes: SSSS 20 → 11 (25 → 16 with the rule alone), loaded
  edges clamped 67 → 45, shear 99 → 51, CCCC 32 → 34, unloaded edges clamped 58 → 48;
- negative curvature: where the barrier problem is nearly solved but the unmodified K
  still has the wrong inertia, the iterate is near a saddle of the barrier problem, to
  which the regularised steps converge; a step along the direction of most negative
  curvature of K on the tangent space leaves it instead (Moré & Sorensen, *On the use
  of directions of negative curvature in a modified Newton method*, Math. Program. 16,
  1979). The direction comes from the factorisation already made: with
  :math:`K_\delta = K + \delta M` positive definite on the tangent space (M the
  regularisation's diagonal), :math:`K_\delta^{-1}M` has the eigenvalues
  :math:`1/(\theta + \delta)` for those :math:`\theta` of the pencil (K, M), so the
  most negative :math:`\theta` dominates a few Krylov vectors (Rayleigh–Ritz on them;
  one triangular solve each, no factorisation);
- fraction to the boundary (0.995) for the gap; the push is updated componentwise, each
  entry kept above 0.005 of its old value;
- a backtracking line search on the barrier objective (the iterate is rescaled to
  :math:`u^TBu = 1` after each trial) while the residual is large, full steps near the
  solution (where the objective's changes are below its rounding);
- the barrier parameter is kept while :math:`\|F_u\|/\|Au\| > 10^{-2}`, then decreased
  superlinearly (:math:`\mu \leftarrow \min(0.2\mu, \mu^{1.5})`) each time the barrier
  problem is solved to :math:`10\mu`.

The complementarity is scaled by :math:`\lambda\|Bu\|_\infty\max|w|` (a push times a
gap), not by :math:`\|Au\|_\infty`, which a prolonged mode's shear pollutes.

Written here because no library solves a nonconvex eigenproblem on a cone: PETSc's
TAO interior-point solvers need a convex (or unconstrained-Hessian) problem and no
normalisation constraint, SNES VI solves complementarity problems without the
eigenvalue.

Note:
    All decisions use values reduced over the ranks; every method is collective on the
    problem's communicator.
"""

from __future__ import annotations

import enum
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.la.options import Prefix, set_options
from unibuckle_fenicsx.la.ownership import Owner, release
from unibuckle_fenicsx.model.problem import UnilateralProblem, require_obstacle

__all__ = [
    "BarrierPoint",
    "InteriorPointNewton",
    "NewtonOptions",
    "NewtonRecord",
    "NewtonStatus",
]

logger = logging.getLogger(__name__)

#: Smallest gap (relative to max|w|) of a pressure deflection that had to be lifted off
#: the obstacle (:meth:`InteriorPointNewton.pressure_mode`); the margin of
#: :meth:`InteriorPointNewton.make_interior`.
PUSH_MARGIN = 1e-2

#: Solver of :meth:`InteriorPointNewton.relax`'s block of A (the deflection's, or the
#: rotations': symmetric positive definite), options prefix ``<prefix>relax_w_`` or
#: ``<prefix>relax_theta_``: conjugate gradients with an incomplete Cholesky
#: preconditioner (block Jacobi across ranks), made once per mesh. Measured on a thin
#: plate at 180×60 (i = 10561): 15–25 ms per block (9 and about 50 iterations), against
#: 0.2–0.3 s for the factorisation of the whole matrix with the other block held by a
#: stiff diagonal, which it replaces.
RELAX_OPTIONS: dict[str, str | float | int | bool] = {
    "ksp_type": "cg",
    "pc_type": "bjacobi",
    "sub_pc_type": "icc",
    "ksp_rtol": 1e-12,
    "ksp_atol": 0.0,
    "ksp_max_it": 5000,
}

_SAME = PETSc.Mat.Structure.SAME_NONZERO_PATTERN
_SUBSET = PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN


def _dot(a: PETSc.Vec, b: PETSc.Vec) -> float:
    """:math:`a^T b` of real vectors (collective)."""
    return float(a.dot(b))  # type: ignore[arg-type]


class NewtonStatus(enum.Enum):
    """How a run of :meth:`InteriorPointNewton.solve` ended."""

    CONVERGED = "converged"
    MAX_STEPS = "max-steps"
    INERTIA = "inertia-correction-failed"
    STALLED = "stalled"
    BREAKDOWN = "breakdown"
    MET_BEFORE = "met before"
    READ = "read"


@dataclass(frozen=True)
class NewtonOptions:
    r"""Settings of the interior-point Newton method (scaled quantities).

    Attributes:
        keep_mu_until: The barrier parameter is not decreased while
            :math:`\|F_u\|_2/\|Au\|_2` exceeds this.
        kappa_eps: The barrier problem counts as solved when its scaled residuals are
            at most ``kappa_eps`` times :math:`\mu`.
        kappa_mu: Linear factor of the decrease of :math:`\mu`.
        theta_mu: Superlinear exponent of the decrease of :math:`\mu`.
        residual_floor: Scaled residual of :math:`F_u` that counts as zero (its
            rounding on thin plates: :math:`|A||u| \gg |Au|`).
        fraction: Fraction to the boundary.
        local_residual: Below this scaled residual, full steps are taken (no line
            search).
        delta_first: First regularisation :math:`\delta` (in the units of ``metric``).
        delta_max: Largest regularisation before giving up (with the geometric
            metric the matrix is positive definite at 1, which is the cap).
        plain_first: After a full step or one that needed no correction, try the
            unmodified matrix first (IPOPT's rule; fast local convergence). Off, the
            correction decays by a third per step (damped steps that stay near the
            start: the exploration of the coarsest mesh uses this).
        metric: The matrix of the regularisation. "geometric": :math:`\lambda D`
            with D the row sums of :math:`|B|`, so that :math:`\delta` is the fraction
            of the geometric stiffness given back (:math:`D - B` is diagonally
            dominant, hence :math:`K + \lambda D \succeq A + E\Sigma E^T \succ 0`).
            "stiffness": diag(A), whose shear part on a thin plate is about
            :math:`(b/t)^2` times the bending stiffness, so that even a small
            :math:`\delta` damps the bending steps heavily.
        curvature_vectors: Krylov vectors of the negative-curvature step (0: none).
            The step is taken instead of the Newton step when the unmodified matrix
            was tried first and had the wrong inertia while the scaled residual is at
            most ``local_residual`` (near a stationary point: a saddle of the barrier
            problem). Measured on thin plates (fine Newton steps / factorisations /
            eigen solves): loaded edges clamped at 90×30 39/65/3 → 26/35/2 (the
            first arrangement no longer converges to a saddle, stalls and escapes
            along a reduced eigenvector: one curvature step, 0.007 of the way to the
            obstacle), at 180×60 21/25/2 → 20/24/2; 4, 8 or 12 vectors the same
            steps. Taken at any residual (the unmodified matrix's inertia is often
            wrong far from a stationary point) it cost more steps on every plate and
            CCCC ended 2.7e-7 higher.
        saddle_curvature: The step is taken when the curvature found,
            :math:`\theta = v^TKv / v^TMv` (in units of the regularisation: a fraction
            of the geometric stiffness), is below minus this. Measured: curvatures of
            -1e-8 to -1e-5 (nearly degenerate plates) gave steps of 1e-14 to 1e-3 of
            the way to the obstacle that only moved the path (unloaded edges clamped
            at 45×15 then fell back to the active-set chain); the saddles these steps
            leave on the benchmark plates have -3e-4 to -3e-3.
        stall_steps: In a run that lowers the barrier parameter (not one held at a
            single parameter), the run stops (status "stalled") when the residual of
            :math:`F_u` has not halved in this many steps (0: never), whatever
            parameter it has reached; the caller reads the contact set there as at
            convergence and goes on from it (saddle escape, lower barrier, polish).
            Measured on thin plates at 180×60: with clamped unloaded edges the steps
            crawled for 80 steps at :math:`\mu = 10^{-14}` (residual 0.05–0.6, load
            settled to 3e-9); under shear, where the buckle can slide along the
            plate, 73 steps at :math:`\mu = 10^{-9}` cut to 0.0001–0.1 by the
            fraction to the boundary (fine mesh 124 steps, now 58, same load).
    """

    keep_mu_until: float = 1e-2
    kappa_eps: float = 10.0
    kappa_mu: float = 0.2
    theta_mu: float = 1.5
    residual_floor: float = 1e-8
    fraction: float = 0.995
    local_residual: float = 1e-2
    delta_first: float = 1e-4
    delta_max: float = 1e6
    plain_first: bool = True
    metric: str = "geometric"
    curvature_vectors: int = 8
    saddle_curvature: float = 1e-4
    stall_steps: int = 10


#: A Newton direction: :math:`(\delta\lambda, z(\delta u), \delta\nu)`.
_Direction = tuple[float, npt.NDArray[np.float64], npt.NDArray[np.float64]]


@dataclass
class BarrierPoint:
    r"""An iterate of the interior-point method.

    Attributes:
        mode: u = (w, theta), :math:`u^TBu = 1`, strictly inside the cone.
        load: :math:`\lambda`.
        push: :math:`\nu > 0` at the constrained nodes owned by this rank, in the
            order of :meth:`~unibuckle_fenicsx.model.contact.ContactSetManager.owned_positions`.
        mu: Scaled barrier parameter.
    """

    mode: dolfinx.fem.Function
    load: float
    push: npt.NDArray[np.float64]
    mu: float


@dataclass
class NewtonRecord:
    r"""What one run of the method did.

    Attributes:
        status: How it ended.
        steps: Newton steps taken.
        factorizations: Numeric factorisations (steps plus inertia corrections).
        curvature_steps: Of the steps, those along a direction of negative curvature.
        seconds: Wall time.
        load: Final :math:`\\lambda`.
        mu: Final scaled barrier parameter.
        history: (load, mu, scaled residual of F_u, scaled complementarity) per step.
    """

    status: NewtonStatus = NewtonStatus.MAX_STEPS
    steps: int = 0
    factorizations: int = 0
    curvature_steps: int = 0
    seconds: float = 0.0
    load: float = math.nan
    mu: float = math.nan
    history: list[tuple[float, float, float, float]] = field(default_factory=list)


@dataclass
class _StallWatch:
    """Whether the residual has not halved in ``steps`` steps (``steps = 0``: never)."""

    steps: int
    best: float = math.inf
    since: int = 0

    def stalled(self, residual: float) -> bool:
        if not self.steps:
            return False
        if residual <= 0.5 * self.best:
            self.best, self.since = residual, 0
        else:
            self.since += 1
        return self.since >= self.steps


class InteriorPointNewton(Owner):
    """The interior-point Newton method on one problem (owns its work vectors and solvers).

    The Newton matrix K and its :math:`LDL^T` are the mesh's
    :class:`~unibuckle_fenicsx.la.factor.SharedFactorization` (``problem.eigensolver``'s),
    whose symbolic analysis the shifted eigen solves and the certificate reuse.

    Args:
        problem: A problem with a rigid obstacle.
        options: Settings (default :class:`NewtonOptions`).
        prefix: Options prefix of the method's own solvers (:data:`RELAX_OPTIONS`).

    Note:
        Construction, every method and :meth:`destroy` are collective.
    """

    def __init__(
        self,
        problem: UnilateralProblem,
        options: NewtonOptions | None = None,
        prefix: str = Prefix.IPM,
    ) -> None:
        require_obstacle(problem, "InteriorPointNewton")
        contact = problem.contact
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
        self.contact = contact
        self._dofs = contact.owned_local_dofs
        self._signs = contact.owned_signs
        A, B = problem.model.A, problem.model.B
        self.A, self.B = A, B
        self._ldl = problem.eigensolver.factorization
        self.K, self.ksp = self._ldl.matrix, self._ldl.ksp  # shared: not destroyed here
        # B with A's pattern (explicit zeros where B has none): K = A - lambda B is then
        # an axpy of two value arrays, not a pattern merge (at 90x30 1.46 -> 0.24 ms a
        # factorisation; the same values up to the rounding of a fused multiply-add).
        self._B_on_A = A.duplicate(copy=False)
        self._B_on_A.axpy(1.0, B, structure=_SUBSET)
        self.prefix = prefix
        self.factorizations = 0
        self._diag_A = A.createVecLeft()
        A.getDiagonal(self._diag_A)
        self._diag = A.createVecLeft()  # diagonal modification of K
        self._Au, self._Bu, self._Fu = A.createVecLeft(), A.createVecLeft(), A.createVecLeft()
        self._y1, self._y2, self._rhs = A.createVecLeft(), A.createVecLeft(), A.createVecLeft()
        self._du, self._trial = A.createVecLeft(), A.createVecLeft()
        # |A| and |B| for the rounding floor of the residual (thin plates: |A||u| >> |Au|);
        # the problem's (not destroyed here).
        self._abs_A, self._abs_B = problem.abs_pencil()
        # The regularisation's diagonal: diag(A), or the row sums of |B| (D - B is then
        # diagonally dominant: D bounds B above).
        self._reg = self._diag_A
        if self.options.metric == "geometric":
            self._reg = A.createVecLeft()
            self._trial.set(1.0)
            self._abs_B.mult(self._trial, self._reg)
        # relax(): the solvers of A's deflection and rotation blocks, made on first use.
        self._blocks: dict[str, tuple[npt.NDArray[np.int64], PETSc.KSP, PETSc.Vec, PETSc.Vec]] = {}
        self._delta_last = 0.0  # the last nonzero inertia correction
        self._last_correction = 0.0  # the correction of the last step
        self._krylov: list[PETSc.Vec] = []  # _curvature_step's basis, made on first use
        # Inside a run's on_solved hook: the next step's (mu_abs, plain_first), and its
        # direction once predicted_contact_set has computed it.
        self._next: tuple[float, bool] | None = None
        self._pending: tuple[_Direction | None] | None = None

    # -- oriented values on the zone (owned nodes, no communication) -----------------
    def oriented(self, vec: PETSc.Vec) -> npt.NDArray[np.float64]:
        """:math:`z = s_k u_k` at the owned constrained nodes of the W-vector ``vec``."""
        return self._signs * vec.array_r[self._dofs]  # type: ignore[return-value]

    def _add_zone(self, vec: PETSc.Vec, values: npt.NDArray[np.float64]) -> None:
        """``vec += E values`` (oriented values at the owned constrained nodes)."""
        vec.array[self._dofs] += self._signs * values

    # (On one rank the reductions skip MPI: mpi4py's allreduce of a Python float pickles
    # it, about 30 us a call, a tenth of a Newton step on the coarsest mesh.)
    def _min(self, values: npt.NDArray[np.float64]) -> float:
        local = float(values.min()) if values.size else math.inf
        return local if self.comm.size == 1 else float(self.comm.allreduce(local, op=MPI.MIN))

    def _max(self, values: npt.NDArray[np.float64]) -> float:
        local = float(values.max()) if values.size else -math.inf
        return local if self.comm.size == 1 else float(self.comm.allreduce(local, op=MPI.MAX))

    def _sum(self, value: float) -> float:
        local = float(value)
        return local if self.comm.size == 1 else float(self.comm.allreduce(local, op=MPI.SUM))

    # -- the Newton matrix -------------------------------------------------------------
    def _factor(
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
            self.K.axpy(-load, self._B_on_A, structure=_SAME)  # type: ignore[arg-type]
        self._diag.zeroEntries()
        if delta:
            geometric = self.options.metric == "geometric"
            self._diag.axpy(delta * load if geometric else delta, self._reg)
        if sigma is not None:
            # E diag(sigma) E^T: the entries are s_k^2 sigma_k = sigma_k, whatever the side.
            self._diag.array[self._dofs] += sigma
        if stiff is not None:
            self._diag.array[stiff[0]] += stiff[1]
        self.K.setDiagonal(self._diag, addv=PETSc.InsertMode.ADD_VALUES)  # type: ignore[arg-type]
        nneg, nzero, _ = self._ldl.factor(self)
        self.factorizations += 1
        return nneg, nzero

    def _held_diagonal(self) -> float:
        """Diagonal entry that holds a DOF (:meth:`relax`, :meth:`lift`): 1e8 max diag(A)."""
        return 1e8 * float(self._diag_A.norm(PETSc.NormType.INFINITY))

    def forget_corrections(self) -> None:
        """Start the next run as a new method would: no inertia correction remembered."""
        self._delta_last = 0.0
        self._last_correction = 0.0

    # -- starts ------------------------------------------------------------------------
    def pressure_mode(self, weights: npt.NDArray[np.float64] | None = None) -> dolfinx.fem.Function:
        r"""Deflection under nodal forces ``weights`` pushing the plate off the obstacle.

        :math:`A u = -E\,\omega` (one factorisation of A): for positive weights a
        deflection strictly inside the cone on simply supported and clamped plates, with
        rotations consistent with it. Where it is not (obstacles on both sides of a
        plate with a free edge: the two pushes twist it across an obstacle), the nodes
        closer to the obstacle than ``margin`` max|w| are moved back by :meth:`lift`.

        Args:
            weights: (i,) nonnegative weights of the constrained nodes (default all 1).
        """
        n = self.contact.size
        weights = np.ones(n) if weights is None else np.asarray(weights, dtype=float)
        self._factor(0.0, None)
        self._rhs.zeroEntries()
        self._add_zone(self._rhs, -weights[self.contact.owned_positions])
        u = self.problem.new_mode("start")
        self.ksp.solve(self._rhs, u.x.petsc_vec)
        u.x.scatter_forward()
        if not self._min(-self.oriented(u.x.petsc_vec)) > 0.0:
            self.lift(u, PUSH_MARGIN)
        return u

    def relax(self, vec: PETSc.Vec, free: str = "rotations") -> None:
        r"""Minimise :math:`a(u, u)` over the rotations (or the deflection) of ``vec``.

        A mode interpolated from another mesh, or built from nodal deflections, is not
        in this mesh's discrete Kirchhoff kernel: its assumed shear strain is not small
        and, on a thin plate, its quotient is orders of magnitude off. Minimising the
        energy over w with the rotations held (a Poisson-like problem: w integrates the
        rotations along the edges), then over the rotations with w held, restores it
        while keeping the shape. Each is a solve with a block of A (the free DOFs'
        rows and columns; :data:`RELAX_OPTIONS`). Should that solver not converge, the
        whole matrix is factorised with the held DOFs given a stiff diagonal
        (:math:`10^8 \max \mathrm{diag} A`, so they move by 1e-8 of the correction).

        Args:
            vec: The W-vector, changed in place.
            free: "rotations" or "deflection": the DOFs that move.
        """
        if free not in ("rotations", "deflection"):
            raise ValueError(f'free must be "rotations" or "deflection", got {free!r}')
        self.A.mult(vec, self._rhs)
        self._rhs.scale(-1.0)
        local, ksp, rhs, step = self._block(free)
        rhs.array[:] = self._rhs.array_r[local]
        ksp.solve(rhs, step)
        if int(ksp.getConvergedReason()) > 0:  # type: ignore[call-overload]
            vec.array[local] += np.asarray(step.array_r, dtype=np.float64)
            return
        logger.debug("relax: the %s block's solver did not converge; factorising", free)
        held = np.zeros(vec.getLocalSize(), dtype=bool)
        held[self.problem.owned_w_dofs] = True
        if free == "deflection":
            held = ~held
        self._factor(0.0, None, stiff=(held, self._held_diagonal()))
        self._rhs.array[held] = 0.0
        self.ksp.solve(self._rhs, self._y1)
        self._y1.array[held] = 0.0
        vec.axpy(1.0, self._y1)

    def _block(self, free: str) -> tuple[npt.NDArray[np.int64], PETSc.KSP, PETSc.Vec, PETSc.Vec]:
        """``free``'s owned DOFs (local numbers), the solver of A's block there, work vectors."""
        if free not in self._blocks:
            mine = np.zeros(self.A.getLocalSize()[0], dtype=bool)
            mine[self.problem.owned_w_dofs] = True
            if free == "rotations":
                mine = ~mine
            local = np.flatnonzero(mine)
            start = self.A.getOwnershipRange()[0]
            rows = PETSc.IS().createGeneral((start + local).astype(PETSc.IntType), comm=self.A.comm)
            block = self.A.createSubMatrix(rows, rows)
            rows.destroy()
            block.setOption(PETSc.Mat.Option.SPD, True)
            ksp = PETSc.KSP().create(self.A.comm)
            ksp.setOperators(block)
            tag = "w" if free == "deflection" else "theta"
            set_options(ksp, f"{self.prefix}relax_{tag}_", RELAX_OPTIONS)
            step, rhs = block.createVecs()
            block.destroy()  # the KSP holds a reference
            self._blocks[free] = (local, ksp, rhs, step)
        return self._blocks[free]

    def relax_rotations(self, vec: PETSc.Vec) -> None:
        """:meth:`relax` over the rotations."""
        self.relax(vec, "rotations")

    def clip(self, u: dolfinx.fem.Function, margin: float) -> int:
        """Move the deflection of the nodes closer to the obstacle than ``margin`` max|w| back.

        Each such node gets the gap ``margin`` max|w| exactly (its rotations are left;
        call :meth:`relax` after). For a mode interpolated from a coarser mesh the
        nodes are few and the changes of the order of the interpolation error.

        Returns:
            The number of nodes moved (over all ranks).
        """
        vec = u.x.petsc_vec
        limit = -margin * self.problem.max_abs_w(vec)
        z = self.oriented(vec)
        moved = z > limit
        vec.array[self._dofs[moved]] = self._signs[moved] * limit
        u.x.scatter_forward()
        return int(self.comm.allreduce(int(moved.sum()), op=MPI.SUM))

    def lift(self, u: dolfinx.fem.Function, margin: float) -> int:
        r"""Move the nodes closer to the obstacle than ``margin`` max|w| back, smoothly.

        The correction :math:`c` is the deformation of least energy :math:`a(c, c)` that
        gives each such node the gap ``margin`` max|w| exactly (its deflection held by a
        stiff diagonal, as in :meth:`relax`; one factorisation). Unlike moving the nodes
        alone (:meth:`clip`), it keeps the mode in the discrete Kirchhoff kernel: on a
        thin clamped plate a mode carried from a coarser mesh keeps its quotient within
        a few per cent instead of gaining a third. Nodes that the correction still
        leaves too close are then clipped.

        Returns:
            The number of nodes moved by the correction (over all ranks).
        """
        vec = u.x.petsc_vec
        limit = -margin * self.problem.max_abs_w(vec)
        z = self.oriented(vec)
        moved = z > limit
        count = int(self.comm.allreduce(int(moved.sum()), op=MPI.SUM))
        if count:
            held = np.zeros(vec.getLocalSize(), dtype=bool)
            held[self._dofs[moved]] = True
            big = self._held_diagonal()
            self._factor(0.0, None, stiff=(held, big))
            self._rhs.zeroEntries()
            self._rhs.array[self._dofs[moved]] = big * self._signs[moved] * (limit - z[moved])
            self.ksp.solve(self._rhs, self._y1)
            vec.axpy(1.0, self._y1)
            u.x.scatter_forward()
        self.clip(u, margin)
        return count

    def negative_part(self, vec: PETSc.Vec, sign: float = 1.0) -> dolfinx.fem.Function:
        """The mode ``sign * vec`` with its deflection set to 0 where it crosses the obstacle.

        The rotations are relaxed (:meth:`relax_rotations`); the result is not yet
        strictly inside the cone (see :meth:`make_interior`).
        """
        u = self.problem.new_mode("start")
        u.x.petsc_vec.array[:] = sign * vec.array_r
        z = self.oriented(u.x.petsc_vec)
        u.x.petsc_vec.array[self._dofs[z > 0.0]] = 0.0
        self.relax_rotations(u.x.petsc_vec)
        u.x.scatter_forward()
        return u

    def make_interior(
        self,
        u: dolfinx.fem.Function,
        margin: float = PUSH_MARGIN,
        push: dolfinx.fem.Function | None = None,
    ) -> dolfinx.fem.Function:
        """Add the pressure deflection to ``u`` so that it lies strictly inside the cone.

        The deflection ``push`` (default :meth:`pressure_mode` with unit weights) is
        added with the smallest amplitude that gives every constrained node a gap of at
        least ``margin`` max|w(u)| (node by node: a node next to a clamped edge, where
        the pressure deflection is small, asks for much only if u crosses there).
        """
        push = push if push is not None else self.pressure_mode()
        gap_push = -self.oriented(push.x.petsc_vec)
        if not self._min(gap_push) > 0.0:
            raise ValueError("the pressure deflection does not lie inside the cone")
        need = self.oriented(u.x.petsc_vec) + margin * self.problem.max_abs_w(u.x.petsc_vec)
        short = need > 0.0
        amount = max(self._max(need[short] / gap_push[short]), 0.0)
        if amount > 0.0:
            u.x.petsc_vec.axpy(amount, push.x.petsc_vec)
            u.x.scatter_forward()
        return u

    # -- the method --------------------------------------------------------------------
    def _normalize(self, vec: PETSc.Vec) -> None:
        self.B.mult(vec, self._Bu)
        b = _dot(vec, self._Bu)
        if not b > 0.0:
            raise FloatingPointError("b(u, u) <= 0: the mode carries no geometric stiffness")
        vec.scale(1.0 / math.sqrt(b))

    def _merit(self, vec: PETSc.Vec, mu_abs: float) -> float:
        """Barrier objective of the normalised ``vec`` (inf outside the cone)."""
        gap = -self.oriented(vec)
        if self._min(gap) <= 0.0:
            return math.inf
        self.A.mult(vec, self._Au)
        return 0.5 * _dot(vec, self._Au) - mu_abs * self._sum(np.log(gap).sum())

    def solve(
        self,
        mode: dolfinx.fem.Function,
        *,
        load: float | None = None,
        push: npt.NDArray[np.float64] | None = None,
        mu: float = 1e-2,
        mu_min: float = 1e-12,
        max_steps: int = 100,
        on_solved: Callable[[BarrierPoint], NewtonStatus | None] | None = None,
        on_step: Callable[[BarrierPoint], NewtonStatus | None] | None = None,
    ) -> tuple[BarrierPoint, NewtonRecord]:
        r"""Run the method from ``mode`` (strictly inside the cone; updated in place).

        Args:
            mode: Start, strictly inside the cone; becomes the final iterate.
            load: Start :math:`\lambda` (default the Rayleigh quotient of ``mode``).
            push: Start :math:`\nu` (default :math:`\mu/g`); entries below
                :math:`10^{-3}\mu/g` are raised to it.
            mu: Start scaled barrier parameter.
            mu_min: The run converges when the barrier problem at ``mu_min`` is solved.
            max_steps: Newton steps allowed.
            on_solved: Called with the iterate (its ``mu`` the parameter solved for)
                each time the barrier problem at a parameter below the start one is
                solved, before the parameter is lowered; a status it returns ends the
                run with that status (``MET_BEFORE``: the caller has been on this
                central path before; ``READ``: the caller has read the critical state
                off the iterate).
            on_step: Called likewise with the iterate (its ``mu`` the current
                parameter) at each step below the start parameter where no barrier
                problem was found solved (so that ``on_solved`` was not called).

        Returns:
            The final iterate and the record of the run.
        """
        opts = self.options
        t0 = time.perf_counter()
        f0 = self.factorizations
        record = NewtonRecord()
        u = mode.x.petsc_vec
        self._normalize(u)
        gap = -self.oriented(u)
        if not self._min(gap) > 0.0:
            raise ValueError("InteriorPointNewton.solve: the start is not inside the cone")
        self.A.mult(u, self._Au)
        lam = _dot(u, self._Au) if load is None else float(load)
        nu = np.asarray(push, dtype=float) if push is not None else None
        keep = True
        mu_abs = math.nan
        plain_first = opts.plain_first
        watch = _StallWatch(opts.stall_steps)  # in a run that lowers mu
        mu_start = mu
        for step in range(max_steps + 1):
            self.A.mult(u, self._Au)
            self.B.mult(u, self._Bu)
            gap = -self.oriented(u)
            w_scale = self.problem.max_abs_w(u)
            f_scale = lam * float(self._Bu.norm(PETSc.NormType.INFINITY))
            if not (math.isfinite(f_scale) and f_scale > 0.0):
                record.status = NewtonStatus.BREAKDOWN
                break
            scale = f_scale * w_scale
            mu_abs = mu * scale
            if nu is None:
                nu = mu_abs / gap
            elif step == 0:
                nu = np.maximum(nu, 1e-3 * mu_abs / gap)
            self._Au.copy(self._Fu)
            self._Fu.axpy(-lam, self._Bu)
            self._add_zone(self._Fu, nu)
            e_u = float(self._Fu.norm(PETSc.NormType.INFINITY)) / f_scale
            floor = max(opts.residual_floor, self._rounding(u, lam) / f_scale)
            rel_u = float(self._Fu.norm()) / float(self._Au.norm())
            e_c = self._max(np.abs(nu * gap - mu_abs)) / scale if gap.size else 0.0
            e_c = max(e_c, 0.0)
            record.history.append((lam, mu, e_u, e_c))
            logger.debug(
                "ipm step %d: lambda %.12g mu %.1e e_u %.2e e_c %.2e rel_u %.2e",
                step, lam, mu, e_u, e_c, rel_u,
            )  # fmt: skip
            # -- barrier parameter ---------------------------------------------------
            if keep and rel_u <= opts.keep_mu_until:
                keep = False
            if not keep:
                mu, e_c, solved = self._lower(mu, mu_min, e_u, e_c, floor, nu * gap, scale)
                mu_abs = mu * scale
                # (Watched first: a run that stops here does not compute a next step.)
                stalled = mu_min < mu_start and watch.stalled(e_u)
                converged = (
                    mu <= mu_min
                    and e_u <= max(opts.kappa_eps * mu, floor)
                    and (e_c <= opts.kappa_eps * mu)
                )
                # The hooks: on_solved where a barrier problem below the start one was
                # found solved, else on_step (below the start parameter; not at the
                # last step: its next direction would be computed for nothing).
                hook, at = (on_solved, solved) if solved < mu_start else (on_step, mu)
                hook = None if hook is on_step and converged else hook
                if hook is not None and at < mu_start and not stalled:
                    assert nu is not None
                    stop = self._call_hook(
                        hook, BarrierPoint(mode, lam, nu, at), mu_abs, plain_first
                    )
                    if stop is not None:
                        record.status = stop
                        break
                if converged:
                    record.status = NewtonStatus.CONVERGED
                    break
                if stalled:
                    record.status = NewtonStatus.STALLED
                    break
            if step == max_steps:
                record.status = NewtonStatus.MAX_STEPS
                break
            # -- Newton direction with inertia control ----------------------------------
            pending = self._take_pending()
            direction = (
                pending[0] if pending else self.direction(u, lam, nu, gap, mu_abs, plain_first)
            )
            if direction is None:
                record.status = NewtonStatus.INERTIA
                break
            dlam, dz, dnu = direction
            # Near a stationary point the unmodified K had the wrong inertia: a saddle
            # of the barrier problem, left along negative curvature.
            saddle = plain_first and not pending and e_u <= opts.local_residual
            moved = self._curvature_step(u, lam, gap, mu_abs) if saddle else None
            if moved is not None:
                lam, nu = moved, mu_abs / (-self.oriented(u))
                record.steps += 1
                record.curvature_steps += 1
                continue
            # -- step length ------------------------------------------------------------
            closing = dz > 0.0  # the gap closes: -dz < 0
            alpha_max = min(1.0, self._min(opts.fraction * gap[closing] / dz[closing]))
            alpha_max = min(alpha_max, 0.5 * lam / max(abs(dlam), 1e-300))  # |dlam| <= lam/2
            alpha = self._line_search(u, mu_abs, alpha_max, dz, gap, e_u)
            plain_first = opts.plain_first and (alpha == 1.0 or self._last_correction == 0.0)
            logger.debug(
                "ipm step %d: alpha %.3g (boundary %.3g) dlambda %.3g correction %.3g",
                step, alpha, alpha_max, dlam, self._last_correction,
            )  # fmt: skip
            lam += alpha * dlam
            nu = np.maximum(nu + dnu, (1.0 - opts.fraction) * nu)
            record.steps += 1
        self._pending = None
        record.factorizations = self.factorizations - f0
        record.seconds = time.perf_counter() - t0
        record.load = lam
        record.mu = mu
        mode.x.scatter_forward()
        assert nu is not None
        return BarrierPoint(mode, lam, nu, mu), record

    def _call_hook(
        self,
        hook: Callable[[BarrierPoint], NewtonStatus | None],
        point: BarrierPoint,
        mu_abs: float,
        plain_first: bool,
    ) -> NewtonStatus | None:
        """Call a run's ``on_solved`` hook; the next step is (``mu_abs``, ``plain_first``)."""
        self._next = (mu_abs, plain_first)
        try:
            return hook(point)
        finally:
            self._next = None

    def _take_pending(self) -> tuple[_Direction | None] | None:
        """The next direction if the hook computed it (:meth:`predicted_contact_set`)."""
        pending, self._pending = self._pending, None
        return pending

    def _lower(
        self,
        mu: float,
        mu_min: float,
        e_u: float,
        e_c: float,
        floor: float,
        products: npt.NDArray[np.float64],
        scale: float,
    ) -> tuple[float, float, float]:
        r"""The barrier parameter lowered while its barrier problem counts as solved.

        ``products``: :math:`\nu_k g_k`; ``scale``: that of the complementarity. Returns
        the new parameter, the scaled complementarity residual there, and the parameter
        whose barrier problem was found solved (inf if ``mu`` stays).
        """
        opts = self.options
        start = mu
        while (
            mu > mu_min
            and max(e_u, e_c) <= max(opts.kappa_eps * mu, floor)
            and (e_c <= opts.kappa_eps * mu)
        ):
            mu = max(mu_min, min(opts.kappa_mu * mu, mu**opts.theta_mu))
            e_c = max(self._max(np.abs(products - mu * scale)) / scale, 0.0)
        return mu, e_c, (start if mu < start else math.inf)

    def direction(
        self,
        u: PETSc.Vec,
        lam: float,
        nu: npt.NDArray[np.float64],
        gap: npt.NDArray[np.float64],
        mu_abs: float,
        plain_first: bool = True,
    ) -> _Direction | None:
        r"""The Newton direction at (u, lambda, nu) for the absolute barrier ``mu_abs``.

        Solves the linearised optimality conditions (module docstring) with the
        inertia-controlled factorisation of K; :math:`\delta u` is left in ``self._du``
        (valid until the next call). ``self._Fu`` must hold :math:`F_u` and
        ``self._Bu`` :math:`Bu` at u.

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
        # from a minimiser) the correction starts from a third of the last one.
        if opts.plain_first:
            memory = self._delta_last
        else:
            memory = self._last_correction if self._last_correction > 1e-11 else 0.0
        retry = memory / 3.0 if memory else opts.delta_first
        limit = min(opts.delta_max, 1.0) if opts.metric == "geometric" else opts.delta_max
        delta = retry if memory and not plain_first else 0.0
        while True:
            nneg, nzero = self._factor(lam, sigma, delta)
            self.ksp.solve(self._Bu, self._y2)
            by2 = _dot(self._Bu, self._y2)
            if nzero == 0 and nneg + (1 if by2 > 0.0 else 0) == 1:
                break
            if delta >= limit:
                return None
            delta = min(limit, retry if delta == 0.0 else delta * (8.0 if memory else 100.0))
        self._last_correction = delta
        if delta:
            self._delta_last = delta
        self._Fu.copy(self._rhs)
        self._rhs.scale(-1.0)
        self._add_zone(self._rhs, f_c / gap)
        self.ksp.solve(self._rhs, self._y1)
        self._y1.copy(self._du)
        dlam = self._add_load_step(u, self._du, by2)
        dz = self.oriented(self._du)
        dnu = (-f_c + nu * dz) / gap
        return dlam, dz, dnu

    def _probe(self) -> PETSc.Vec:
        """Start of the negative-curvature Krylov space: a fixed pseudo-random field.

        A function of each DOF's coordinates (not of its number), so that the same
        direction is found on any number of ranks; not symmetric, so that it sees
        antisymmetric directions on a symmetric plate.
        """
        length = self.problem.spec.plate.length

        def noise(x: npt.NDArray[np.float64], c: float) -> npt.NDArray[np.float64]:
            return np.modf(np.sin(12.9898 * x[0] / length + 78.233 * x[1] / length + c) * 4.3e4)[0]

        f = self.problem.new_mode("probe")
        f.sub(0).interpolate(lambda x: noise(x, 0.0))
        f.sub(1).interpolate(lambda x: np.vstack([noise(x, 1.0), noise(x, 2.0)]))
        f.x.scatter_forward()
        return f.x.petsc_vec.copy()

    def negative_curvature(self, u: PETSc.Vec, lam: float) -> tuple[float, PETSc.Vec, float] | None:
        r"""The direction of most negative curvature of K on the tangent space.

        Uses the last factorisation, :math:`K_\delta = K + \delta M` with
        :math:`\delta` the last step's correction (:meth:`direction`, which also left
        :math:`Bu` in ``self._Bu`` and :math:`y_2 = K_\delta^{-1}Bu` in ``self._y2``).
        Rayleigh–Ritz on the Krylov space of :math:`K_\delta^{-1} M` (``curvature_vectors``
        vectors, one triangular solve each), M-orthonormal and projected on the tangent
        space :math:`(Bu)^Tv = 0` along :math:`y_2`: since :math:`K_\delta^{-1}M` has the
        eigenvalues :math:`1/(\theta + \delta)` for the eigenvalues :math:`\theta` of
        (K, M) on the tangent space, the most negative :math:`\theta` dominates.

        Returns:
            :math:`\theta = \min v^TKv / v^TMv` over the Krylov space, its direction
            v (scaled to :math:`v^TBv = 1`; a work vector, valid until the next call)
            and :math:`v^TKv`;
            None when the last step needed no correction (``delta = 0``), no vector
            was wanted, or v carries no geometric stiffness (:math:`v^TBv \le 0`,
            possible under shear). The Newton direction in ``self._du`` is left as it
            was.
        """
        opts = self.options
        delta = self._last_correction
        if not (opts.curvature_vectors and delta > 0.0):
            return None
        if not self._krylov:
            extra = opts.curvature_vectors + 3  # the metric, work, direction, basis
            self._krylov = [self._probe()] + [u.duplicate() for _ in range(extra)]
        probe, metric, work, d, *basis = self._krylov
        self._reg.copy(metric)  # M: the diagonal whose multiple delta M regularises K
        if opts.metric == "geometric":
            metric.scale(lam)
        # Projected on the tangent space along y2 = K_delta^{-1} Bu, which keeps every
        # vector in the range of K_delta^{-1} on the DOFs that M weighs (the rotations,
        # which carry no geometric stiffness, stay at their least energy).
        by2 = _dot(self._Bu, self._y2)
        if by2 == 0.0:
            return None
        source, size = probe, 0
        for v in basis:
            work.pointwiseMult(metric, source)
            self.ksp.solve(work, v)
            v.axpy(-_dot(self._Bu, v) / by2, self._y2)  # tangent
            work.pointwiseMult(metric, v)
            before = _dot(work, v)
            for w in basis[:size]:  # M-orthogonal to the previous vectors
                work.pointwiseMult(metric, w)
                v.axpy(-_dot(work, v), w)
            work.pointwiseMult(metric, v)
            norm2 = _dot(work, v)
            if not norm2 > 1e-20 * before:  # the space is exhausted: rounding only
                break
            v.scale(1.0 / math.sqrt(norm2))
            source, size = v, size + 1
        if size == 0:
            return None
        # The projected pencil (V^T K V, V^T M V), with K v = K_delta v - delta M v.
        H, G = np.empty((size, size)), np.empty((size, size))
        for j, vj in enumerate(basis[:size]):
            self.K.mult(vj, self._trial)
            work.pointwiseMult(metric, vj)
            self._trial.axpy(-delta, work)
            for i, vi in enumerate(basis[:size]):
                H[i, j] = _dot(vi, self._trial)
                G[i, j] = _dot(vi, work)
        try:
            L = np.linalg.cholesky(0.5 * (G + G.T))
        except np.linalg.LinAlgError:
            return None  # (the basis is M-orthonormal: G is the identity up to rounding)
        theta, Y = np.linalg.eigh(np.linalg.solve(L, np.linalg.solve(L, 0.5 * (H + H.T)).T))
        coef = np.linalg.solve(L.T, Y[:, 0])
        d.zeroEntries()
        for c, v in zip(coef, basis[:size], strict=True):
            d.axpy(float(c), v)
        d.axpy(-_dot(self._Bu, d) / by2, self._y2)  # tangent again (rounding)
        self.B.mult(d, work)
        norm2 = _dot(d, work)
        if not norm2 > 0.0:  # (B is indefinite under shear)
            return None
        d.scale(1.0 / math.sqrt(norm2))
        self.K.mult(d, self._trial)  # K v = K_delta v - delta M v
        work.pointwiseMult(metric, d)
        curvature = _dot(d, self._trial) - delta * _dot(d, work)
        return float(theta[0]), d, curvature

    def _curvature_step(
        self, u: PETSc.Vec, lam: float, gap: npt.NDArray[np.float64], mu_abs: float
    ) -> float | None:
        r"""A step along the direction of most negative curvature (in place).

        Taken when :meth:`negative_curvature` finds :math:`\theta <
        -` ``saddle_curvature``; the step goes along :math:`\pm v` (downhill on the
        barrier objective) up to the fraction to the boundary, and backtracks to a
        decrease of at least 1e-4 of the quadratic model's.

        Returns:
            The Rayleigh quotient of the new (normalised) iterate, or None (``u``
            unchanged) when no curvature below the threshold or no decrease was found.
        """
        opts = self.options
        found = self.negative_curvature(u, lam)
        if found is None or not found[0] < -opts.saddle_curvature:
            return None
        theta, d, curvature = found
        dz = self.oriented(d)
        self.A.mult(u, self._Au)
        slope = _dot(self._Au, d) + mu_abs * self._sum((dz / gap).sum())
        sign = -1.0 if slope > 0.0 else 1.0
        closing = sign * dz > 0.0
        t = min(1.0, opts.fraction * self._min(gap[closing] / (sign * dz[closing])))
        phi0 = self._merit(u, mu_abs)
        for _ in range(30):
            u.copy(self._trial)
            self._trial.axpy(sign * t, d)
            model = t * sign * slope + 0.5 * t * t * curvature
            try:
                self._normalize(self._trial)
            except FloatingPointError:  # b(u, u) <= 0 there (shear): shorter
                t *= 0.5
                continue
            if self._merit(self._trial, mu_abs) <= phi0 + 1e-4 * model:
                break
            t *= 0.5
        else:
            return None
        logger.debug("ipm curvature step: theta %.3g, step %.3g", theta, t)
        self._trial.copy(u)
        self.A.mult(u, self._Au)
        return _dot(u, self._Au)

    def _add_load_step(self, u: PETSc.Vec, y: PETSc.Vec, by2: float) -> float:
        r""":math:`\delta\lambda` from the linearised normalisation; ``y`` becomes :math:`\delta u`.

        ``y`` solves K y = (right-hand side without the load term), ``self._y2`` is
        :math:`K^{-1}Bu` and ``by2`` :math:`(Bu)^Ty_2`; :math:`\delta u = y + \delta\lambda\,y_2`.
        """
        dlam = (-0.5 * (_dot(u, self._Bu) - 1.0) - _dot(self._Bu, y)) / by2
        y.axpy(dlam, self._y2)
        return dlam

    def predicted_contact_set(self, point: BarrierPoint) -> npt.NDArray[np.int64]:
        r"""The contact set Z that the central path through ``point`` tends to.

        The Newton direction for :math:`\mu = 0` (the affine-scaling predictor) at
        ``point`` moves each constrained node's gap :math:`g` by :math:`-\delta z`
        and its push to :math:`\nu\,\delta z/g`. Of a node that ends touching, the
        gap tends to zero and the push stays; of one that ends free, the reverse. Z
        holds the nodes whose gap falls by a larger fraction than their push, i.e.
        :math:`\delta z > g/2` (the Tapia indicator: El-Bakry, Tapia & Zhang, *A study
        of indicators for identifying zero variables in interior-point methods*, SIAM
        Rev. 36, 1994), and those whose predicted gap is at the tolerance ``tau``.
        Read where the barrier problem at a small parameter (:math:`10^{-9}`) is
        solved, it is on most plates the set read off the gaps at :math:`10^{-14}`,
        some Newton steps later.

        Inside a run's ``on_solved`` hook it costs one solve: the factorisation is that
        of the run's next step, which is computed here and kept for it (the run goes on
        exactly as without the call). Elsewhere it factorises K at ``point`` once.
        Same on every rank (node numbers, sorted).
        """
        u = point.mode.x.petsc_vec
        lam, nu = point.load, point.push
        gap = -self.oriented(u)
        if self._next is not None:  # inside the hook: the run's next direction
            mu_abs, plain_first = self._next
            step = self.direction(u, lam, nu, gap, mu_abs, plain_first)
            self._pending = (step,)
            if step is not None:
                # The same system for mu = 0: the right-hand side gains E(mu_abs / g).
                self._rhs.zeroEntries()
                self._add_zone(self._rhs, mu_abs / gap)
                self.ksp.solve(self._rhs, self._trial)
                self._trial.axpy(1.0, self._y1)
                self._add_load_step(u, self._trial, _dot(self._Bu, self._y2))
                dz = self.oriented(self._trial)
        else:
            self._residual(u, lam, nu)
            memory = (self._last_correction, self._delta_last)
            step = self.direction(u, lam, nu, gap, 0.0)
            self._last_correction, self._delta_last = memory
            if step is not None:
                dz = step[1]
        tol = self.problem.tau * self.problem.max_abs_w(u)
        touching = gap <= tol if step is None else (2.0 * dz > gap) | (gap - dz <= tol)
        mine = self.contact.owned_positions[touching]
        return np.sort(np.concatenate(self.comm.allgather(mine))).astype(np.int64)

    def _rounding(self, u: PETSc.Vec, lam: float) -> float:
        r"""Rounding level of :math:`F_u`: :math:`100\,\epsilon\,(|A| + \lambda|B|)|u|`.

        The largest entry; on thin plates it lies far above :math:`\epsilon |Au|`.
        """
        u.copy(self._trial)
        self._trial.abs()
        self._abs_A.mult(self._trial, self._rhs)
        self._rhs.abs()
        self._abs_B.mult(self._trial, self._y1)
        self._rhs.axpy(lam, self._y1)
        eps = float(np.finfo(float).eps)
        return 100.0 * eps * float(self._rhs.norm(PETSc.NormType.INFINITY))

    def _line_search(
        self,
        u: PETSc.Vec,
        mu_abs: float,
        alpha: float,
        dz: npt.NDArray[np.float64],
        gap: npt.NDArray[np.float64],
        e_u: float,
    ) -> float:
        """Backtrack from ``alpha`` on the barrier objective; apply the step to ``u``."""
        local = e_u <= self.options.local_residual
        phi0 = self._merit(u, mu_abs)
        self.A.mult(u, self._Au)
        slope = _dot(self._Au, self._du) + mu_abs * self._sum((dz / gap).sum())
        for _ in range(30):
            u.copy(self._trial)
            self._trial.axpy(alpha, self._du)
            self._normalize(self._trial)
            if local or slope >= 0.0:
                break
            phi = self._merit(self._trial, mu_abs)
            if phi <= phi0 + 1e-4 * alpha * slope + 1e-10 * abs(phi0):
                break
            alpha *= 0.5
        self._trial.copy(u)
        return alpha

    def escape(self, point: BarrierPoint, lower: PETSc.Vec, fraction: float = 0.99) -> bool:
        r"""Leave a saddle along a lower mode of the contact-reduced pencil (in place).

        At a stationary point whose contact-reduced pencil has an eigenvector ``lower``
        with a smaller load, :math:`R` decreases along :math:`u + t v` (v the part of
        ``lower`` B-orthogonal to u) in both directions; the step goes, in the
        direction that lowers R more, to ``fraction`` of the way to the first node
        that would touch the obstacle. (Two weakly coupled buckles with nearly equal
        loads: the barrier keeps both, the lower antisymmetric combination moves the
        weight to the one with the smaller load until the other lies on the obstacle.)

        Returns:
            Whether the quotient decreased (the mode is then rescaled, the push reset).
        """
        u = point.mode.x.petsc_vec
        self.B.mult(u, self._Bu)
        lower.copy(self._du)
        self._du.axpy(-_dot(self._du, self._Bu), u)
        self.B.mult(self._du, self._rhs)
        norm = _dot(self._du, self._rhs)
        if not norm > 0.0:
            return False
        self._du.scale(1.0 / math.sqrt(norm))
        gap = -self.oriented(u)
        dz = self.oriented(self._du)
        self.A.mult(u, self._Au)
        r0 = _dot(u, self._Au)
        best, best_t = r0, 0.0
        for sign in (1.0, -1.0):
            moving = sign * dz > 0.0
            t = fraction * self._min(gap[moving] / (sign * dz[moving]))
            t = min(t, 1e3) if math.isfinite(t) else 1e3
            u.copy(self._trial)
            self._trial.axpy(sign * t, self._du)
            self._normalize(self._trial)
            self.A.mult(self._trial, self._Au)
            r = _dot(self._trial, self._Au)
            if r < best:
                best, best_t = r, sign * t
        if best_t == 0.0:
            return False
        u.axpy(best_t, self._du)
        self._normalize(u)
        point.mode.x.scatter_forward()
        point.load = best
        self.B.mult(u, self._Bu)
        f_scale = best * float(self._Bu.norm(PETSc.NormType.INFINITY))
        point.push = point.mu * f_scale * self.problem.max_abs_w(u) / (-self.oriented(u))
        return True

    def _residual(
        self, u: PETSc.Vec, lam: float, nu: npt.NDArray[np.float64] | None = None
    ) -> None:
        r""":math:`Au`, :math:`Bu`, :math:`F_u = Au - \lambda Bu\ (+ E\nu)` into work vectors."""
        self.A.mult(u, self._Au)
        self.B.mult(u, self._Bu)
        self._Au.copy(self._Fu)
        self._Fu.axpy(-lam, self._Bu)
        if nu is not None:
            self._add_zone(self._Fu, nu)

    def reaction_push(
        self, mode: dolfinx.fem.Function, load: float, mu: float
    ) -> npt.NDArray[np.float64]:
        r"""Push estimate at ``mode``: the reaction :math:`-z(Au - \lambda Bu)`.

        At least :math:`\mu/g` at every node. ``mode`` must lie strictly inside the
        cone; it is normalised in place.
        """
        vec = mode.x.petsc_vec
        self._normalize(vec)
        self._residual(vec, load)
        f_scale = load * float(self._Bu.norm(PETSc.NormType.INFINITY))
        gap = -self.oriented(vec)
        mu_abs = mu * f_scale * self.problem.max_abs_w(vec)
        return np.maximum(-self.oriented(self._Fu), mu_abs / gap)

    def from_candidate(self, cand: Any, mu: float) -> BarrierPoint:
        r"""A barrier point near an exact critical state ``cand`` (a :class:`Candidate`).

        The mode is pushed strictly inside the cone (by :math:`10^{-6}` of its
        amplitude); the push is :meth:`reaction_push`.
        """
        u = self.problem.new_mode("barrier")
        cand.mode.x.petsc_vec.copy(u.x.petsc_vec)
        u.x.scatter_forward()
        self.make_interior(u, margin=1e-6)
        push = self.reaction_push(u, float(cand.load), mu)
        return BarrierPoint(u, float(cand.load), push, mu)

    def contact_set(self, point: BarrierPoint) -> npt.NDArray[np.int64]:
        r"""The nodes whose gap is at most :math:`\tau \max|w|`: the contact set Z.

        Same on every rank (node numbers, sorted). A node in the degenerate part of the
        obstacle (gap and push both near zero) counts as touching only when its gap is
        at the solver's tolerance.
        """
        u = point.mode.x.petsc_vec
        gap = -self.oriented(u) / self.problem.max_abs_w(u)
        mine = self.contact.owned_positions[gap <= self.problem.tau]
        return np.sort(np.concatenate(self.comm.allgather(mine))).astype(np.int64)

    def destroy(self) -> None:
        """Destroy the matrix, its factorisation and the work vectors (collective)."""
        if self._reg is self._diag_A:
            self._reg = None
        for _, ksp, rhs, step in getattr(self, "_blocks", {}).values():
            for obj in (ksp, rhs, step):
                obj.destroy()
        self._blocks = {}
        # (K and its KSP are the problem's shared factorisation: not destroyed here.)
        release(self, "_B_on_A", "_diag_A", "_diag", "_reg")
        release(self, "_Au", "_Bu", "_Fu", "_y1", "_y2", "_rhs", "_du", "_trial")
        for vec in getattr(self, "_krylov", []):
            vec.destroy()
        self._krylov = []

    def __del__(self) -> None:
        self.destroy()
