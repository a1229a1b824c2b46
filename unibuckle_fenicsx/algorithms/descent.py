r"""Feasible descent on the cone: a monotone route to a KKT point when the others stall.

The primal-dual iteration (:mod:`.pdas`) and the penalty continuation
(:mod:`.continuation`) jump between contact sets and can wander for ever on plates whose
buckle may sit almost anywhere at nearly the same load. This is the classical active-set
method of nonlinear programming applied to the Rayleigh quotient
:math:`R(u) = a(u,u)/b(u,u)` on the cone :math:`C = \{u: u_k \le 0,\ k \in I\}`: it keeps
an *admissible* vector u and a working set :math:`W \subseteq \{k \in I: u_k = 0\}`, and
never lets R increase.

One step: release the nodes :math:`R_\ell \subseteq W` that pull (none at the start),
solve the pencil with :math:`W' = W \setminus R_\ell` removed for its smallest eigenvector
v, and move from u towards v on the arc of span{u, v}

.. math::

    x(\varphi) = \cos\varphi\, e_1 + \sin\varphi\, e_2, \qquad
    e_1 = u/\|u\|_A,\quad e_2 \perp_A e_1,\quad v \propto x(\varphi_v),\ 0 \le \varphi_v \le \pi/2.

On span{u, v}, v maximises :math:`b/a` (it minimises R on the larger space of W'), and
:math:`b(x(\varphi))` is :math:`c + \rho\cos 2(\varphi - \varphi_v)`, so R decreases
monotonically along the arc. The step stops at the first node of :math:`I \setminus W'`
that reaches the obstacle (those nodes join W) or at v itself. At v, an eigenvector of
W, the point is KKT when no node of W pulls (:math:`r_k \le \tau`); otherwise the pulling
nodes are released at the next step. Released nodes that would cross the obstacle at
once (a zero step) stay in W and the others are released.

R strictly decreases on every non-zero step and a zero step shrinks the release set, so
the iteration cannot cycle: it ends at a KKT point, or at its step budget with an
admissible mode (an upper bound) that is never worse than its start. Each step is one
eigen solve; the price of monotonicity is that a contact line moves by about one node
layer per step, so this is the last link of the chain, not the first.

Note:
    Decisions use values reduced over the ranks; collective on the problem's communicator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from petsc4py import PETSc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import RunStatus, UnilateralSolution
from unibuckle_fenicsx.algorithms.arc import ArcPlane
from unibuckle_fenicsx.algorithms.pdas import Run
from unibuckle_fenicsx.algorithms.records import ContinuedRecord
from unibuckle_fenicsx.errors import EigenSolveError
from unibuckle_fenicsx.la.options import Prefix, option_defaults, ordering_options, set_options
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem, require_obstacle
from unibuckle_fenicsx.tolerances import ROUNDING_RTOL, SMALLEST_RTOL_FACTOR, ZERO_STEP

__all__ = ["admissible_start", "continue_from", "descend"]

#: Options of the gradient release's solve (prefix ``unibuckle_descent_``).
GRADIENT_OPTIONS = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
#: Kinds of step counted by :func:`descend`.
STEP_KINDS = ("full", "partial", "zero", "gradient")


def admissible_start(
    problem: UnilateralProblem, start: Candidate, max_iterations: int
) -> tuple[Candidate | None, int]:
    r"""An admissible eigen mode from ``start``, by adding the violating nodes to Z.

    Z only grows, so this ends in at most i iterates: at an admissible mode, or with no
    finite load (None) when the obstacle leaves no geometric stiffness.

    Returns:
        The admissible candidate (or None) and the eigen solves used.

    Note:
        Collective.
    """
    cand, solves = start, 0
    while not cand.feasible and solves < max_iterations:
        grow = np.union1d(cand.active, np.flatnonzero(cand.values > problem.tau))
        cand = problem.evaluate(grow, initial=cand.mode.x.petsc_vec)
        solves += 1
        if not math.isfinite(cand.load):
            return None, solves
    return (cand if cand.feasible else None), solves


class _Arc(ArcPlane):
    r"""The arc from u towards d on which R decreases.

    :math:`e_1 = u/\|u\|_A`, :math:`e_2` the A-orthogonal part of d (unit, with the sign on
    which :math:`b` increases from u); on the unit A-circle :math:`b(\varphi) = b_{11}\cos^2
    + 2 b_{12}\cos\sin + b_{22}\sin^2` is :math:`c + \rho\cos 2(\varphi - \varphi_m)`, so it
    increases (R decreases) on :math:`[0, \varphi_m]`. For d an eigenvector of a space
    holding u, :math:`x(\varphi_m)` is d.
    """

    def __init__(self, A: PETSc.Mat, B: PETSc.Mat, u: PETSc.Vec, d: PETSc.Vec) -> None:
        super().__init__(A, B, u, d)
        self.phi_max = 0.0
        if self.e2 is not None:
            if self.b12 < 0.0:
                self.flip()
            self.phi_max = 0.5 * math.atan2(2.0 * self.b12, self.b11 - self.b22)


class Gradient:
    r"""Descent direction :math:`g = -A_{W'}^{-1} r` with :math:`r = Au - R(u)Bu`.

    On a node k released from W (:math:`u_k = 0`, :math:`r_k > 0`) alone,
    :math:`g_k = -r_k (A_{W'}^{-1})_{kk} < 0`: g leaves the obstacle there, and
    :math:`r \cdot g < 0` makes it a descent direction of R. Used when every eigen step
    towards a release is a zero step (on a 4th-order operator the reduced eigenvector
    need not leave the obstacle where the multiplier pulls).
    """

    def __init__(self, problem: UnilateralProblem) -> None:
        self.problem = problem
        self.ksp = PETSc.KSP().create(problem.model.A.comm)
        set_options(self.ksp, Prefix.DESCENT, GRADIENT_OPTIONS)

    def direction(self, u: PETSc.Vec, working: npt.NDArray[np.int64]) -> PETSc.Vec:
        """The direction g for the working set ``working`` (a new vector)."""
        problem = self.problem
        A, B = problem.model.A, problem.model.B
        rows = np.asarray(problem.contact.removed_rows(working), dtype=PETSc.IntType)
        Aw, _ = problem.eigensolver.reduced(rows)
        au, bu = u.duplicate(), u.duplicate()
        A.mult(u, au)
        B.mult(u, bu)
        rhs = au.copy()
        rhs.axpy(-u.dot(au).real / u.dot(bu).real, bu)
        rhs.scale(-1.0)
        rhs.setValues(rows, np.zeros(len(rows)))  # type: ignore[arg-type]
        rhs.assemble()
        g = u.duplicate()
        self.ksp.setOperators(Aw)
        # The ordering is read at the analysis, which serves every later direction.
        with option_defaults(Prefix.DESCENT, ordering_options(Aw, reused=True)):
            self.ksp.solve(rhs, g)
        for v in (au, bu, rhs):
            v.destroy()
        return g

    def arc(self, u: PETSc.Vec, working: npt.NDArray[np.int64]) -> _Arc:
        """The arc from ``u`` along the direction g for ``working`` (collective)."""
        model = self.problem.model
        d = self.direction(u, working)
        arc = _Arc(model.A, model.B, u, d)
        d.destroy()
        return arc

    def destroy(self) -> None:
        """Destroy the solver (collective)."""
        self.ksp.destroy()


def _blocking(
    problem: UnilateralProblem, arc: _Arc, trial: npt.NDArray[np.int64]
) -> tuple[float, npt.NDArray[np.int64]]:
    """The angle of the arc at which the first free node reaches the obstacle, and those nodes.

    Nodes that the end of the arc puts above the obstacle beyond the tolerance block it;
    the nodes within :data:`~unibuckle_fenicsx.tolerances.ZERO_STEP` of the step of the
    first are blocked with it. Collective.
    """
    n, tau = problem.contact.size, problem.tau
    free = np.ones(n, dtype=bool)
    free[trial] = False
    e1 = problem.contact.values(arc.e1)
    e2 = np.zeros(n)
    if arc.phi_max > 0.0 and arc.e2 is not None:
        e2 = problem.contact.values(arc.e2)
    end = math.cos(arc.phi_max) * e1 + math.sin(arc.phi_max) * e2
    target = arc.point(arc.phi_max)
    scale = problem.max_abs_w(target) or 1.0
    target.destroy()
    rising = free & (e2 > 0.0) & (end > tau * scale)
    angle = np.full(n, np.inf)
    angle[rising] = np.arctan2(np.maximum(-e1[rising], 0.0), e2[rising])
    phi_b = float(angle.min()) if rising.any() else math.inf
    zero = ZERO_STEP * arc.phi_max
    blocked = np.flatnonzero(rising & (angle <= max(phi_b, zero)))
    return phi_b, blocked


def descend(
    problem: UnilateralProblem, start: Candidate, max_steps: int
) -> tuple[Run, dict[str, int]]:
    """Monotone feasible descent from the admissible eigen mode ``start``.

    Args:
        problem: The problem (with an obstacle).
        start: An admissible candidate (``start.feasible``); its contact set is the
            first working set. It need not be an eigen mode (a refuting mode is a
            Rayleigh quotient): the first step then goes to its contact set's eigen mode.
        max_steps: Solves allowed (eigen and gradient), >= 1.

    Returns:
        A run named "descent" (status KKT at a KKT point, else MAX_ITERATIONS or
        STALLED; ``best_feasible`` is the last admissible eigen mode met: R never
        increases, so it is also the lowest) and the number of steps of each kind.

    Note:
        Collective.
    """
    require_obstacle(problem, "descend")
    if not start.feasible:
        raise ValueError("descend: start must be feasible (an admissible mode)")
    n, tau = problem.contact.size, problem.tau
    A, B = problem.model.A, problem.model.B
    run = Run("descent", best_feasible=start, final=start)
    if start.kkt and start.eigen is not None:  # else not an eigenpair: one step at least
        run.status = RunStatus.KKT
        return run, dict.fromkeys(STEP_KINDS, 0)
    u = start.mode.x.petsc_vec.copy()
    gradient: Gradient | None = None
    sets = _Sets(start.active, _pulling(start, n, tau))
    steps = dict.fromkeys(STEP_KINDS, 0)
    try:
        for step in range(max_steps):
            run.iterations = step + 1
            trial = np.setdiff1d(sets.working, sets.release)
            cand: Candidate | None = None
            if sets.by_gradient:
                steps["gradient"] += 1
                gradient = gradient or Gradient(problem)  # rarely needed: made on first use
                arc = gradient.arc(u, trial)
            else:
                cand = problem.evaluate(trial, initial=u)
                arc = _Arc(A, B, u, cand.mode.x.petsc_vec)
            phi_b, blocked = _blocking(problem, arc, trial)
            if phi_b <= ZERO_STEP * arc.phi_max:
                arc.destroy()
                steps["zero"] += 1
                if sets.blocked_at_once(blocked, run.final, n, tau):
                    run.status = RunStatus.STALLED
                    break
                continue
            full = phi_b >= arc.phi_max
            u.destroy()
            if full and cand is not None:
                # u = v, an eigenvector of the working set.
                arc.destroy()
                steps["full"] += 1
                u = cand.mode.x.petsc_vec.copy()
                if sets.reached(run, cand, trial, n, tau):
                    break
                continue
            steps["partial"] += 1
            u = arc.point(arc.phi_max if full else phi_b)
            arc.destroy()
            sets.working = trial if full else np.union1d(trial, blocked)
            sets.release = np.empty(0, dtype=np.int64)
            sets.by_gradient = False
    finally:
        u.destroy()
        if gradient is not None:
            gradient.destroy()
    return run, steps


@dataclass
class _Sets:
    """The descent's working set W, the nodes to release from it, and how the next arc is made.

    Attributes:
        working: Nodes held at the obstacle (global contact indices).
        release: Nodes of ``working`` released at the next step.
        by_gradient: Whether the next arc follows the gradient instead of an eigen solve.
    """

    working: npt.NDArray[np.int64]
    release: npt.NDArray[np.int64]
    by_gradient: bool = False

    def blocked_at_once(
        self, blocked: npt.NDArray[np.int64], final: Candidate | None, n: int, tau: float
    ) -> bool:
        """A zero step: update the sets and say whether the descent has stalled.

        Released nodes that would cross at once stay in W, nodes already at the obstacle
        join it; the others are released. When every eigen step towards a release is a
        zero step, the most pulling node of ``final`` is released along the gradient
        instead (which leaves the obstacle there); when that too is a zero step, the
        descent has stalled.
        """
        had = self.release.size > 0
        self.working = np.union1d(self.working, blocked)
        self.release = np.setdiff1d(self.release, blocked)
        if had and self.release.size == 0:
            if self.by_gradient:
                return True
            self.release, self.by_gradient = _pulling(final, n, tau, largest=True), True
        return False

    def reached(
        self, run: Run, cand: Candidate, trial: npt.NDArray[np.int64], n: int, tau: float
    ) -> bool:
        """A full step to ``cand``, the eigenvector of ``trial``: record it, say if it is KKT."""
        self.working, self.by_gradient = trial, False
        run.final = cand
        run.history.append((len(trial), cand.load, cand.feasible))
        if cand.feasible:
            run.best_feasible = cand
        if cand.kkt:
            run.status = RunStatus.KKT
            return True
        self.release = _pulling(cand, n, tau)
        return False


def _pulling(
    cand: Candidate | None, n: int, tau: float, largest: bool = False
) -> npt.NDArray[np.int64]:
    """Nodes of the candidate's contact set whose force pulls (r_k > tau)."""
    if cand is None or cand.active.size == 0:
        return np.empty(0, dtype=np.int64)
    forces = cand.forces[cand.active]
    pull = forces > tau
    if largest and pull.any():
        pull &= forces >= forces[pull].max() * (1.0 - ROUNDING_RTOL)
    return cand.active[pull].astype(np.int64)


