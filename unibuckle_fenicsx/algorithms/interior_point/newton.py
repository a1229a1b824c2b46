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

which tend to the KKT conditions of the critical state as :math:`\mu \to 0`. One Newton
step is one numeric :math:`LDL^T` and two solves (:mod:`.kernel`); a step along a
direction of negative curvature leaves a saddle (:mod:`.curvature`); the starts are
points strictly inside the cone (:mod:`.starts`).

Why a barrier. On thin long plates the critical mode lies almost flat on the obstacle:
thousands of constrained nodes have both a gap and a push close to zero. An active-set
step must decide for each of them whether it touches; the decisions flip from one step
to the next and their number grows with the mesh. The barrier treats those nodes
smoothly, and Newton's method on the barrier problem needs about the same number of
steps on every mesh (the nested route, ``algorithms.chain``, starts each mesh from the
previous one's solution).

Safeguards (Nocedal & Wright, *Numerical Optimization*, 2nd ed., ch. 19; Wächter &
Biegler, Math. Program. 106, 2006, the IPOPT paper): inertia control, the
negative-curvature step, the fraction to the boundary for the gap (the push is updated
componentwise, each entry kept above ``1 - fraction`` of its old value), a backtracking
line search on the barrier objective while the residual is large, full steps near the
solution; the barrier parameter is kept while :math:`\|F_u\|/\|Au\|` exceeds
``keep_mu_until``, then decreased superlinearly (:math:`\mu \leftarrow
\min(\kappa_\mu\mu, \mu^{\theta_\mu})`) each time the barrier problem is solved to
:math:`\kappa_\epsilon\mu`. The complementarity is scaled by
:math:`\lambda\|Bu\|_\infty\max|w|` (a push times a gap), not by :math:`\|Au\|_\infty`,
which a prolonged mode's shear pollutes.

Written here because no library solves a nonconvex eigenproblem on a cone: PETSc's
TAO interior-point solvers need a convex (or unconstrained-Hessian) problem and no
normalisation constraint, SNES VI solves complementarity problems without the
eigenvalue.

Note:
    All decisions use values reduced over the ranks; every method is collective on the
    problem's communicator.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass

from petsc4py import PETSc

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms.interior_point.curvature import NegativeCurvature
from unibuckle_fenicsx.algorithms.interior_point.kernel import Direction, NewtonKernel, dot
from unibuckle_fenicsx.algorithms.interior_point.options import (
    BarrierPoint,
    NewtonOptions,
    NewtonRecord,
    NewtonStatus,
)
from unibuckle_fenicsx.algorithms.interior_point.starts import Starts
from unibuckle_fenicsx.la.options import Prefix
from unibuckle_fenicsx.la.ownership import Owner
from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.tolerances import DIVISION_FLOOR

__all__ = ["InteriorPointNewton", "StallWatch"]

logger = logging.getLogger(__name__)

#: A hook of a run: called with an iterate, it may end the run with a status.
Hook = Callable[[BarrierPoint], NewtonStatus | None]


@dataclass
class StallWatch:
    """Whether the residual has not halved in ``steps`` steps (``steps = 0``: never)."""

    steps: int
    best: float = math.inf
    since: int = 0

    def stalled(self, residual: float) -> bool:
        """Record ``residual``; whether it has not halved in ``steps`` steps."""
        if not self.steps:
            return False
        if residual <= 0.5 * self.best:
            self.best, self.since = residual, 0
        else:
            self.since += 1
        return self.since >= self.steps


@dataclass
class _Run:
    """The state of one run of :meth:`InteriorPointNewton.solve`."""

    mode: dolfinx.fem.Function
    lam: float
    nu: npt.NDArray[np.float64] | None
    mu: float
    mu_min: float
    mu_start: float
    plain_first: bool
    record: NewtonRecord
    watch: StallWatch
    on_solved: Hook | None
    on_step: Hook | None
    keep: bool = True
    mu_abs: float = math.nan


@dataclass(frozen=True)
class _Measure:
    """The residuals of the iterate: the gaps, scaled residuals, their floor and scale."""

    gap: npt.NDArray[np.float64]
    e_u: float
    e_c: float
    rel_u: float
    floor: float
    scale: float


class InteriorPointNewton(Owner):
    """The interior-point Newton method on one problem (owns its work vectors and solvers).

    The Newton matrix K and its :math:`LDL^T` are the mesh's
    :class:`~unibuckle_fenicsx.la.factor.SharedFactorization` (``problem.eigensolver``'s),
    whose symbolic analysis the shifted eigen solves and the certificate reuse.

    Args:
        problem: A problem with a rigid obstacle.
        options: Settings (default :class:`~.options.NewtonOptions`).
        prefix: Options prefix of the method's own solvers (the starts' relaxation).

    Attributes:
        kernel: The Newton step (:class:`~.kernel.NewtonKernel`).
        starts: Points strictly inside the cone (:class:`~.starts.Starts`).
        curvature: The negative-curvature step (:class:`~.curvature.NegativeCurvature`).

    Note:
        Construction, every method and :meth:`destroy` are collective.
    """

    def __init__(
        self,
        problem: UnilateralProblem,
        options: NewtonOptions | None = None,
        prefix: str = Prefix.IPM,
    ) -> None:
        self.kernel = NewtonKernel(problem, options)
        self.problem = problem
        self.options = self.kernel.options
        self.starts = Starts(self.kernel, prefix)
        self.curvature = NegativeCurvature(self.kernel)
        # Inside a run's on_solved hook: the next step's (mu_abs, plain_first), and its
        # direction once predicted_contact_set has computed it.
        self._next: tuple[float, bool] | None = None
        self._pending: tuple[Direction | None] | None = None

    def solve(
        self,
        mode: dolfinx.fem.Function,
        *,
        load: float | None = None,
        push: npt.NDArray[np.float64] | None = None,
        mu: float = 1e-2,
        mu_min: float = 1e-12,
        max_steps: int = 100,
        on_solved: Hook | None = None,
        on_step: Hook | None = None,
    ) -> tuple[BarrierPoint, NewtonRecord]:
        r"""Run the method from ``mode`` (strictly inside the cone; updated in place).

        Args:
            mode: Start, strictly inside the cone; becomes the final iterate.
            load: Start :math:`\lambda` (default the Rayleigh quotient of ``mode``).
            push: Start :math:`\nu` (default :math:`\mu/g`); entries below ``push_floor``
                times :math:`\mu/g` are raised to it.
            mu: Start scaled barrier parameter (in (0, 1); the default, 1e-2, lies well
                inside the cone's neighbourhood where the barrier is smooth).
            mu_min: The run converges when the barrier problem at ``mu_min`` is solved
                (the default, 1e-12, reads contact sets to the rounding of the gaps).
            max_steps: Newton steps allowed (>= 0).
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
        kernel = self.kernel
        t0 = time.perf_counter()
        f0 = kernel.factorizations
        u = mode.x.petsc_vec
        kernel.normalize(u)
        gap = -kernel.oriented(u)
        if not kernel.min(gap) > 0.0:
            raise ValueError("InteriorPointNewton.solve: the start is not inside the cone")
        kernel.A.mult(u, kernel.Au)
        run = _Run(
            mode=mode,
            lam=dot(u, kernel.Au) if load is None else float(load),
            nu=np.asarray(push, dtype=float) if push is not None else None,
            mu=mu,
            mu_min=mu_min,
            mu_start=mu,
            plain_first=self.options.plain_first,
            record=NewtonRecord(),
            watch=StallWatch(self.options.stall_steps),  # in a run that lowers mu
            on_solved=on_solved,
            on_step=on_step,
        )
        for step in range(max_steps + 1):
            residuals = self._measure(run, step)
            status = NewtonStatus.BREAKDOWN if residuals is None else self._barrier(run, residuals)
            if status is None and step == max_steps:
                status = NewtonStatus.MAX_STEPS
            if status is None and residuals is not None:
                status = self._advance(run, residuals, step)
            if status is not None:
                run.record.status = status
                break
        self._pending = None
        record = run.record
        record.factorizations = kernel.factorizations - f0
        record.seconds = time.perf_counter() - t0
        record.load = run.lam
        record.mu = run.mu
        mode.x.scatter_forward()
        assert run.nu is not None
        return BarrierPoint(mode, run.lam, run.nu, run.mu), record

    def _measure(self, run: _Run, step: int) -> _Measure | None:
        """The residuals at the iterate (and the push's start); None at a breakdown."""
        opts, kernel = self.options, self.kernel
        u = run.mode.x.petsc_vec
        kernel.A.mult(u, kernel.Au)
        kernel.B.mult(u, kernel.Bu)
        gap = -kernel.oriented(u)
        w_scale = self.problem.max_abs_w(u)
        f_scale = run.lam * float(kernel.Bu.norm(PETSc.NormType.INFINITY))
        if not (math.isfinite(f_scale) and f_scale > 0.0):
            return None
        scale = f_scale * w_scale
        run.mu_abs = run.mu * scale
        if run.nu is None:
            run.nu = run.mu_abs / gap
        elif step == 0:
            run.nu = np.maximum(run.nu, opts.push_floor * run.mu_abs / gap)
        nu = run.nu
        kernel.Au.copy(kernel.Fu)
        kernel.Fu.axpy(-run.lam, kernel.Bu)
        kernel.add_zone(kernel.Fu, nu)
        e_u = float(kernel.Fu.norm(PETSc.NormType.INFINITY)) / f_scale
        floor = max(opts.residual_floor, kernel.rounding(u, run.lam) / f_scale)
        rel_u = float(kernel.Fu.norm()) / float(kernel.Au.norm())
        # Collective on every rank, also one that owns no constrained node (-inf there).
        e_c = max(kernel.max(np.abs(nu * gap - run.mu_abs)) / scale, 0.0)
        run.record.history.append((run.lam, run.mu, e_u, e_c))
        logger.debug(
            "ipm step %d: lambda %.12g mu %.1e e_u %.2e e_c %.2e rel_u %.2e",
            step, run.lam, run.mu, e_u, e_c, rel_u,
        )  # fmt: skip
        return _Measure(gap, e_u, e_c, rel_u, floor, scale)

    def _barrier(self, run: _Run, m: _Measure) -> NewtonStatus | None:
        """Lower the barrier parameter where its problem is solved; call the hooks.

        Returns the status that ends the run (converged, stalled, or a hook's), or None.
        """
        opts = self.options
        if run.keep and m.rel_u <= opts.keep_mu_until:
            run.keep = False
        if run.keep:
            return None
        assert run.nu is not None
        mu, e_c, solved = self._lower(
            run.mu, run.mu_min, m.e_u, m.e_c, m.floor, run.nu * m.gap, m.scale
        )
        run.mu = mu
        run.mu_abs = mu * m.scale
        # (Watched first: a run that stops here does not compute a next step.)
        stalled = run.mu_min < run.mu_start and run.watch.stalled(m.e_u)
        converged = (
            mu <= run.mu_min
            and m.e_u <= max(opts.kappa_eps * mu, m.floor)
            and (e_c <= opts.kappa_eps * mu)
        )
        # The hooks: on_solved where a barrier problem below the start one was found
        # solved, else on_step (below the start parameter; not at the last step: its
        # next direction would be computed for nothing).
        hook, at = (run.on_solved, solved) if solved < run.mu_start else (run.on_step, mu)
        hook = None if hook is run.on_step and converged else hook
        if hook is not None and at < run.mu_start and not stalled:
            point = BarrierPoint(run.mode, run.lam, run.nu, at)
            stop = self._call_hook(hook, point, run.mu_abs, run.plain_first)
            if stop is not None:
                return stop
        if converged:
            return NewtonStatus.CONVERGED
        if stalled:
            return NewtonStatus.STALLED
        return None

    def _advance(self, run: _Run, m: _Measure, step: int) -> NewtonStatus | None:
        """One step: the Newton direction (or one of negative curvature) and its length.

        Returns INERTIA when the inertia correction failed, else None.
        """
        opts, kernel = self.options, self.kernel
        u = run.mode.x.petsc_vec
        assert run.nu is not None
        pending = self._take_pending()
        direction = (
            pending[0]
            if pending
            else kernel.direction(u, run.lam, run.nu, m.gap, run.mu_abs, run.plain_first)
        )
        if direction is None:
            return NewtonStatus.INERTIA
        dlam, dz, dnu = direction
        # Near a stationary point the unmodified K had the wrong inertia: a saddle of the
        # barrier problem, left along negative curvature.
        saddle = run.plain_first and not pending and m.e_u <= opts.local_residual
        moved = self.curvature.step(u, run.lam, m.gap, run.mu_abs) if saddle else None
        if moved is not None:
            run.lam, run.nu = moved, run.mu_abs / (-kernel.oriented(u))
            run.record.steps += 1
            run.record.curvature_steps += 1
            return None
        closing = dz > 0.0  # the gap closes: -dz < 0
        alpha_max = min(1.0, kernel.min(opts.fraction * m.gap[closing] / dz[closing]))
        bound = opts.max_load_step * run.lam / max(abs(dlam), DIVISION_FLOOR)
        alpha_max = min(alpha_max, bound)  # |dlam| <= max_load_step lam
        alpha = kernel.line_search(u, run.mu_abs, alpha_max, dz, m.gap, m.e_u)
        run.plain_first = opts.plain_first and (alpha == 1.0 or kernel.last_correction == 0.0)
        logger.debug(
            "ipm step %d: alpha %.3g (boundary %.3g) dlambda %.3g correction %.3g",
            step, alpha, alpha_max, dlam, kernel.last_correction,
        )  # fmt: skip
        run.lam += alpha * dlam
        run.nu = np.maximum(run.nu + dnu, (1.0 - opts.fraction) * run.nu)
        run.record.steps += 1
        return None

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

    def _take_pending(self) -> tuple[Direction | None] | None:
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
            e_c = max(self.kernel.max(np.abs(products - mu * scale)) / scale, 0.0)
        return mu, e_c, (start if mu < start else math.inf)

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
        kernel = self.kernel
        u = point.mode.x.petsc_vec
        lam, nu = point.load, point.push
        gap = -kernel.oriented(u)
        if self._next is not None:  # inside the hook: the run's next direction
            mu_abs, plain_first = self._next
            step = kernel.direction(u, lam, nu, gap, mu_abs, plain_first)
            self._pending = (step,)
            if step is not None:
                # The same system for mu = 0: the right-hand side gains E(mu_abs / g).
                kernel.rhs.zeroEntries()
                kernel.add_zone(kernel.rhs, mu_abs / gap)
                kernel.ksp.solve(kernel.rhs, kernel.trial)
                kernel.trial.axpy(1.0, kernel.y1)
                kernel.add_load_step(u, kernel.trial, dot(kernel.Bu, kernel.y2))
                dz = kernel.oriented(kernel.trial)
        else:
            kernel.residual(u, lam, nu)
            memory = (kernel.last_correction, kernel.delta_last)
            step = kernel.direction(u, lam, nu, gap, 0.0)
            kernel.last_correction, kernel.delta_last = memory
            if step is not None:
                dz = step[1]
        tol = self.problem.tau * self.problem.max_abs_w(u)
        touching = gap <= tol if step is None else (2.0 * dz > gap) | (gap - dz <= tol)
        mine = kernel.contact.owned_positions[touching]
        return np.sort(np.concatenate(kernel.comm.allgather(mine))).astype(np.int64)

    def contact_set(self, point: BarrierPoint) -> npt.NDArray[np.int64]:
        r"""The nodes whose gap is at most :math:`\tau \max|w|`: the contact set Z.

        Same on every rank (node numbers, sorted). A node in the degenerate part of the
        obstacle (gap and push both near zero) counts as touching only when its gap is
        at the solver's tolerance.
        """
        kernel = self.kernel
        u = point.mode.x.petsc_vec
        gap = -kernel.oriented(u) / self.problem.max_abs_w(u)
        mine = kernel.contact.owned_positions[gap <= self.problem.tau]
        return np.sort(np.concatenate(kernel.comm.allgather(mine))).astype(np.int64)

    def escape(self, point: BarrierPoint, lower: PETSc.Vec) -> bool:
        r"""Leave a saddle along a lower mode of the contact-reduced pencil (in place).

        At a stationary point whose contact-reduced pencil has an eigenvector ``lower``
        with a smaller load, :math:`R` decreases along :math:`u + t v` (v the part of
        ``lower`` B-orthogonal to u) in both directions; the step goes, in the
        direction that lowers R more, to ``escape_fraction`` of the way to the first
        node that would touch the obstacle (at most ``max_escape_step``). (Two weakly
        coupled buckles with nearly equal loads: the barrier keeps both, the lower
        antisymmetric combination moves the weight to the one with the smaller load
        until the other lies on the obstacle.)

        Returns:
            Whether the quotient decreased (the mode is then rescaled, the push reset).
        """
        kernel = self.kernel
        u = point.mode.x.petsc_vec
        kernel.B.mult(u, kernel.Bu)
        lower.copy(kernel.du)
        kernel.du.axpy(-dot(kernel.du, kernel.Bu), u)
        kernel.B.mult(kernel.du, kernel.rhs)
        norm = dot(kernel.du, kernel.rhs)
        if not norm > 0.0:
            return False
        kernel.du.scale(1.0 / math.sqrt(norm))
        gap = -kernel.oriented(u)
        dz = kernel.oriented(kernel.du)
        kernel.A.mult(u, kernel.Au)
        r0 = dot(u, kernel.Au)
        best, best_t = r0, 0.0
        opts = self.options
        for sign in (1.0, -1.0):
            moving = sign * dz > 0.0
            t = opts.escape_fraction * kernel.min(gap[moving] / (sign * dz[moving]))
            t = min(t, opts.max_escape_step) if math.isfinite(t) else opts.max_escape_step
            u.copy(kernel.trial)
            kernel.trial.axpy(sign * t, kernel.du)
            kernel.normalize(kernel.trial)
            kernel.A.mult(kernel.trial, kernel.Au)
            r = dot(kernel.trial, kernel.Au)
            if r < best:
                best, best_t = r, sign * t
        if best_t == 0.0:
            return False
        u.axpy(best_t, kernel.du)
        kernel.normalize(u)
        point.mode.x.scatter_forward()
        point.load = best
        kernel.B.mult(u, kernel.Bu)
        f_scale = best * float(kernel.Bu.norm(PETSc.NormType.INFINITY))
        point.push = point.mu * f_scale * self.problem.max_abs_w(u) / (-kernel.oriented(u))
        return True

    def destroy(self) -> None:
        """Destroy the kernel's, the starts' and the curvature's objects (collective)."""
        for part in ("curvature", "starts", "kernel"):
            owner = self.__dict__.get(part)
            if owner is not None:
                owner.destroy()