def continue_from(
    problem: UnilateralProblem, solution: UnilateralSolution, start: Candidate, max_steps: int
) -> UnilateralSolution:
    """The solve continued from ``start``, an admissible mode below the returned load.

    A certificate that meets such a mode (a *refuting* mode: the returned KKT point is
    not the global minimum) hands it back; the feasible descent from it never raises the
    load, so the answer becomes a KKT point (or admissible mode) at or below ``start``'s
    load (within rounding, :data:`~unibuckle_fenicsx.tolerances.ROUNDING_RTOL`). The
    returned point joins the other KKT points met; the continuation is recorded in
    ``solution.continued``.

    Args:
        problem: The problem.
        solution: The algorithm's answer that ``start`` refutes.
        start: The admissible mode (``start.feasible``, its contact set where it vanishes).
        max_steps: Solves allowed for the descent, >= 1.

    Raises:
        EigenSolveError: The answer's load lies below ``solution``'s proven lower bound
            beyond the eigen solver's accuracy (a contradiction, never a lower bound).

    Note:
        Collective.
    """
    run, steps = descend(problem, start, max_steps)
    final = run.final if run.status is RunStatus.KKT else run.best_feasible
    # R never rises along the descent, but the start's load is a Rayleigh quotient and an
    # eigen solve's load is accurate to its tolerance: a KKT point of the start's own
    # contact set can come out a rounding above it and is still the answer (the start,
    # not an eigenvector, would fail the certificate's KKT test).
    if final is None or not final.feasible or final.load > start.load * (1.0 + ROUNDING_RTOL):
        final = start
    # An admissible mode's load is at least the critical load, so at least a proven lower
    # bound: below it beyond the eigen solver's accuracy is a contradiction, never a bound.
    lower = solution.lower_bound
    if final.load < lower * (1.0 - SMALLEST_RTOL_FACTOR * problem.spec.solver.eps_tol):
        raise EigenSolveError(
            f"the continued solve's admissible load {final.load!r} lies below the proven "
            f"lower bound {lower!r} (by {solution.lower_bound_by or 'interlacing'}): the "
            "mode is not an eigenvector of its reduced pencil, or the bound is none"
        )
    record = ContinuedRecord(
        from_load=start.load,
        to_load=final.load,
        status=str(run.status),
        steps=run.iterations,
        refuted_load=solution.load,
    )
    return UnilateralSolution(
        candidate=final,
        method=solution.method,
        eigensolves=solution.eigensolves + run.iterations - steps.get("gradient", 0),
        lower_bound=min(lower, final.load),  # equal within the solver's accuracy
        global_optimum_proven=False,
        upper_bound=min(solution.upper_bound, final.load),
        kkt_points=[*solution.kkt_points, solution.candidate],
        p_star=solution.p_star,
        lower_bound_by=solution.lower_bound_by,
        status=solution.status,
        details=solution.details,
        route=list(solution.route),
        continued=[*solution.continued, record],
    )
